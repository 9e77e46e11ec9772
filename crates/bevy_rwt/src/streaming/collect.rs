//! Finished generation tasks become spawn and despawn queues, by point identity: existing
//! instances never move.

use super::{ChunkContent, ChunkLoaded, LayerState};
use bevy::platform::collections::HashSet;
use bevy::prelude::*;
use bevy::tasks::futures::check_ready;
use rwt_core::query::PointId;
use rwt_core::streaming::diff_instances;

/// Collects finished tasks and queues the instances that appear or disappear.
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
            let packed_count: usize = packed.iter().map(|p| p.buffer.instances.len()).sum();
            if !packed.is_empty() {
                c.upload = packed;
                if !c.in_upload_order {
                    c.in_upload_order = true;
                    state.upload_order.push_back(chunk);
                }
            }
            c.lod = band;
            // Compare with what the chunk shows or is about to show.
            let spawned = c.instances.iter().map(|(id, (_, class))| (*id, *class));
            let queued = c.queued.iter().map(|p| (p.id, p.class));
            let diff = diff_instances(spawned.chain(queued), &points);
            if !diff.removed.is_empty() {
                let removed: HashSet<PointId> = diff.removed.iter().copied().collect();
                c.queued.retain(|p| !removed.contains(&p.id));
                for id in &diff.removed {
                    if let Some((e, _)) = c.instances.remove(id) {
                        state.despawn.push_back(e);
                    }
                }
            }
            let count = points.len() + packed_count;
            c.queued.extend(diff.added);
            if !c.queued.is_empty() && !c.in_order {
                c.in_order = true;
                state.spawn_order.push_back(chunk);
            }
            loaded.write(ChunkLoaded {
                layer: entity,
                chunk,
                instances: count,
            });
        }
    }
}
