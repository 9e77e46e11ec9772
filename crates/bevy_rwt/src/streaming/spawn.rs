//! Budgeted spawning and despawning of the queued instances.

use super::LayerState;
use crate::instancing::{InstancedChunk, InstancedMeshes, PackedClass};
use crate::layers::{ClassLook, GroundPlane, HeightFn, ScatterInstance, ScatterLayer};
use crate::settings::RwtSettings;
use bevy::prelude::*;
use rwt_core::query::Point;
use rwt_core::streaming::ChunkCoord;

/// Spawns and despawns queued instances and hands instance buffers to their chunk entities,
/// within the per-frame budgets (shared by all layers, in query order).
pub(super) fn apply_budget(
    mut commands: Commands,
    mut layers: Query<(Entity, &ScatterLayer, &mut LayerState)>,
    settings: Res<RwtSettings>,
    meshes: Option<Res<Assets<Mesh>>>,
    mut checked: ResMut<InstancedMeshes>,
) {
    let mut spawn_budget = settings.spawn_budget;
    let mut despawn_budget = settings.despawn_budget;
    let mut upload = Upload {
        budget: settings.upload_budget,
        meshes: meshes.as_deref(),
        checked: &mut checked,
        first: true,
    };
    for (entity, layer, mut state) in &mut layers {
        let state = &mut *state;
        despawn_queued(&mut commands, state, &mut despawn_budget);
        spawn_queued(&mut commands, entity, layer, state, &mut spawn_budget);
        upload.chunks(&mut commands, entity, layer, state);
    }
}

/// Despawns the chunk entities of unloaded chunks, then queued instances, oldest first,
/// while the budget lasts.
fn despawn_queued(commands: &mut Commands, state: &mut LayerState, budget: &mut usize) {
    for e in state.retired.drain(..) {
        commands.entity(e).try_despawn();
    }
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
    match (&class.look, &class.lod) {
        (ClassLook::Mesh { mesh, material }, None) => commands
            .spawn((
                instance,
                Mesh3d(mesh.clone()),
                MeshMaterial3d(material.clone()),
                transform,
            ))
            .id(),
        (ClassLook::Mesh { mesh, material }, Some(lod)) => {
            let (near, far) = lod.ranges();
            commands
                .spawn((
                    instance,
                    Mesh3d(mesh.clone()),
                    MeshMaterial3d(material.clone()),
                    transform,
                    near,
                    children![(
                        Mesh3d(lod.mesh.clone()),
                        MeshMaterial3d(lod.material.clone()),
                        far,
                    )],
                ))
                .id()
        }
        (ClassLook::Custom(insert), _) => {
            let mut custom = commands.spawn((instance, transform));
            insert(&mut custom);
            custom.id()
        }
        // Packed in the generation task instead; never queued for spawning.
        (ClassLook::Instanced(_), _) => commands.spawn((instance, transform)).id(),
    }
}

/// The per-frame hand-over of instance buffers to chunk entities.
struct Upload<'a> {
    /// Instances that may still be handed over this frame.
    budget: usize,
    meshes: Option<&'a Assets<Mesh>>,
    /// Mesh bounds, checked once per mesh.
    checked: &'a mut InstancedMeshes,
    /// Whether no chunk was handed over yet this frame (one always is).
    first: bool,
}

impl Upload<'_> {
    /// Hands the layer's waiting buffers over, chunk by chunk in the order they finished.
    fn chunks(
        &mut self,
        commands: &mut Commands,
        entity: Entity,
        layer: &ScatterLayer,
        state: &mut LayerState,
    ) {
        while let Some(&chunk) = state.upload_order.front() {
            let Some(c) = state.states.get_mut(&chunk) else {
                // Unloaded while waiting.
                state.upload_order.pop_front();
                continue;
            };
            let count: usize = c.upload.iter().map(|p| p.buffer.instances.len()).sum();
            if count > self.budget && !self.first {
                break;
            }
            self.budget = self.budget.saturating_sub(count);
            self.first = false;
            state.upload_order.pop_front();
            c.in_upload_order = false;
            for packed in std::mem::take(&mut c.upload) {
                let class = packed.class;
                let slot = c.instanced.get(&class).map(|(e, _)| *e);
                let len = packed.buffer.instances.len();
                match self.hand_over(commands, entity, layer, chunk, slot, packed) {
                    Some(e) => c.instanced.insert(class, (e, len)),
                    None => c.instanced.remove(&class),
                };
            }
        }
    }

    /// Puts one class's buffer on its chunk entity (spawned when new, despawned when the
    /// buffer is empty); returns the entity that holds it.
    fn hand_over(
        &mut self,
        commands: &mut Commands,
        entity: Entity,
        layer: &ScatterLayer,
        chunk: ChunkCoord,
        slot: Option<Entity>,
        packed: PackedClass,
    ) -> Option<Entity> {
        let class = layer.classes.get(packed.class as usize)?;
        let ClassLook::Instanced(look) = &class.look else {
            return None;
        };
        if packed.buffer.instances.is_empty() {
            if let Some(e) = slot {
                commands.entity(e).try_despawn();
            }
            return None;
        }
        let corner = chunk.rect(layer.streaming.chunk_size).min();
        let max_scale = class.scale * (1.0 + class.scale_variation.abs());
        let mesh_bounds = self.checked.bounds(&look.mesh, self.meshes);
        let component = InstancedChunk {
            layer: entity,
            chunk,
            class: packed.class,
            mesh: look.mesh.clone(),
            material: look.material.clone(),
            mesh_top: mesh_bounds.1.y.max(1e-3),
            max_scale,
            falloff: layer
                .falloff
                .map(|f| (f.near as f32, f.far as f32, f.floor as f32)),
            buffer: packed.buffer,
        };
        let aabb = component.aabb(mesh_bounds);
        let transform = Transform::from_xyz(corner.x as f32, 0.0, corner.y as f32);
        Some(match slot {
            Some(e) => {
                commands.entity(e).insert((component, aabb));
                e
            }
            None => commands.spawn((component, aabb, transform)).id(),
        })
    }
}
