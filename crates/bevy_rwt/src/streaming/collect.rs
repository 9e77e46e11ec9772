//! Finished generation tasks go to the looks that show them: points of entity classes to the
//! entity look, instance buffers to the instanced look.

use super::{ChunkContent, ChunkLoaded, LayerState};
use crate::edits::EditSet;
use crate::entities::{ImpostorReach, Spawner};
use crate::layers::ScatterLayer;
use bevy::prelude::*;
use bevy::tasks::futures::check_ready;
use std::sync::Arc;

/// Collects finished tasks and hands their content to each look.
pub(super) fn collect_results(
    mut commands: Commands,
    mut layers: Query<(Entity, &ScatterLayer, &mut LayerState)>,
    mut loaded: MessageWriter<ChunkLoaded>,
) {
    for (entity, layer, mut state) in &mut layers {
        let classes = layer.classes.len();
        let reach = ImpostorReach::of(layer);
        let state = &mut *state;
        let mut finished = Vec::new();
        for (chunk, c) in state.states.iter_mut() {
            let Some((task, band)) = c.task.as_mut() else {
                continue;
            };
            if let Some(result) = check_ready(task) {
                let band = *band;
                c.task = None;
                finished.push((*chunk, band, result));
            }
        }
        for (chunk, band, result) in finished {
            let Some(c) = state.states.get_mut(&chunk) else {
                continue;
            };
            let ChunkContent {
                mut points,
                packed,
                edits,
            } = match result {
                Ok(content) => content,
                Err(e) => {
                    c.refused = true;
                    if !std::mem::replace(&mut state.refusal_logged, true) {
                        error!("scatter layer {entity}: chunk {chunk:?} not generated: {e}");
                    }
                    continue;
                }
            };
            c.refused = false;
            c.shown = true;
            c.lod = band;
            let reground = std::mem::take(&mut c.task_regrounds);
            let packed_count: usize = packed.iter().map(|p| p.buffer.instances.len()).sum();
            let count = points.len() + packed_count;
            let current = state.chunk_edits.get(&chunk);
            if same_edits(edits.as_ref(), current) {
                state.instanced.show(chunk, packed);
            } else {
                // Edited while generating: the entity points take the edits now; the
                // instance buffers are made again.
                if let Some(current) = current {
                    EditSet::apply(current, &mut points, classes);
                }
                c.stale = true;
            }
            // Only a chunk whose ground changed moves the entities it keeps.
            if reground && let Some(generator) = state.generator(layer) {
                let spawner = Spawner {
                    entity,
                    layer,
                    ground: &generator.ground,
                };
                state
                    .entities
                    .replace_kept(&mut commands, &spawner, chunk, &points);
            }
            state.entities.show(chunk, points, reach.as_ref());
            loaded.write(ChunkLoaded {
                layer: entity,
                chunk,
                instances: count,
            });
        }
    }
}

/// Whether a task applied the chunk's current edits (a chunk's set is copied when edited
/// while a task holds it).
fn same_edits(applied: Option<&Arc<EditSet>>, current: Option<&Arc<EditSet>>) -> bool {
    match (applied, current) {
        (None, None) => true,
        (Some(a), Some(b)) => Arc::ptr_eq(a, b),
        _ => false,
    }
}
