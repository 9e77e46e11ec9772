//! Budgeted spawning and despawning of the queued instances.

use super::LayerState;
use crate::layers::{ClassLook, GroundPlane, HeightFn, ScatterInstance, ScatterLayer};
use crate::settings::RwtSettings;
use bevy::prelude::*;
use rwt_core::query::Point;

/// Spawns and despawns queued instances within the per-frame budgets (shared by all
/// layers, in query order).
pub(super) fn apply_budget(
    mut commands: Commands,
    mut layers: Query<(Entity, &ScatterLayer, &mut LayerState)>,
    settings: Res<RwtSettings>,
) {
    let mut spawn_budget = settings.spawn_budget;
    let mut despawn_budget = settings.despawn_budget;
    for (entity, layer, mut state) in &mut layers {
        let state = &mut *state;
        despawn_queued(&mut commands, state, &mut despawn_budget);
        spawn_queued(&mut commands, entity, layer, state, &mut spawn_budget);
    }
}

/// Despawns queued instances, oldest first, while the budget lasts.
fn despawn_queued(commands: &mut Commands, state: &mut LayerState, budget: &mut usize) {
    while *budget > 0 {
        let Some(e) = state.despawn.pop_front() else {
            break;
        };
        commands.entity(e).try_despawn();
        *budget -= 1;
    }
}

/// Spawns queued instances chunk by chunk, in the order their chunks finished.
fn spawn_queued(
    commands: &mut Commands,
    entity: Entity,
    layer: &ScatterLayer,
    state: &mut LayerState,
    budget: &mut usize,
) {
    while *budget > 0 {
        let Some(&chunk) = state.spawn_order.front() else {
            break;
        };
        let Some(height) = state.sources.height().cloned() else {
            break;
        };
        let Some(c) = state.states.get_mut(&chunk) else {
            // Unloaded while waiting.
            state.spawn_order.pop_front();
            continue;
        };
        while *budget > 0 {
            let Some(p) = c.queued.pop() else { break };
            let e = spawn_instance(commands, entity, layer, &height, &p);
            c.instances.insert(p.id, (e, p.class));
            *budget -= 1;
        }
        if c.queued.is_empty() {
            c.in_order = false;
            state.spawn_order.pop_front();
        }
    }
}

/// Spawns one instance: the class's look at the point's place on the layer's plane, turned
/// and scaled by hashes of its identity.
fn spawn_instance(
    commands: &mut Commands,
    entity: Entity,
    layer: &ScatterLayer,
    height: &HeightFn,
    p: &Point,
) -> Entity {
    let class = &layer.classes[(p.class as usize).min(layer.classes.len().saturating_sub(1))];
    let ground = Vec2::new(p.position.x as f32, p.position.y as f32);
    let scale = class.scale * p.id.scale(layer.seed, class.scale_variation as f64) as f32;
    let yaw = p.id.rotation(layer.seed) as f32;
    let depth = match layer.plane {
        GroundPlane::Xy => p.id.unit(layer.seed, 0xde97) as f32,
        GroundPlane::Xz => 0.0,
    };
    let transform = layer
        .plane
        .transform(ground, height(ground), yaw, scale, depth);
    let instance = ScatterInstance {
        layer: entity,
        id: p.id,
        class: p.class,
    };
    // One bundle for the common case: an insert after the spawn would move every instance
    // to a second archetype.
    match &class.look {
        ClassLook::Mesh { mesh, material } => commands
            .spawn((
                instance,
                Mesh3d(mesh.clone()),
                MeshMaterial3d(material.clone()),
                transform,
            ))
            .id(),
        ClassLook::Custom(insert) => {
            let mut custom = commands.spawn((instance, transform));
            insert(&mut custom);
            custom.id()
        }
    }
}
