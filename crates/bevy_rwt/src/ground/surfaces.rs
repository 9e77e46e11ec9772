//! The game's meshes as a layer's ground: [`ScatterSurface`] marks them, [`SurfaceGround`]
//! combines the meshes of every marked entity for one layer.

use super::{Ground, GroundBounds, SurfaceHit, SurfaceMesh};
use bevy::prelude::*;
use std::sync::Arc;

/// Marks an entity's mesh, and the mesh of every entity below it (a glTF `WorldAssetRoot`), as
/// ground for the layers whose height source is [`crate::HeightSource::Surfaces`].
///
/// A marked mesh is ground for the layers it names (all of them for
/// [`ScatterSurface::all`]). For the other layers it is not ground, but it still covers
/// what lies under it: a top-most layer grows nothing where such a mesh is the highest
/// surface (no grass inside a rock that only moss grows on).
///
/// Moving a marked entity, changing its mesh, marking or unmarking it re-scatters only the
/// chunks under its old and new bounds; its triangles are gathered on the main thread and
/// indexed on the async compute pool.
#[derive(Component, Clone, Debug, Default, PartialEq, Reflect)]
#[reflect(Component, Clone, Debug, Default, PartialEq)]
pub struct ScatterSurface {
    /// The layer entities it is ground for; `None`: every layer on surfaces.
    pub layers: Option<Vec<Entity>>,
}

impl ScatterSurface {
    /// Ground for every layer on surfaces.
    pub fn all() -> Self {
        Self { layers: None }
    }

    /// Ground for these layers only.
    pub fn for_layers(layers: impl IntoIterator<Item = Entity>) -> Self {
        Self {
            layers: Some(layers.into_iter().collect()),
        }
    }

    /// Whether it is ground for `layer`.
    pub fn grows(&self, layer: Entity) -> bool {
        self.layers.as_ref().is_none_or(|l| l.contains(&layer))
    }
}

/// One layer's mesh ground: the meshes of every marked entity, each either the layer's
/// ground or a cover over it. An index of their ground rectangles finds the few meshes
/// above a point.
#[derive(Default)]
pub struct SurfaceGround {
    meshes: Vec<(Arc<SurfaceMesh>, bool)>,
    index: MeshIndex,
}

impl SurfaceGround {
    /// The ground of `meshes`, each with whether the layer grows on it (otherwise it only
    /// covers what lies under it). Order them the same way for the same world (by entity):
    /// it decides between surfaces of exactly one height.
    pub fn new(meshes: Vec<(Arc<SurfaceMesh>, bool)>) -> Self {
        let index = MeshIndex::new(meshes.iter().map(|(m, _)| m.ground_rect()));
        Self { meshes, index }
    }

    /// The meshes, with whether the layer grows on each.
    pub fn meshes(&self) -> &[(Arc<SurfaceMesh>, bool)] {
        &self.meshes
    }

    fn near(&self, p: Vec2) -> impl Iterator<Item = &(Arc<SurfaceMesh>, bool)> {
        self.index.at(p).iter().map(|&i| &self.meshes[i as usize])
    }
}

impl Ground for SurfaceGround {
    fn top(&self, p: Vec2) -> Option<SurfaceHit> {
        let mut best: Option<SurfaceHit> = None;
        self.hits(p, &mut |hit| {
            if best.is_none_or(|b| hit.height > b.height) {
                best = Some(hit);
            }
        });
        best.filter(|hit| hit.grows)
    }

    fn hits(&self, p: Vec2, visit: &mut dyn FnMut(SurfaceHit)) {
        for (mesh, grows) in self.near(p) {
            mesh.hits(p, &mut |hit| {
                visit(SurfaceHit {
                    grows: *grows,
                    ..hit
                })
            });
        }
    }

    fn bounds(&self, min: Vec2, max: Vec2) -> GroundBounds {
        let mut acc = GroundBounds::EMPTY;
        for (mesh, _) in self.meshes.iter().filter(|(_, grows)| *grows) {
            let b = mesh.bounds(min, max);
            acc = GroundBounds {
                max_surfaces: acc.max_surfaces + b.max_surfaces,
                ..acc.union(b)
            };
        }
        acc.covered = false;
        acc
    }
}

/// A uniform grid over the meshes' ground rectangles: each cell lists the meshes over it.
#[derive(Default)]
struct MeshIndex {
    origin: Vec2,
    cell: Vec2,
    dims: UVec2,
    cells: Vec<Vec<u32>>,
}

impl MeshIndex {
    /// Cells a side at most.
    const SIDE: u32 = 64;

    fn new(rects: impl Iterator<Item = (Vec2, Vec2)>) -> Self {
        let rects: Vec<(Vec2, Vec2)> = rects.collect();
        let (lo, hi) = rects
            .iter()
            .fold((Vec2::INFINITY, Vec2::NEG_INFINITY), |(lo, hi), r| {
                (lo.min(r.0), hi.max(r.1))
            });
        if !(lo.is_finite() && hi.is_finite()) {
            return Self::default();
        }
        let dims = UVec2::splat(Self::SIDE.min(rects.len() as u32 * 4).max(1));
        let cell = ((hi - lo) / dims.as_vec2()).max(Vec2::splat(1e-6));
        let mut index = Self {
            origin: lo,
            cell,
            dims,
            cells: vec![Vec::new(); (dims.x * dims.y) as usize],
        };
        for (i, (a, b)) in rects.iter().enumerate() {
            let (a, b) = (index.cell_at(*a), index.cell_at(*b));
            for y in a.y..=b.y {
                for x in a.x..=b.x {
                    index.cells[(y * dims.x + x) as usize].push(i as u32);
                }
            }
        }
        index
    }

    fn cell_at(&self, p: Vec2) -> UVec2 {
        let c = ((p - self.origin) / self.cell).floor();
        c.clamp(Vec2::ZERO, (self.dims.max(UVec2::ONE) - 1).as_vec2())
            .as_uvec2()
    }

    /// The meshes whose rectangles may hold `p`.
    fn at(&self, p: Vec2) -> &[u32] {
        if self.cells.is_empty() || !p.is_finite() {
            return &[];
        }
        let c = self.cell_at(p);
        &self.cells[(c.y * self.dims.x + c.x) as usize]
    }
}
