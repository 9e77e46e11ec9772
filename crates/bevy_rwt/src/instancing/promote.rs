//! Promotion: instances of a promoted class within its distance of a viewer leave their
//! chunk's buffer for an entity (a [`ScatterEntity`] with the class's inserted
//! components, at the transform the buffer drew it with, and a child that draws the same
//! instance), and go back beyond it. The buffer change and the entity are commands of one
//! system, applied together: no frame draws an instance twice or misses it.

use super::chunk::{GpuInstance, InstanceBuffer};
use super::queue::{ClassBuffer, InstancedQueue, Target, Upload};
use crate::layers::{Promotion, ScatterEntity, ScatterLayer};
use bevy::prelude::*;
use glam::DVec2;
use rwt_core::query::PointId;
use rwt_core::streaming::Viewer;
use std::sync::Arc;

impl Upload<'_> {
    /// Promotes and hands back the instances of the layer's promoted classes as the viewers
    /// moved.
    pub fn promote(
        &mut self,
        commands: &mut Commands,
        entity: Entity,
        layer: &ScatterLayer,
        queue: &mut InstancedQueue,
        viewers: &[Viewer],
    ) {
        let size = layer.streaming.chunk_size;
        for (chunk, c) in queue.chunks.iter_mut() {
            let target = Target {
                entity,
                layer,
                chunk: *chunk,
            };
            let near = chunk.viewer_distance(size, viewers);
            for (class, buffer) in c.classes.iter_mut() {
                let Some(promotion) = layer
                    .classes
                    .get(*class as usize)
                    .and_then(|c| c.promotion.as_ref())
                    .filter(|_| self.promotes(layer, *class))
                else {
                    continue;
                };
                let reach = (promotion.distance * Promotion::HYSTERESIS) as f64;
                if near > reach && buffer.promoted.is_empty() {
                    continue;
                }
                let moved = Moved {
                    target,
                    class: *class,
                    promotion,
                    viewers,
                };
                if moved.update(self, commands, buffer) {
                    self.redraw(commands, target, *class, buffer);
                }
            }
        }
    }
}

/// One class of one chunk, as the viewers stand.
struct Moved<'a> {
    target: Target<'a>,
    class: u16,
    promotion: &'a Promotion,
    viewers: &'a [Viewer],
}

impl Moved<'_> {
    /// Promotes instances that came within the distance and hands back those beyond it
    /// (with hysteresis); returns whether any changed.
    fn update(
        &self,
        upload: &mut Upload,
        commands: &mut Commands,
        buffer: &mut ClassBuffer,
    ) -> bool {
        let corner = self.corner();
        let (enter, leave) = (
            self.promotion.distance as f64,
            (self.promotion.distance * Promotion::HYSTERESIS) as f64,
        );
        let mut changed = false;
        let whole = buffer.whole.clone();
        for (g, id) in whole.instances.iter().zip(&whole.ids) {
            let at = DVec2::new(
                (corner.x + g.offset[0]) as f64,
                (corner.z + g.offset[2]) as f64,
            );
            let distance = self
                .viewers
                .iter()
                .map(|v| v.position.distance(at))
                .fold(f64::INFINITY, f64::min);
            match buffer.promoted.get(id) {
                Some(e) if distance > leave => {
                    commands.entity(*e).try_despawn();
                    buffer.promoted.remove(id);
                    changed = true;
                }
                None if distance <= enter => {
                    let e = self.spawn(upload, commands, corner, g, *id);
                    buffer.promoted.insert(*id, e);
                    changed = true;
                }
                _ => {}
            }
        }
        changed
    }

    /// The chunk's corner as its entity stands (what the buffer's offsets add to).
    fn corner(&self) -> Vec3 {
        let size = self.target.layer.streaming.chunk_size;
        let corner = self.target.chunk.rect(size).min();
        Vec3::new(corner.x as f32, 0.0, corner.y as f32)
    }

    /// The entity of a promoted instance: its transform as drawn, the class's components,
    /// and a child that draws the instance (its own transform undoes the parent's turn and
    /// scale: the instance carries them).
    fn spawn(
        &self,
        upload: &mut Upload,
        commands: &mut Commands,
        corner: Vec3,
        g: &GpuInstance,
        id: PointId,
    ) -> Entity {
        let translation = corner + Vec3::from_array(g.offset);
        let rotation = g.rotation();
        let scale = g.scale;
        let transform = Transform {
            translation,
            rotation,
            scale: Vec3::splat(scale),
        };
        let one = InstanceBuffer {
            instances: vec![GpuInstance {
                offset: [0.0; 3],
                ..*g
            }],
            ids: vec![id],
            bounds: (Vec3::ZERO, Vec3::ZERO),
        };
        let undo = Transform {
            translation: Vec3::ZERO,
            rotation: rotation.inverse(),
            scale: Vec3::splat(1.0 / scale.abs().max(1e-6)),
        };
        let instance = ScatterEntity {
            layer: self.target.entity,
            id,
            class: self.class,
        };
        let mut e = commands.spawn((instance, transform, Visibility::default(), PromotedInstance));
        #[cfg(feature = "gltf")]
        if let Some(collider) = upload.asset_collider(self.target, self.class) {
            e.insert(collider);
        }
        (self.promotion.insert)(&mut e);
        let parent = e.id();
        for (component, aabb) in upload.parts(self.target, self.class, Arc::new(one)) {
            commands.spawn((component, aabb, undo, ChildOf(parent)));
        }
        parent
    }
}

/// Marks the entity of a promoted instance (see [`Promotion`]).
#[derive(Component, Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct PromotedInstance;
