//! The instanced look's side of streaming: each chunk's instance buffers (packed in its
//! generation task) wait for the upload budget, then go to one [`InstancedChunk`] entity per
//! (chunk, class), spawned when new, updated in place, despawned when empty or unloaded.

use super::{InstancedChunk, InstancedMeshes, PackedClass};
use crate::layers::ScatterLayer;
use crate::look::ClassLook;
use bevy::platform::collections::HashMap;
use bevy::prelude::*;
use rwt_core::streaming::ChunkCoord;
use std::collections::VecDeque;

/// A chunk's instanced classes.
#[derive(Default)]
struct ChunkBuffers {
    /// The chunk entity of each instanced class, with its instance count.
    drawn: HashMap<u16, (Entity, usize)>,
    /// Buffers generated but not yet handed to their entities.
    waiting: Vec<PackedClass>,
    /// Whether the chunk is in the upload order.
    in_order: bool,
}

/// A layer's instanced chunks: what each chunk draws and is about to draw.
#[derive(Default)]
pub(crate) struct InstancedQueue {
    chunks: HashMap<ChunkCoord, ChunkBuffers>,
    /// Chunks with buffers to hand over, in the order they finished.
    upload_order: VecDeque<ChunkCoord>,
    /// Chunk entities of unloaded chunks: despawned at once, whatever the budget (one
    /// entity each).
    retired: Vec<Entity>,
}

impl InstancedQueue {
    /// Shows `packed` in `chunk` once the upload budget lets it (replacing what is waiting).
    pub fn show(&mut self, chunk: ChunkCoord, packed: Vec<PackedClass>) {
        if packed.is_empty() {
            return;
        }
        let c = self.chunks.entry(chunk).or_default();
        c.waiting = packed;
        if !c.in_order {
            c.in_order = true;
            self.upload_order.push_back(chunk);
        }
    }

    /// Forgets a chunk that unloaded: its entities are retired.
    pub fn unload(&mut self, chunk: ChunkCoord) {
        if let Some(c) = self.chunks.remove(&chunk) {
            self.retired.extend(c.drawn.values().map(|(e, _)| *e));
        }
    }

    /// Instances in the chunks' buffers.
    pub fn live(&self) -> usize {
        let per_chunk = |c: &ChunkBuffers| c.drawn.values().map(|(_, n)| n).sum::<usize>();
        self.chunks.values().map(per_chunk).sum()
    }

    /// Instances waiting for the upload budget.
    pub fn queued(&self) -> usize {
        let waiting = |c: &ChunkBuffers| -> usize {
            c.waiting.iter().map(|p| p.buffer.instances.len()).sum()
        };
        self.chunks.values().map(waiting).sum()
    }

    /// Despawns every chunk entity, drawn or retired.
    pub fn despawn_all(&self, commands: &mut Commands) {
        let drawn = self.chunks.values().flat_map(|c| c.drawn.values());
        for e in drawn.map(|(e, _)| *e).chain(self.retired.iter().copied()) {
            commands.entity(e).try_despawn();
        }
    }

    /// Despawns the chunk entities of unloaded chunks.
    pub fn despawn_retired(&mut self, commands: &mut Commands) {
        for e in self.retired.drain(..) {
            commands.entity(e).try_despawn();
        }
    }
}

/// The per-frame hand-over of instance buffers to chunk entities, shared by all layers.
pub(crate) struct Upload<'a> {
    /// Instances that may still be handed over this frame.
    budget: usize,
    meshes: Option<&'a Assets<Mesh>>,
    /// Mesh bounds, checked once per mesh.
    checked: &'a mut InstancedMeshes,
    /// Whether no chunk was handed over yet this frame (one always is).
    first: bool,
}

impl<'a> Upload<'a> {
    /// A frame's hand-over of up to `budget` instances (at least one chunk).
    pub fn new(
        budget: usize,
        meshes: Option<&'a Assets<Mesh>>,
        checked: &'a mut InstancedMeshes,
    ) -> Self {
        Self {
            budget,
            meshes,
            checked,
            first: true,
        }
    }

    /// Hands a layer's waiting buffers over, chunk by chunk in the order they finished.
    pub fn chunks(
        &mut self,
        commands: &mut Commands,
        entity: Entity,
        layer: &ScatterLayer,
        queue: &mut InstancedQueue,
    ) {
        while let Some(&chunk) = queue.upload_order.front() {
            let Some(c) = queue.chunks.get_mut(&chunk) else {
                // Unloaded while waiting.
                queue.upload_order.pop_front();
                continue;
            };
            let count: usize = c.waiting.iter().map(|p| p.buffer.instances.len()).sum();
            if count > self.budget && !self.first {
                break;
            }
            self.budget = self.budget.saturating_sub(count);
            self.first = false;
            queue.upload_order.pop_front();
            c.in_order = false;
            for packed in std::mem::take(&mut c.waiting) {
                let class = packed.class;
                let slot = c.drawn.get(&class).map(|(e, _)| *e);
                let len = packed.buffer.instances.len();
                let target = Target {
                    entity,
                    layer,
                    chunk,
                    slot,
                };
                match self.hand_over(commands, target, packed) {
                    Some(e) => c.drawn.insert(class, (e, len)),
                    None => c.drawn.remove(&class),
                };
            }
        }
    }

    /// Puts one class's buffer on its chunk entity (spawned when new, despawned when the
    /// buffer is empty); returns the entity that holds it.
    fn hand_over(
        &mut self,
        commands: &mut Commands,
        target: Target,
        packed: PackedClass,
    ) -> Option<Entity> {
        let layer = target.layer;
        let class = layer.classes.get(packed.class as usize)?;
        let ClassLook::Instanced(look) = &class.look else {
            return None;
        };
        if packed.buffer.instances.is_empty() {
            if let Some(e) = target.slot {
                commands.entity(e).try_despawn();
            }
            return None;
        }
        let corner = target.chunk.rect(layer.streaming.chunk_size).min();
        let max_scale = class.scale * (1.0 + class.scale_variation.abs());
        let mesh_bounds = self.checked.bounds(&look.mesh, self.meshes);
        let component = InstancedChunk {
            layer: target.entity,
            chunk: target.chunk,
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
        Some(match target.slot {
            Some(e) => {
                commands.entity(e).insert((component, aabb));
                e
            }
            None => commands.spawn((component, aabb, transform)).id(),
        })
    }
}

/// Where a buffer goes: a layer's chunk, and the entity that draws its class there, if any.
struct Target<'a> {
    entity: Entity,
    layer: &'a ScatterLayer,
    chunk: ChunkCoord,
    slot: Option<Entity>,
}
