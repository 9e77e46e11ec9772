//! Layers that keep out of each other: a layer's [`KeepOut`]s name other layers whose
//! instances clear it within a radius per class (trees clear grass around their trunks).
//! A generation task makes the other layer's points over its chunk grown by the largest
//! radius, at full detail and with that layer's edits, from the same deterministic query
//! that layer's own chunks use: the result never depends on which chunk finished first.
//! An edit of the other layer (a tree removed) generates again the chunks within reach.

use super::LayerState;
use super::generate::{Clearing, Generator};
use crate::edits::EditSet;
use crate::layers::{KeepOut, LayerRef, ScatterLayer};
use bevy::platform::collections::HashMap;
use bevy::prelude::*;
use glam::DVec2;
use rwt_core::query::Rect;
use rwt_core::streaming::ChunkCoord;
use std::sync::Arc;

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
