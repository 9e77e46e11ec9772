//! Each look's queue, spent within the per-frame budgets (shared by all layers, in query
//! order).

use super::LayerState;
use crate::entities::{ImpostorReach, Spawner};
use crate::instancing::UploadSources;
use crate::layers::ScatterLayer;
use crate::settings::RwtSettings;
use crate::viewers::Viewers;
use bevy::prelude::*;

/// Despawns and spawns entity instances and hands instance buffers to their chunk entities,
/// within the per-frame budgets.
pub(super) fn apply_budget(
    mut commands: Commands,
    mut layers: Query<(Entity, &ScatterLayer, &mut LayerState)>,
    settings: Res<RwtSettings>,
    mut looks: UploadSources,
    viewers: Res<Viewers>,
) {
    let mut spawn_budget = settings.spawn_budget;
    let mut despawn_budget = settings.despawn_budget;
    let mut upload = looks.upload(settings.upload_budget);
    for (entity, layer, mut state) in &mut layers {
        let state = &mut *state;
        state.instanced.despawn_retired(&mut commands);
        if let Some(reach) = ImpostorReach::of(layer) {
            let viewers = viewers.on(layer.plane);
            let size = layer.streaming.chunk_size;
            state.entities.follow_viewers(&reach, size, viewers);
        }
        state
            .entities
            .despawn_queued(&mut commands, &mut despawn_budget);
        if let Some(generator) = state.generator(layer) {
            let spawner = Spawner {
                entity,
                layer,
                ground: &generator.ground,
            };
            state
                .entities
                .spawn_queued(&mut commands, &spawner, &mut spawn_budget);
        }
        upload.chunks(&mut commands, entity, layer, &mut state.instanced);
        upload.refresh_classes(&mut commands, entity, layer, &mut state.instanced);
        let viewers = viewers.on(layer.plane);
        upload.promote(&mut commands, entity, layer, &mut state.instanced, viewers);
    }
}
