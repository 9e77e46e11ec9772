//! Finished generation tasks go to the looks that show them: points of entity classes to the
//! entity look, instance buffers to the instanced look.

use super::{ChunkContent, ChunkLoaded, LayerState};
use bevy::prelude::*;
use bevy::tasks::futures::check_ready;

/// Collects finished tasks and hands their content to each look.
pub(super) fn collect_results(
    mut layers: Query<(Entity, &mut LayerState)>,
    mut loaded: MessageWriter<ChunkLoaded>,
) {
    for (entity, mut state) in &mut layers {
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
            let c = state.states.get_mut(&chunk).expect("finished chunks exist");
            let ChunkContent { points, packed } = match result {
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
            c.lod = band;
            let packed_count: usize = packed.iter().map(|p| p.buffer.instances.len()).sum();
            let count = points.len() + packed_count;
            state.instanced.show(chunk, packed);
            state.entities.show(chunk, points);
            loaded.write(ChunkLoaded {
                layer: entity,
                chunk,
                instances: count,
            });
        }
    }
}
