//! Which mesh each culled instance draws. Where a class has a far mesh it may choose per
//! instance ([`MeshLods`]), culling gives each instance the mesh its own distance from the
//! eye calls for, instead of the mesh the chunk's nearest point calls for: a chunk across
//! the distance becomes two parts, each a record keeping the instances of its band of
//! distances and a draw of its mesh. A 16 m chunk whose nearest corner is at the distance
//! otherwise draws the near mesh 20 m beyond it.
//!
//! The two meshes must draw under one pipeline (the same vertex layout, topology and index
//! format), else the chunk keeps its own mesh whole, as the direct path draws it.

use super::views::ViewCulling;
use crate::instancing::render::extract::{ExtractedChunk, MeshLods};
use bevy::camera::primitives::Aabb;
use bevy::prelude::*;
use bevy::render::mesh::RenderMesh;
use bevy::render::render_asset::RenderAssets;

/// One mesh a chunk draws in a view, for its instances at distances from the eye in
/// `from..to`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Part {
    pub mesh: AssetId<Mesh>,
    pub from: f32,
    pub to: f32,
    /// Whether it draws the class's far mesh.
    pub far: bool,
}

impl Part {
    /// Every instance of `mesh`.
    fn whole(mesh: AssetId<Mesh>, far: bool) -> Self {
        Self {
            mesh,
            from: 0.0,
            to: f32::INFINITY,
            far,
        }
    }

    /// The record's band (`fade_in_from`, `fade_out_to`; 0: no end) of a chunk whose own
    /// band is `fade_in_from..fade_out_to`: where both hold.
    pub fn band(&self, fade_in_from: f32, fade_out_to: f32) -> (f32, f32) {
        let to = match (fade_out_to > 0.0, self.to.is_finite()) {
            (true, true) => fade_out_to.min(self.to),
            (false, true) => self.to,
            (_, false) => fade_out_to,
        };
        (fade_in_from.max(self.from), to)
    }
}

/// The parts `chunk` draws in `view` (one or two): its own mesh whole, or where it may
/// choose per instance, the near mesh nearer than the distance and the far mesh from it.
pub(super) fn parts(
    view: &ViewCulling,
    chunk: &ExtractedChunk,
    meshes: &RenderAssets<RenderMesh>,
) -> [Option<Part>; 2] {
    match chunk.lods.filter(|l| one_pipeline(meshes, l)) {
        Some(lods) => split(&lods, &chunk.bounds, chunk.uniform.fade_out_to, view.eye),
        None => [Some(Part::whole(chunk.mesh, false)), None],
    }
}

/// The parts of a chunk of a class with `lods` within `bounds`, its meshes drawn until
/// `fade_out_to` (0: no end), seen from `eye`.
fn split(lods: &MeshLods, bounds: &Aabb, fade_out_to: f32, eye: Vec3) -> [Option<Part>; 2] {
    let (nearest, farthest) = distances(bounds, eye);
    // Meshes that fade out (into impostors) before the distance never draw the far one.
    if farthest < lods.distance || (fade_out_to > 0.0 && fade_out_to <= lods.distance) {
        return [Some(Part::whole(lods.near, false)), None];
    }
    let far = Part {
        from: lods.distance,
        ..Part::whole(lods.far, true)
    };
    if nearest >= lods.distance {
        return [Some(far), None];
    }
    let near = Part {
        to: lods.distance,
        ..Part::whole(lods.near, false)
    };
    [Some(near), Some(far)]
}

/// Whether `chunk` has instances on both sides of its class's far distance in `view`
/// (so that culling, drawing each with its mesh, draws fewer vertices than the chunk
/// drawn whole).
pub(super) fn across(view: &ViewCulling, chunk: &ExtractedChunk) -> bool {
    chunk.lods.is_some_and(|lods| {
        let (nearest, farthest) = distances(&chunk.bounds, view.eye);
        nearest < lods.distance && lods.distance <= farthest
    })
}

/// The distances from `eye` to the nearest and the farthest point of `bounds`.
fn distances(bounds: &Aabb, eye: Vec3) -> (f32, f32) {
    let (nearest, farthest) = super::whole::nearest_and_farthest(bounds, eye);
    (nearest.distance(eye), farthest.distance(eye))
}

/// Whether the near and far meshes draw under one pipeline: prepared, the same vertex
/// layout, topology and index format.
fn one_pipeline(meshes: &RenderAssets<RenderMesh>, lods: &MeshLods) -> bool {
    let (Some(near), Some(far)) = (meshes.get(lods.near), meshes.get(lods.far)) else {
        return false;
    };
    near.layout == far.layout
        && near.key_bits.bits() == far.key_bits.bits()
        && near.index_format() == far.index_format()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_part_keeps_the_band_both_its_own_and_the_chunks_allow() {
        let mesh = AssetId::default();
        let whole = Part::whole(mesh, false);
        assert_eq!(whole.band(0.0, 0.0), (0.0, 0.0));
        assert_eq!(whole.band(5.0, 40.0), (5.0, 40.0));
        let near = Part { to: 30.0, ..whole };
        assert_eq!(near.band(0.0, 0.0), (0.0, 30.0));
        assert_eq!(near.band(0.0, 40.0), (0.0, 30.0));
        assert_eq!(near.band(0.0, 20.0), (0.0, 20.0));
        let far = Part {
            from: 30.0,
            ..whole
        };
        assert_eq!(far.band(0.0, 0.0), (30.0, 0.0));
        assert_eq!(far.band(35.0, 40.0), (35.0, 40.0));
    }

    #[test]
    fn a_chunk_across_the_distance_draws_each_mesh_on_its_side() {
        let lods = MeshLods {
            near: AssetId::from(bevy::asset::uuid::Uuid::from_u128(1)),
            far: AssetId::from(bevy::asset::uuid::Uuid::from_u128(2)),
            distance: 30.0,
        };
        let chunk =
            |x: f32| Aabb::from_min_max(Vec3::new(x, 0.0, 0.0), Vec3::new(x + 16.0, 1.0, 16.0));
        let eye = Vec3::ZERO;
        // Wholly nearer: the near mesh, every instance.
        assert_eq!(
            split(&lods, &chunk(5.0), 0.0, eye),
            [Some(Part::whole(lods.near, false)), None]
        );
        // Across: the near mesh before 30 m, the far one from it.
        let [Some(near), Some(far)] = split(&lods, &chunk(20.0), 0.0, eye) else {
            panic!("a chunk from 20 m to 41 m is split");
        };
        assert_eq!(
            (near.mesh, near.from, near.to, near.far),
            (lods.near, 0.0, 30.0, false)
        );
        assert_eq!(
            (far.mesh, far.from, far.to, far.far),
            (lods.far, 30.0, f32::INFINITY, true)
        );
        // Wholly beyond: the far mesh from 30 m (its instances all are).
        assert_eq!(split(&lods, &chunk(31.0), 0.0, eye)[0], Some(far));
        assert_eq!(split(&lods, &chunk(31.0), 0.0, eye)[1], None);
        // Meshes fading out into impostors by 30 m never reach the far mesh.
        assert_eq!(
            split(&lods, &chunk(20.0), 28.0, eye),
            [Some(Part::whole(lods.near, false)), None]
        );
    }

    #[test]
    fn distances_reach_the_boxs_nearest_and_farthest_points() {
        let bounds = Aabb::from_min_max(Vec3::new(3.0, 0.0, -4.0), Vec3::new(6.0, 1.0, 4.0));
        let (near, far) = distances(&bounds, Vec3::ZERO);
        assert_eq!(near, 3.0);
        assert!((far - (36.0f32 + 1.0 + 16.0).sqrt()).abs() < 1e-6);
        // Inside the box: nearest 0.
        assert_eq!(distances(&bounds, Vec3::new(4.0, 0.5, 0.0)).0, 0.0);
    }
}
