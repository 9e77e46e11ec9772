//! Packing a chunk's points of instanced classes into GPU-ready buffers, in the generation
//! task (off the main thread).

use super::chunk::{GpuInstance, InstanceBuffer};
use crate::ground::{GroundRule, Stands, SurfaceHit};
use crate::layers::ScatterLayer;
use crate::look::{ClassLook, GroundPlane, Pose, Stance};
use bevy::prelude::*;
use glam::DVec2;
use rwt_core::density::{Density, sanitize};
use rwt_core::query::Point;
use std::sync::Arc;

/// Salt of the hashed colour variation.
const TINT_SALT: u64 = 0x7117;

/// What packing needs of a layer: which classes are instanced, with their scale.
#[derive(Clone, Debug)]
pub(crate) struct InstancedClasses {
    /// Per class, when instanced: how it is packed.
    classes: Arc<[Option<PackedLook>]>,
    seed: u64,
    /// Whether the layer's plane can show them (the x-z ground only); their points are left
    /// out otherwise.
    drawable: bool,
}

/// What packing needs of an instanced class.
#[derive(Clone, Copy, Debug)]
struct PackedLook {
    scale: f32,
    variation: f32,
    stance: Stance,
    /// Promoted classes keep their instances' identities.
    keep_ids: bool,
    /// An entity class packed for its impostors: its points are also spawned.
    keep_points: bool,
}

/// A chunk's instances of one class, ready for the GPU.
pub(crate) struct PackedClass {
    pub class: u16,
    pub buffer: Arc<InstanceBuffer>,
}

impl InstancedClasses {
    /// The instanced classes of `layer` (logs an error when its plane cannot show them).
    pub fn new(entity: Entity, layer: &ScatterLayer, keep_ids: bool) -> Self {
        let classes = layer
            .classes
            .iter()
            .map(|c| match (&c.look, &c.impostor) {
                (look, _) if look.is_instanced() => Some(PackedLook {
                    scale: c.scale,
                    variation: c.scale_variation,
                    stance: c.stance,
                    keep_ids: keep_ids || c.promotion.is_some(),
                    keep_points: false,
                }),
                (ClassLook::Mesh { .. }, Some(_)) => Some(PackedLook {
                    scale: c.scale,
                    variation: c.scale_variation,
                    stance: c.stance,
                    keep_ids,
                    keep_points: true,
                }),
                _ => None,
            })
            .collect();
        let packing = Self {
            classes,
            seed: layer.seed,
            drawable: layer.plane == GroundPlane::Xz,
        };
        if packing.any() && !packing.drawable {
            error!(
                "scatter layer {entity}: instanced classes are drawn on GroundPlane::Xz only; \
                 their points are left out on {:?}",
                layer.plane
            );
        }
        packing
    }

    /// Whether any class is instanced.
    pub fn any(&self) -> bool {
        self.classes.iter().any(Option::is_some)
    }

    /// Whether points of `class` are packed (rather than spawned, or besides being spawned
    /// for a class drawn far as impostors).
    pub fn is_instanced(&self, class: u16) -> bool {
        matches!(self.classes.get(class as usize), Some(Some(_)))
    }

    /// Whether points of `class` stay for the entity look once packed.
    fn keeps_points(&self, class: u16) -> bool {
        self.classes
            .get(class as usize)
            .is_some_and(|c| c.is_some_and(|c| c.keep_points))
    }

    /// Moves the points of instanced classes out of `points` into one buffer per class, and
    /// copies those of entity classes with impostors into one (every packed class gets one,
    /// empty or not, so that emptied chunks are cleared).
    /// `densities` are the class densities the chunk was queried with, at level-of-detail
    /// `factor`; `corner` is the chunk's corner, which positions are relative to.
    pub fn pack(
        &self,
        points: &mut Vec<Point>,
        corner: DVec2,
        (ground, stands): (&GroundRule, &Stands),
        densities: &[impl Density],
        factor: f64,
    ) -> Vec<PackedClass> {
        let mut buffers: Vec<InstanceBuffer> = self
            .classes
            .iter()
            .map(|_| InstanceBuffer::default())
            .collect();
        points.retain(|p| {
            if !self.is_instanced(p.class) {
                return true;
            }
            let keep = self.keeps_points(p.class);
            if !self.drawable {
                return keep;
            }
            let (hit, area) = ground
                .stand_in(p, stands)
                .unwrap_or((SurfaceHit::flat(0.0), 1.0));
            let appear = appear_factor(p, densities, area * factor);
            let buffer = &mut buffers[p.class as usize];
            buffer
                .instances
                .push(self.instance(p, corner, &hit, appear));
            if self.classes[p.class as usize].is_some_and(|c| c.keep_ids) {
                buffer.ids.push(p.id);
            }
            keep
        });
        buffers
            .into_iter()
            .enumerate()
            .filter(|(class, _)| self.drawable && self.classes[*class].is_some())
            .map(|(class, mut buffer)| {
                buffer.bounds = bounds(&buffer.instances);
                PackedClass {
                    class: class as u16,
                    buffer: Arc::new(buffer),
                }
            })
            .collect()
    }

    /// One instance on surface `hit`: the same place, turn and scale as the entity path
    /// would give it.
    fn instance(&self, p: &Point, corner: DVec2, hit: &SurfaceHit, appear: f64) -> GpuInstance {
        let look = self.classes[p.class as usize].expect("packed classes are instanced");
        let pose = Pose::of(&p.id, self.seed, look.scale, look.variation);
        let footing = look.stance.footing(hit.height, hit.normal);
        let root = Vec3::new(0.0, footing.height, 0.0) - footing.up * footing.sink;
        let offset = p.position - corner;
        GpuInstance {
            offset: [offset.x as f32 + root.x, root.y, offset.y as f32 + root.z],
            scale: pose.scale,
            yaw: unit_u16(pose.yaw / std::f64::consts::TAU),
            appear: unit_u16(appear),
            tint: unit_u16(p.id.unit(self.seed, TINT_SALT)),
            tilt: GpuInstance::pack_up(footing.up),
        }
    }
}

/// The level-of-detail factor at which `p` appears: its threshold over the summed density
/// at full detail (the query ran at `factor` times it, `factor` including the ground's area
/// weight at the point).
fn appear_factor(p: &Point, densities: &[impl Density], factor: f64) -> f64 {
    let total: f64 = densities
        .iter()
        .map(|d| sanitize(d.density(p.position)))
        .sum();
    if total > 0.0 {
        (p.threshold / total * factor).clamp(0.0, 1.0)
    } else {
        0.0
    }
}

/// `v` in `[0, 1]` as a 16-bit fraction (`1` saturates at `u16::MAX`).
fn unit_u16(v: f64) -> u16 {
    (v * 65_536.0).clamp(0.0, u16::MAX as f64) as u16
}

/// Bounds of the instances' offsets (zero for no instance).
pub(super) fn bounds(instances: &[GpuInstance]) -> (Vec3, Vec3) {
    let mut it = instances.iter().map(|i| Vec3::from_array(i.offset));
    let Some(first) = it.next() else {
        return (Vec3::ZERO, Vec3::ZERO);
    };
    it.fold((first, first), |(lo, hi), v| (lo.min(v), hi.max(v)))
}
