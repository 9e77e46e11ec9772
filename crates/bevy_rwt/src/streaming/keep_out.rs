//! Layers that keep out of each other: a layer's [`KeepOut`]s name other layers whose
//! instances clear it within a radius per class (trees clear grass around their trunks).
//! A generation task makes the other layer's points over its chunk grown by the largest
//! radius, at full detail and with that layer's edits, from the same deterministic query
//! that layer's own chunks use: the result never depends on which chunk finished first.
//! An edit of the other layer (a tree removed) generates again the chunks within reach.

use super::LayerState;
use super::generate::{Changes, Generator};
use crate::edits::EditSet;
use crate::layers::{KeepOut, LayerRef, ScatterLayer};
use bevy::platform::collections::HashMap;
use bevy::prelude::*;
use glam::DVec2;
use rwt_core::query::{Point, QueryError, Rect};
use rwt_core::streaming::ChunkCoord;
use std::sync::Arc;

/// Another layer's points as they clear a layer: how they are generated and edited.
#[derive(Clone)]
pub(crate) struct Clearing {
    generator: Generator,
    /// Per class of the other layer: how far its instances clear.
    radii: Arc<[f32]>,
    /// The other layer's chunk size and edits by chunk.
    chunk_size: f64,
    edits: HashMap<ChunkCoord, Arc<EditSet>>,
}

impl Clearing {
    fn reach(&self) -> f64 {
        self.radii.iter().fold(0.0f32, |m, r| m.max(*r)) as f64
    }

    /// Removes from `out` (the points of `rect`) every point within reach of an instance
    /// of the other layer.
    pub fn clear(&self, rect: Rect, out: &mut Vec<Point>) -> Result<(), QueryError> {
        let reach = self.reach();
        if reach <= 0.0 || out.is_empty() {
            return Ok(());
        }
        let grown = Rect::new(
            rect.min() - DVec2::splat(reach),
            rect.max() + DVec2::splat(reach),
        )
        .unwrap_or(rect);
        let g = &self.generator;
        let mut others = g.points(grown, &g.scaled(1.0, None), &Changes::default())?;
        for (chunk, set) in &self.edits {
            if chunk.rect(self.chunk_size).overlaps(&grown) {
                g.edit(set, &mut others);
            }
        }
        let discs = Discs::new(&others, &self.radii, reach);
        out.retain(|p| !discs.covers(p.position));
        Ok(())
    }
}

/// The other layer's instances as discs, bucketed by a grid of the largest radius.
struct Discs {
    cell: f64,
    buckets: HashMap<(i64, i64), Vec<(DVec2, f64)>>,
}

impl Discs {
    fn new(points: &[Point], radii: &[f32], reach: f64) -> Self {
        let mut buckets: HashMap<(i64, i64), Vec<(DVec2, f64)>> = HashMap::new();
        for p in points {
            let r = radii.get(p.class as usize).copied().unwrap_or(0.0) as f64;
            if r > 0.0 {
                let key = Self::key(p.position, reach);
                buckets.entry(key).or_default().push((p.position, r * r));
            }
        }
        Self {
            cell: reach,
            buckets,
        }
    }

    fn key(p: DVec2, cell: f64) -> (i64, i64) {
        ((p.x / cell).floor() as i64, (p.y / cell).floor() as i64)
    }

    /// Whether `p` lies strictly within a disc.
    fn covers(&self, p: DVec2) -> bool {
        let (x, y) = Self::key(p, self.cell);
        (x - 1..=x + 1).any(|i| {
            (y - 1..=y + 1).any(|j| {
                self.buckets
                    .get(&(i, j))
                    .is_some_and(|discs| discs.iter().any(|(c, r2)| c.distance_squared(p) < *r2))
            })
        })
    }
}

/// What a layer's keep-out needs of every layer: how its points are made and its edits.
struct Source {
    generator: Option<Generator>,
    chunk_size: f64,
    edits: HashMap<ChunkCoord, Arc<EditSet>>,
}

/// Gives every layer with keep-outs the current state of the layers that clear it; where
/// their edits changed, or the layers themselves, the chunks within reach are generated
/// again. A layer waits while a layer that clears it is not ready.
pub(super) fn track_keep_out(
    mut layers: Query<(Entity, &ScatterLayer, &mut LayerState)>,
    names: Query<(Entity, &Name), With<ScatterLayer>>,
) {
    if layers.iter().all(|(_, l, _)| l.keep_out.is_empty()) {
        return;
    }
    let named = |name: &str| {
        names
            .iter()
            .find(|(_, n)| n.as_str() == name)
            .map(|(e, _)| e)
    };
    let sources: HashMap<Entity, Source> = layers
        .iter()
        .map(|(e, layer, state)| {
            let source = Source {
                generator: state.generator(layer),
                chunk_size: layer.streaming.chunk_size,
                edits: state.chunk_edits.clone(),
            };
            (e, source)
        })
        .collect();
    for (entity, layer, mut state) in &mut layers {
        if layer.keep_out.is_empty() {
            continue;
        }
        let mut clearings = Vec::new();
        let mut ready = true;
        for keep in &layer.keep_out {
            let other = match &keep.layer {
                LayerRef::Entity(e) => Some(*e),
                LayerRef::Named(name) => named(name),
            };
            let source = other.filter(|e| *e != entity).and_then(|e| sources.get(&e));
            match source {
                Some(Source {
                    generator: Some(generator),
                    chunk_size,
                    edits,
                }) => clearings.push(Clearing {
                    generator: generator.without_keep_out(),
                    radii: keep.radii.clone().into(),
                    chunk_size: *chunk_size,
                    edits: edits.clone(),
                }),
                Some(_) => ready = false,
                None => warn_once(entity, keep),
            }
        }
        mark_changed(layer, &mut state, &clearings);
        state.keep_out = ready.then(|| Arc::from(clearings));
    }
}

fn warn_once(entity: Entity, keep: &KeepOut) {
    bevy::log::warn_once!(
        "scatter layer {entity}: keeps out of {:?}, which is not another scatter layer",
        keep.layer
    );
}

/// Marks the chunks within reach of what changed in the clearing layers: every chunk when
/// one was made anew, the chunks near their edited chunks otherwise.
fn mark_changed(layer: &ScatterLayer, state: &mut LayerState, now: &[Clearing]) {
    let Some(before) = state.keep_out.clone() else {
        return;
    };
    let size = layer.streaming.chunk_size;
    let same = |a: &Clearing, b: &Clearing| a.generator.same_as(&b.generator) && a.radii == b.radii;
    if before.len() != now.len() || before.iter().zip(now).any(|(a, b)| !same(a, b)) {
        state.mark_all_stale();
        return;
    }
    for (old, new) in before.iter().zip(now) {
        let chunks = old.edits.keys().chain(new.edits.keys());
        for chunk in chunks {
            let unchanged = match (old.edits.get(chunk), new.edits.get(chunk)) {
                (Some(a), Some(b)) => Arc::ptr_eq(a, b),
                _ => false,
            };
            if !unchanged {
                let r = chunk.rect(new.chunk_size);
                let reach = DVec2::splat(new.reach());
                if let Ok(region) = Rect::new(r.min() - reach, r.max() + reach) {
                    state.mark_stale(size, &region);
                }
            }
        }
    }
}
