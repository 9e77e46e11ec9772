//! Which chunks a view draws whole without culling: those of which culling could drop no
//! instance. A chunk wholly inside the view, nearer than where its fall-off and thinning
//! begin, within its class's shadow distance of a shadow view's eye and, in a cascade,
//! where its shadows are read ([`receivers`](crate::instancing::render::receivers)), inside
//! its crossfades, in a view that does not occlude, keeps every instance; it is drawn
//! directly, with no dispatch, no uniform and no pool range (the same pixels, less work).

use super::views::ViewCulling;
use crate::instancing::render::uniforms::ChunkUniform;
use crate::look::InstancedShadows;
use bevy::camera::primitives::Aabb;
use bevy::prelude::*;

/// Whether culling may drop an instance of a chunk with `bounds` (world space, every root
/// inside), the level of detail of `chunk` and `shadows` in `view`.
pub(super) fn may_drop(
    view: &ViewCulling,
    bounds: &Aabb,
    chunk: &ChunkUniform,
    shadows: InstancedShadows,
) -> bool {
    if view.occluding.is_some() {
        return true;
    }
    let (min, max) = (Vec3::from(bounds.min()), Vec3::from(bounds.max()));
    // The corner of the box farthest from each half-space's inside must be inside.
    let across = view.planes.iter().any(|p| {
        let nearest = Vec3::select(p.truncate().cmpge(Vec3::ZERO), min, max);
        p.truncate().dot(nearest) + p.w <= 0.0
    });
    if across {
        return true;
    }
    let eye = view.eye;
    let (nearest, farthest) = nearest_and_farthest(bounds, eye);
    let far = farthest.distance(eye);
    let far_xz = farthest.xz().distance(eye.xz());
    let near = nearest.distance(eye);
    let lod = &chunk.lod;
    let grows = lod.falloff_on != 0 && far_xz > lod.falloff_near;
    let thins = lod.thinning_on != 0 && far_xz > lod.thinning_from;
    let casts_beyond = view.shadow && matches!(shadows, InstancedShadows::Within(d) if far > d);
    let casts_nowhere = view.receivers.is_some_and(|r| r.may_drop(bounds));
    let fades = near < chunk.fade_in_from || (chunk.fade_out_to > 0.0 && far >= chunk.fade_out_to);
    grows || thins || casts_beyond || casts_nowhere || fades
}

/// The point of `bounds` nearest to `eye` (itself inside them) and the corner farthest
/// from it.
pub(super) fn nearest_and_farthest(bounds: &Aabb, eye: Vec3) -> (Vec3, Vec3) {
    let (min, max) = (Vec3::from(bounds.min()), Vec3::from(bounds.max()));
    let farthest = Vec3::select((eye - min).cmpge(max - eye), min, max);
    (eye.clamp(min, max), farthest)
}

#[cfg(test)]
mod tests {
    use super::super::tests::looking_down_x;
    use super::*;
    use crate::instancing::render::receivers::Receivers;
    use crate::instancing::render::uniforms::LodUniform;

    /// A camera at the origin looking down +x (x > 0, |z| < x, no far plane).
    fn view() -> ViewCulling {
        ViewCulling {
            entity: Entity::PLACEHOLDER,
            planes: looking_down_x(),
            eye: Vec3::ZERO,
            shadow: false,
            receivers: None,
            occluding: None,
        }
    }

    fn chunk(x: f32, z: f32) -> Aabb {
        Aabb::from_min_max(Vec3::new(x, 0.0, z), Vec3::new(x + 4.0, 1.0, z + 4.0))
    }

    #[test]
    fn a_chunk_is_culled_only_where_an_instance_may_be_dropped() {
        let plain = ChunkUniform::default();
        let off = InstancedShadows::Off;
        // Inside the view: nothing to drop; across its side or behind the eye: culled.
        assert!(!may_drop(&view(), &chunk(10.0, -2.0), &plain, off));
        assert!(may_drop(&view(), &chunk(10.0, 8.0), &plain, off));
        assert!(may_drop(&view(), &chunk(-6.0, -2.0), &plain, off));
        // A fall-off from 12 m: its farther corner (14.1 m) is in it.
        let falloff = ChunkUniform {
            lod: LodUniform {
                falloff_near: 12.0,
                falloff_on: 1,
                ..plain.lod
            },
            ..plain
        };
        assert!(may_drop(&view(), &chunk(10.0, -2.0), &falloff, off));
        assert!(!may_drop(&view(), &chunk(5.0, -2.0), &falloff, off));
        let thinning = ChunkUniform {
            lod: LodUniform {
                thinning_from: 12.0,
                thinning_on: 1,
                ..plain.lod
            },
            ..plain
        };
        assert!(may_drop(&view(), &chunk(10.0, -2.0), &thinning, off));
        // Impostor cards from 11 m, meshes until 13 m.
        let cards = ChunkUniform {
            fade_in_from: 11.0,
            ..plain
        };
        assert!(may_drop(&view(), &chunk(10.0, -2.0), &cards, off));
        assert!(!may_drop(&view(), &chunk(12.0, -2.0), &cards, off));
        let meshes = ChunkUniform {
            fade_out_to: 13.0,
            ..plain
        };
        assert!(may_drop(&view(), &chunk(10.0, -2.0), &meshes, off));
        assert!(!may_drop(&view(), &chunk(5.0, -2.0), &meshes, off));
        // A shadow view drops what lies beyond the class's shadow distance.
        let shadow = ViewCulling {
            shadow: true,
            ..view()
        };
        let within = InstancedShadows::Within(14.0);
        assert!(may_drop(&shadow, &chunk(10.0, -2.0), &plain, within));
        assert!(!may_drop(&shadow, &chunk(5.0, -2.0), &plain, within));
        assert!(!may_drop(&view(), &chunk(10.0, -2.0), &plain, within));
        // A cascade read up to 12 m ahead, lit from above: a chunk beyond is culled.
        let cascade = ViewCulling {
            receivers: Some(Receivers {
                planes: [
                    Vec4::W,
                    Vec4::W,
                    Vec4::W,
                    Vec4::W,
                    Vec4::W,
                    Vec4::new(-1.0, 0.0, 0.0, 12.0),
                ],
                light: Vec3::NEG_Y,
            }),
            ..shadow
        };
        let on = InstancedShadows::On;
        assert!(!may_drop(&cascade, &chunk(5.0, -2.0), &plain, on));
        assert!(may_drop(&cascade, &chunk(10.0, -2.0), &plain, on));
    }
}
