//! Repainted maps: the snapshots that read them are made again, and the chunks the paint
//! covers are regenerated; only instances that appear or disappear are touched.

use super::{DensityMapPainted, LayerState};
use crate::layers::ScatterLayer;
use bevy::platform::collections::HashMap;
use bevy::prelude::*;
use rwt_core::query::Rect;

/// Regions painted into each map since its last `Modified` event.
#[derive(Resource, Default)]
pub(super) struct PaintedRegions(HashMap<AssetId<Image>, Vec<Rect>>);

/// Re-resolves the densities and heights that read a changed map and marks the chunks it
/// covers stale: the painted regions when a brush said which (widened by a texel of the
/// map, which bilinear filtering blends into), else all that the map covers.
pub(super) fn repaint(
    mut events: MessageReader<AssetEvent<Image>>,
    mut painted: MessageReader<DensityMapPainted>,
    mut regions: ResMut<PaintedRegions>,
    mut layers: Query<(&ScatterLayer, &mut LayerState)>,
    images: Res<Assets<Image>>,
) {
    for p in painted.read() {
        regions.0.entry(p.image).or_default().push(p.region);
    }
    let changed: Vec<AssetId<Image>> = events
        .read()
        .filter_map(|e| match e {
            AssetEvent::Modified { id } | AssetEvent::LoadedWithDependencies { id } => Some(*id),
            _ => None,
        })
        .collect();
    for image in changed {
        let texels = images
            .get(image)
            .map(|i| glam::DVec2::new(i.width() as f64, i.height() as f64));
        let strokes = regions.0.remove(&image);
        for (layer, mut state) in &mut layers {
            let covered = state.sources.forget_image(layer, image);
            let size = layer.streaming.chunk_size;
            for region in covered {
                let mark = |state: &mut LayerState, r: &Rect| state.mark_stale(size, r);
                match (&strokes, region) {
                    (Some(strokes), Some(map)) => {
                        let texel =
                            texels.map_or(map.size(), |t| map.size() / t.max(glam::DVec2::ONE));
                        strokes
                            .iter()
                            .filter_map(|s| widen(s, texel).intersect(&map))
                            .for_each(|r| mark(&mut state, &r))
                    }
                    (None, Some(map)) => mark(&mut state, &map),
                    (_, None) => mark(&mut state, &everywhere()),
                }
            }
        }
    }
}

/// `r` grown by `by` on every side.
fn widen(r: &Rect, by: glam::DVec2) -> Rect {
    Rect::new(r.min() - by, r.max() + by).unwrap_or(*r)
}

/// A rectangle that overlaps every chunk a layer can load.
fn everywhere() -> Rect {
    Rect::new(glam::DVec2::splat(-f64::MAX), glam::DVec2::splat(f64::MAX)).expect("ordered")
}
