//! Footprints reach the chunks they cover: a footprint that appears, moves, changes or goes
//! marks the chunks under it (before and after) for generation, whose tasks leave out the
//! points it clears.

use super::LayerState;
use crate::footprints::{Footprint, GroundFootprint};
use crate::layers::ScatterLayer;
use crate::look::GroundPlane;
use bevy::platform::collections::HashMap;
use bevy::prelude::*;
use bevy::transform::helper::TransformHelper;
use glam::DVec2;
use rwt_core::Rect;

/// Every footprint as last seen, placed by its transform at the time.
#[derive(Resource, Default)]
pub(crate) struct KnownFootprints(HashMap<Entity, Known>);

/// A footprint and its transform, and where it lies on each ground plane (made once, when
/// it is seen, for every generation task that reads it).
#[derive(Clone)]
struct Known {
    footprint: Footprint,
    transform: GlobalTransform,
    xz: GroundFootprint,
    xy: GroundFootprint,
}

impl Known {
    fn new(footprint: Footprint, transform: GlobalTransform) -> Self {
        Self {
            xz: footprint.on_ground(&transform, GroundPlane::Xz),
            xy: footprint.on_ground(&transform, GroundPlane::Xy),
            footprint,
            transform,
        }
    }

    fn on(&self, plane: GroundPlane) -> &GroundFootprint {
        match plane {
            GroundPlane::Xz => &self.xz,
            GroundPlane::Xy => &self.xy,
        }
    }
}

impl KnownFootprints {
    /// The footprints that clear points of `layer` on `plane` in `region`.
    pub fn clearing(
        &self,
        layer: Entity,
        plane: GroundPlane,
        region: &Rect,
    ) -> Vec<GroundFootprint> {
        self.0
            .values()
            .filter(|k| k.footprint.clears_layer(layer))
            .map(|k| k.on(plane))
            .filter(|g| g.bounds().is_some_and(|b| overlaps(&b, region)))
            .cloned()
            .collect()
    }
}

/// A footprint that is new, changed, or whose transform (or a parent's) changed.
type Moved = Or<(
    Changed<Footprint>,
    Changed<Transform>,
    Changed<GlobalTransform>,
)>;

/// Notes added, changed, moved and removed footprints and marks the chunks they cover, before
/// and after, for generation.
pub(super) fn track_footprints(
    changed: Query<Entity, (With<Footprint>, Moved)>,
    footprints: Query<&Footprint>,
    transforms: TransformHelper,
    mut removed: RemovedComponents<Footprint>,
    mut known: ResMut<KnownFootprints>,
    mut layers: Query<(Entity, &ScatterLayer, &mut LayerState)>,
) {
    let mut touched = Vec::new();
    for entity in &changed {
        // The transform as of now, whether or not propagation ran since it changed.
        let (Ok(footprint), Ok(transform)) = (
            footprints.get(entity),
            transforms.compute_global_transform(entity),
        ) else {
            continue;
        };
        let was = known.0.get(&entity);
        if was.is_some_and(|k| k.footprint == *footprint && k.transform == transform) {
            continue;
        }
        let now = Known::new(footprint.clone(), transform);
        touched.extend(known.0.insert(entity, now.clone()));
        touched.push(now);
    }
    for entity in removed.read() {
        touched.extend(known.0.remove(&entity));
    }
    if touched.is_empty() {
        return;
    }
    for (entity, layer, mut state) in &mut layers {
        let size = layer.streaming.chunk_size;
        for k in touched.iter().filter(|k| k.footprint.clears_layer(entity)) {
            if let Some(bounds) = k.on(layer.plane).bounds() {
                state.mark_stale(size, &widen(&bounds));
            }
        }
    }
}

/// Whether a footprint's (closed) bounds reach into a (half-open) region.
fn overlaps(bounds: &Rect, region: &Rect) -> bool {
    widen(bounds).overlaps(region)
}

/// `r` grown a little, so that a closed shape's edge on a chunk border reaches the chunk
/// beyond it.
fn widen(r: &Rect) -> Rect {
    let by = DVec2::splat(1e-9) * (DVec2::ONE + r.min().abs().max(r.max().abs()));
    Rect::new(r.min() - by, r.max() + by).unwrap_or(*r)
}
