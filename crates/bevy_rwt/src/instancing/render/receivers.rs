//! Which instances a directional light's shadow cascade needs: those whose shadow can fall
//! where the camera samples that cascade.
//!
//! A cascade's shadow map covers a box around the sphere that bounds its slice of the
//! camera's frustum, so it holds casters behind the camera, beside it, and in every other
//! cascade's slice: grass within 25 m of the eye is drawn into each of open_world's three
//! cascades, all around the eye. A fragment samples cascade `i` only where its view depth
//! lies in the cascade's slice (Bevy's `shadows.wgsl`: the first cascade whose far bound
//! passes the depth, blended with the next one past `1 - overlap` of that bound), and it is
//! in the camera's frustum. An instance's shadow lies on the rays the light casts through
//! it, so an instance whose sphere, swept along the light, leaves that region through one of
//! its half-spaces casts nothing a fragment reads from the cascade. The test is per
//! half-space, so it keeps some instances it could drop, never drops one it needs.

use crate::instancing::settings::CascadeCasters;
use bevy::camera::primitives::{Aabb, Frustum};
use bevy::light::CascadeShadowConfig;
use bevy::math::primitives::ViewFrustum;
use bevy::pbr::{ExtractedDirectionalLight, LightEntity, ViewLightEntities};
use bevy::platform::collections::HashMap;
use bevy::prelude::*;
use bevy::render::view::ExtractedView;
use std::ops::Range;

/// The region whose fragments read a cascade, grown by [`margin`], and the direction its
/// light travels.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(in crate::instancing) struct Receivers {
    /// Half-spaces (unit normal, distance; inside where `dot(n, p) + d > 0`): the camera
    /// frustum's four sides, then the slice's near and far bounds of view depth.
    pub planes: [Vec4; 6],
    /// The direction the light travels (unit).
    pub light: Vec3,
}

impl Receivers {
    /// The region of a camera (its frustum's half-spaces, its place) between `depths` of
    /// view depth, grown by `margin` metres, lit along `light`.
    pub fn new(
        camera: &ViewFrustum,
        eye: &GlobalTransform,
        depths: Range<f32>,
        light: Vec3,
        margin: f32,
    ) -> Self {
        let forward = eye.forward().as_vec3();
        let along = forward.dot(eye.translation());
        let h = camera.half_spaces;
        let sides = [0, 1, 2, 3].map(|k| h[k].normal_d());
        let near = forward.extend(-along - depths.start);
        let far = (-forward).extend(along + depths.end);
        let planes =
            [sides[0], sides[1], sides[2], sides[3], near, far].map(|p| p + Vec4::W * margin);
        Self {
            planes,
            light: light.normalize(),
        }
    }

    /// Whether a sphere may cast a shadow into the region: for each half-space, inside it
    /// or carried into it by the light.
    #[cfg(test)]
    pub fn casts(&self, center: Vec3, radius: f32) -> bool {
        casts(&self.planes, self.light, center, radius)
    }

    /// Whether an instance with its root inside `bounds` may cast nothing into the region
    /// (a chunk that culling per instance tests).
    pub fn may_drop(&self, bounds: &Aabb) -> bool {
        let (min, max) = (Vec3::from(bounds.min()), Vec3::from(bounds.max()));
        self.planes.iter().any(|p| {
            let nearest = Vec3::select(p.truncate().cmpge(Vec3::ZERO), min, max);
            p.truncate().dot(self.light) <= 0.0 && p.truncate().dot(nearest) + p.w <= 0.0
        })
    }

    /// Whether anything inside `bounds` may cast into the region (a chunk that casts
    /// nowhere is not binned into the cascade).
    pub fn may_cast(&self, bounds: &Aabb) -> bool {
        let (min, max) = (Vec3::from(bounds.min()), Vec3::from(bounds.max()));
        self.planes.iter().all(|p| {
            let farthest = Vec3::select(p.truncate().cmpge(Vec3::ZERO), max, min);
            p.truncate().dot(self.light) > 0.0 || p.truncate().dot(farthest) + p.w > 0.0
        })
    }
}

/// [`Receivers::casts`] on its parts (`cull.wgsl` makes the same test).
#[cfg(any(test, feature = "testing"))]
pub(in crate::instancing) fn casts(
    planes: &[Vec4; 6],
    light: Vec3,
    center: Vec3,
    radius: f32,
) -> bool {
    planes
        .iter()
        .all(|p| p.truncate().dot(light) > 0.0 || p.truncate().dot(center) + p.w + radius > 0.0)
}

/// The view depths whose fragments read cascade `index` of `config`; `None` past its
/// cascades.
pub(in crate::instancing) fn depths(
    config: &CascadeShadowConfig,
    index: usize,
) -> Option<Range<f32>> {
    let far = *config.bounds.get(index)?;
    let near = match index {
        0 => 0.0,
        _ => (1.0 - config.overlap_proportion) * config.bounds[index - 1],
    };
    Some(near..far)
}

/// How far beyond the region a caster still counts (metres): a metre (a diffuse
/// transmission's sample lies its thickness under the surface) and eight texels of the
/// shadow map (filtering reads a few texels around a fragment, offset along its normal by
/// the normal bias, in texels).
pub(in crate::instancing) fn margin(texel: f32, normal_bias: f32) -> f32 {
    1.0 + texel * (8.0 + normal_bias.max(0.0))
}

/// The receivers of every directional light's cascade this frame, by shadow view
/// ([`find_receivers`]); none for a view that keeps every caster.
#[derive(Resource, Default)]
pub(in crate::instancing) struct CascadeReceivers(HashMap<Entity, Receivers>);

impl CascadeReceivers {
    /// The receivers of shadow view `view`, where its casters can be narrowed down.
    pub fn of(&self, view: Entity) -> Option<&Receivers> {
        self.0.get(&view)
    }
}

/// Finds the receivers of every directional light's cascade ([`CascadeCasters`]), once a
/// frame for the shadow queue and the culling. None for a light with soft shadows (their
/// penumbra reaches as far as the light's size makes it).
pub(in crate::instancing) fn find_receivers(
    setting: Option<Res<CascadeCasters>>,
    cameras: Query<(&ExtractedView, &Frustum, &ViewLightEntities)>,
    shadow_views: Query<(&ExtractedView, &LightEntity)>,
    lights: Query<&ExtractedDirectionalLight>,
    mut found: ResMut<CascadeReceivers>,
) {
    found.0.clear();
    if setting.as_deref().copied().unwrap_or_default() == CascadeCasters::All {
        return;
    }
    for (camera, frustum, views) in &cameras {
        for &entity in &views.lights {
            let Ok((view, light)) = shadow_views.get(entity) else {
                continue;
            };
            let LightEntity::Directional {
                light_entity,
                cascade_index,
            } = *light
            else {
                continue;
            };
            let Ok(light) = lights.get(light_entity) else {
                continue;
            };
            if light.soft_shadow_size.is_some() {
                continue;
            }
            let Some(depths) = depths(&light.cascade_shadow_config, cascade_index) else {
                continue;
            };
            // The cascade's projection is orthographic: 2 / width on the diagonal.
            let size = view.viewport.z.max(1) as f32;
            let texel = 2.0 / (view.clip_from_view.x_axis.x.abs().max(1e-6) * size);
            let margin = margin(texel, light.shadow_normal_bias);
            let travels = light.transform.forward().as_vec3();
            let eye = &camera.world_from_view;
            let receivers = Receivers::new(&frustum.0, eye, depths, travels, margin);
            found.0.insert(entity, receivers);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A camera at the origin looking down +x with a 90° field of view each way, its
    /// receivers between `depths`, lit along `light`.
    fn lit(depths: Range<f32>, light: Vec3) -> Receivers {
        let eye = GlobalTransform::from(Transform::IDENTITY.looking_to(Vec3::X, Vec3::Y));
        let clip_from_view = Mat4::perspective_infinite_reverse_rh(90f32.to_radians(), 1.0, 0.1);
        let clip_from_world = clip_from_view * eye.to_matrix().inverse();
        let frustum = ViewFrustum::from_clip_from_world(&clip_from_world);
        Receivers::new(&frustum, &eye, depths, light, 0.0)
    }

    /// The light travels down and along the view.
    fn receivers(depths: Range<f32>) -> Receivers {
        lit(depths, Vec3::new(1.0, -1.0, 0.0))
    }

    #[test]
    fn a_caster_counts_where_its_shadow_may_fall_in_the_slice() {
        let r = receivers(10.0..30.0);
        // In the slice, in view: kept.
        assert!(r.casts(Vec3::new(20.0, 0.0, 0.0), 0.5));
        // Behind the eye, high: its shadow travels forward and down, into the slice.
        assert!(r.casts(Vec3::new(-5.0, 20.0, 0.0), 0.5));
        // Behind the eye, low: under the frustum's floor, which the light runs along.
        assert!(!r.casts(Vec3::new(-5.0, -10.0, 0.0), 0.5));
        // Beyond the slice: the light carries it farther still.
        assert!(!r.casts(Vec3::new(40.0, 0.0, 0.0), 0.5));
        // Just outside the far bound by less than its radius: kept.
        assert!(r.casts(Vec3::new(30.4, 0.0, 0.0), 0.5));
        // Beside the view: the light travels into the side's half-space, so the test by
        // half-space keeps it (its shadow passes beyond the far bound first).
        assert!(r.casts(Vec3::new(15.0, 0.0, -40.0), 0.5));
        // Lit from straight above, the same caster is dropped, and one in view is kept.
        let noon = lit(10.0..30.0, Vec3::NEG_Y);
        assert!(!noon.casts(Vec3::new(15.0, 0.0, -40.0), 0.5));
        assert!(noon.casts(Vec3::new(15.0, 0.0, 0.0), 0.5));
    }

    #[test]
    fn a_kept_caster_is_kept_whenever_a_point_of_its_shadow_is_inside() {
        // Brute force: sample spheres and points along their rays; any ray point inside
        // the region (every half-space) means the test must keep it.
        let r = receivers(5.0..25.0);
        let mut seed = 12345u32;
        let mut next = || {
            seed ^= seed << 13;
            seed ^= seed >> 17;
            seed ^= seed << 5;
            seed as f32 / u32::MAX as f32
        };
        let inside = |p: Vec3| r.planes.iter().all(|h| h.truncate().dot(p) + h.w > 0.0);
        let (mut kept, mut dropped) = (0, 0);
        for _ in 0..4000 {
            let c = Vec3::new(
                next() * 80.0 - 40.0,
                next() * 40.0 - 20.0,
                next() * 80.0 - 40.0,
            );
            let radius = next() * 2.0;
            let shadowed = (0..200).any(|s| {
                let along = r.light * s as f32 * 0.5;
                let offset = Vec3::new(next() - 0.5, next() - 0.5, next() - 0.5) * radius;
                inside(c + along + offset)
            });
            if r.casts(c, radius) {
                kept += 1;
            } else {
                assert!(
                    !shadowed,
                    "{c} (radius {radius}) dropped, its shadow is inside"
                );
                dropped += 1;
            }
        }
        assert!(kept > 500 && dropped > 500, "kept {kept} dropped {dropped}");
    }

    #[test]
    fn a_chunk_is_tested_where_an_instance_may_cast_nothing_and_left_where_all_do() {
        let r = receivers(10.0..30.0);
        assert!(!r.may_drop(&Aabb::from_min_max(
            Vec3::new(12.0, -1.0, -2.0),
            Vec3::new(16.0, 0.0, 2.0)
        )));
        assert!(r.may_drop(&Aabb::from_min_max(
            Vec3::new(28.0, -1.0, -2.0),
            Vec3::new(32.0, 0.0, 2.0)
        )));
        assert!(r.may_drop(&Aabb::from_min_max(
            Vec3::new(-8.0, -5.0, -2.0),
            Vec3::new(-4.0, -4.0, 2.0)
        )));
        // A chunk wholly beyond the far bound casts nowhere; one across it may.
        let beyond = Aabb::from_min_max(Vec3::new(31.0, -1.0, -2.0), Vec3::new(35.0, 0.0, 2.0));
        let across = Aabb::from_min_max(Vec3::new(28.0, -1.0, -2.0), Vec3::new(32.0, 0.0, 2.0));
        assert!(!r.may_cast(&beyond));
        assert!(r.may_cast(&across));
    }

    #[test]
    fn a_cascade_is_read_from_the_next_ones_blend_to_its_far_bound() {
        let config = CascadeShadowConfig {
            bounds: vec![30.0, 100.0, 350.0],
            overlap_proportion: 0.2,
            minimum_distance: 0.1,
        };
        assert_eq!(depths(&config, 0), Some(0.0..30.0));
        assert_eq!(depths(&config, 1), Some(24.0..100.0));
        assert_eq!(depths(&config, 2), Some(80.0..350.0));
        assert_eq!(depths(&config, 3), None);
        assert!((margin(0.1, 2.0) - 2.0).abs() < 1e-6);
    }
}
