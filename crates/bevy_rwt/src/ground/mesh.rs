//! One entity's mesh as ground: its world-space triangles in the plane's frame, in a uniform
//! grid over the plane. A vertical line through a point of the plane meets exactly the
//! triangles whose projection holds the point, so finding the surfaces above a point is a
//! point-in-triangle test against the few triangles of one grid cell; a max/min pyramid of
//! the cells bounds heights and slopes over any rectangle in a few cells' reads.
//!
//! Why not a 3-D BVH (parry3d, obvhs): every query here is a vertical line, which a 2-D
//! grid answers in O(1) with one cell's list; the pyramid gives the density bounds a BVH
//! does not keep; building is two linear passes; and the whole structure is about 40 bytes
//! a triangle (an indexed mesh's vertices and indices, the cells' lists and bounds).

use super::{GroundBounds, SurfaceHit};
use crate::look::GroundPlane;
use bevy::mesh::{Indices, PrimitiveTopology, VertexAttributeValues};
use bevy::prelude::*;

/// Why a mesh cannot be ground.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum MeshGroundError {
    /// It has no `Float32x3` positions.
    #[error("the mesh has no Float32x3 positions")]
    NoPositions,
    /// It is not a triangle list.
    #[error("the mesh is a {0:?}, not a triangle list")]
    Topology(PrimitiveTopology),
    /// An index points past its vertices.
    #[error("index {index} of a mesh of {vertices} vertices")]
    BadIndex {
        /// The index.
        index: u32,
        /// How many vertices the mesh has.
        vertices: usize,
    },
    /// More triangles than [`SurfaceMesh::MAX_TRIANGLES`].
    #[error("{triangles} triangles, over the limit of {limit}")]
    TooManyTriangles {
        /// How many the mesh has.
        triangles: usize,
        /// The limit.
        limit: usize,
    },
}

/// A mesh's triangles in its own space: what ground is made of, copied out of the mesh
/// (on the main thread) to be placed and indexed elsewhere.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MeshTriangles {
    /// Vertex positions.
    pub positions: Vec<Vec3>,
    /// Three vertex indices a triangle.
    pub indices: Vec<u32>,
}

impl MeshTriangles {
    /// The triangles of a triangle-list mesh with `Float32x3` positions.
    pub fn of(mesh: &Mesh) -> Result<Self, MeshGroundError> {
        if mesh.primitive_topology() != PrimitiveTopology::TriangleList {
            return Err(MeshGroundError::Topology(mesh.primitive_topology()));
        }
        let Some(VertexAttributeValues::Float32x3(positions)) =
            mesh.attribute(Mesh::ATTRIBUTE_POSITION)
        else {
            return Err(MeshGroundError::NoPositions);
        };
        let indices: Vec<u32> = match mesh.indices() {
            Some(Indices::U16(i)) => i.iter().map(|&i| i as u32).collect(),
            Some(Indices::U32(i)) => i.clone(),
            None => (0..positions.len() as u32).collect(),
        };
        let positions = positions.iter().map(|p| Vec3::from_array(*p)).collect();
        Ok(Self { positions, indices })
    }

    /// Their ground, placed by `transform` on `plane`, belonging to `entity`.
    pub fn place(
        self,
        transform: &GlobalTransform,
        plane: GroundPlane,
        entity: Option<Entity>,
    ) -> Result<SurfaceMesh, MeshGroundError> {
        let affine = transform.affine();
        let world = self
            .positions
            .into_iter()
            .map(|p| affine.transform_point3(p))
            .collect();
        // A transform that mirrors turns front faces around.
        let mirrored = affine.matrix3.determinant() < 0.0;
        SurfaceMesh::from_world(world, &self.indices, plane, mirrored, entity)
    }
}

/// Bounds of the triangles over one cell (or a block of cells, in the pyramid).
#[derive(Clone, Copy, Debug, PartialEq)]
struct CellBounds {
    min_height: f32,
    max_height: f32,
    /// Steepest upward-facing triangle.
    max_slope: f32,
    /// Upward-facing triangles over the cell: at most this many surfaces above a point.
    upward: u32,
}

impl CellBounds {
    const EMPTY: Self = Self {
        min_height: f32::INFINITY,
        max_height: f32::NEG_INFINITY,
        max_slope: 0.0,
        upward: 0,
    };

    fn union(self, o: Self) -> Self {
        Self {
            min_height: self.min_height.min(o.min_height),
            max_height: self.max_height.max(o.max_height),
            max_slope: self.max_slope.max(o.max_slope),
            upward: self.upward.max(o.upward),
        }
    }
}

/// One entity's mesh as ground, in world space (see the module's documentation).
#[derive(Debug)]
pub struct SurfaceMesh {
    entity: Option<Entity>,
    /// Vertices in the plane's frame: (u, height, v).
    vertices: Vec<Vec3>,
    /// Triangles whose projection on the plane has an area, wound so that their normal
    /// points the way the mesh's front face does.
    triangles: Vec<[u32; 3]>,
    /// The ground rectangle the triangles cover.
    min: Vec2,
    max: Vec2,
    /// Ground position of the grid's corner.
    origin: Vec2,
    /// Side of a cell.
    cell: f32,
    /// Cells along u and v.
    dims: UVec2,
    /// Per cell, where its triangles start in `refs` (one more than cells).
    starts: Vec<u32>,
    refs: Vec<u32>,
    /// Level 0: each cell; level `l`: blocks of `2^l` cells.
    pyramid: Vec<Vec<CellBounds>>,
}

impl SurfaceMesh {
    /// The most triangles one mesh may bring.
    pub const MAX_TRIANGLES: usize = 1 << 24;

    /// The ground of `mesh` placed by `transform`, on `plane`, belonging to `entity`.
    pub fn from_mesh(
        mesh: &Mesh,
        transform: &GlobalTransform,
        plane: GroundPlane,
        entity: Option<Entity>,
    ) -> Result<Self, MeshGroundError> {
        MeshTriangles::of(mesh)?.place(transform, plane, entity)
    }

    /// The ground of world-space `vertices` and triangle `indices` (three a triangle, a
    /// front face counter-clockwise unless `mirrored`), on `plane`.
    pub fn from_world(
        vertices: Vec<Vec3>,
        indices: &[u32],
        plane: GroundPlane,
        mirrored: bool,
        entity: Option<Entity>,
    ) -> Result<Self, MeshGroundError> {
        let triangles = indices.len() / 3;
        if triangles > Self::MAX_TRIANGLES {
            return Err(MeshGroundError::TooManyTriangles {
                triangles,
                limit: Self::MAX_TRIANGLES,
            });
        }
        if let Some(&index) = indices.iter().find(|&&i| i as usize >= vertices.len()) {
            return Err(MeshGroundError::BadIndex {
                index,
                vertices: vertices.len(),
            });
        }
        // The plane's frame swaps two axes for the x-y plane: a mirror.
        let flip = mirrored != (plane == GroundPlane::Xy);
        let vertices: Vec<Vec3> = vertices.into_iter().map(|v| frame(plane, v)).collect();
        let triangles: Vec<[u32; 3]> = indices
            .chunks_exact(3)
            .map(|t| {
                if flip {
                    [t[0], t[2], t[1]]
                } else {
                    [t[0], t[1], t[2]]
                }
            })
            .filter(|t| projected_area(&vertices, t).abs() > 0.0)
            .filter(|t| t.iter().all(|&i| vertices[i as usize].is_finite()))
            .collect();
        Ok(Self::build(vertices, triangles, entity))
    }

    fn build(vertices: Vec<Vec3>, triangles: Vec<[u32; 3]>, entity: Option<Entity>) -> Self {
        let (lo, hi) = triangles
            .iter()
            .flatten()
            .map(|&i| vertices[i as usize].xz())
            .fold((Vec2::INFINITY, Vec2::NEG_INFINITY), |(lo, hi), p| {
                (lo.min(p), hi.max(p))
            });
        let span = (hi - lo).max(Vec2::splat(1e-6));
        // About one cell per two triangles.
        let cells = (triangles.len() as f32 * 0.5).max(1.0);
        let cell = (span.x * span.y / cells)
            .sqrt()
            .max(span.max_element() / 4096.0);
        let dims = (span / cell).ceil().as_uvec2().max(UVec2::ONE);
        let (lo, hi) = if lo.is_finite() {
            (lo, hi)
        } else {
            (Vec2::ZERO, Vec2::ZERO)
        };
        let mut mesh = Self {
            entity,
            vertices,
            triangles,
            min: lo,
            max: hi,
            origin: lo,
            cell,
            dims,
            starts: Vec::new(),
            refs: Vec::new(),
            pyramid: Vec::new(),
        };
        mesh.fill_cells();
        mesh
    }

    /// Lists each triangle in the cells its bounding box overlaps, and bounds each cell.
    fn fill_cells(&mut self) {
        let n = (self.dims.x * self.dims.y) as usize;
        let mut counts = vec![0u32; n + 1];
        let mut bounds = vec![CellBounds::EMPTY; n];
        for t in &self.triangles {
            let own = self.triangle_bounds(t);
            for c in self.cells_of(t) {
                counts[c] += 1;
                bounds[c] = bounds[c].union(own);
            }
        }
        let mut start = 0;
        for c in counts.iter_mut() {
            let count = *c;
            *c = start;
            start += count;
        }
        let mut fill = counts.clone();
        let mut refs = vec![0u32; start as usize];
        for (i, t) in self.triangles.iter().enumerate() {
            for c in self.cells_of(t) {
                refs[fill[c] as usize] = i as u32;
                fill[c] += 1;
            }
        }
        self.starts = counts;
        self.refs = refs;
        self.pyramid = pyramid(bounds, self.dims);
    }

    fn triangle_bounds(&self, t: &[u32; 3]) -> CellBounds {
        let [a, b, c] = t.map(|i| self.vertices[i as usize]);
        let normal = (b - a).cross(c - a);
        let upward = normal.y > 0.0;
        CellBounds {
            min_height: a.y.min(b.y).min(c.y),
            max_height: a.y.max(b.y).max(c.y),
            max_slope: if upward {
                normal.xz().length() / normal.y
            } else {
                0.0
            },
            upward: upward as u32,
        }
    }

    /// The cells a triangle's bounding box overlaps.
    fn cells_of(&self, t: &[u32; 3]) -> impl Iterator<Item = usize> + use<> {
        let [a, b, c] = t.map(|i| self.vertices[i as usize].xz());
        let lo = self.cell_at(a.min(b).min(c));
        let hi = self.cell_at(a.max(b).max(c));
        let width = self.dims.x as usize;
        (lo.y..=hi.y).flat_map(move |y| (lo.x..=hi.x).map(move |x| y as usize * width + x as usize))
    }

    /// The cell holding `p`, clamped to the grid.
    fn cell_at(&self, p: Vec2) -> UVec2 {
        let c = ((p - self.origin) / self.cell).floor();
        c.clamp(Vec2::ZERO, (self.dims - 1).as_vec2()).as_uvec2()
    }

    /// The entity this mesh belongs to.
    pub fn entity(&self) -> Option<Entity> {
        self.entity
    }

    /// How many triangles it keeps (those with an area on the plane).
    pub fn triangles(&self) -> usize {
        self.triangles.len()
    }

    /// The ground rectangle its triangles cover.
    pub fn ground_rect(&self) -> (Vec2, Vec2) {
        (self.min, self.max)
    }

    /// Bytes it holds.
    pub fn bytes(&self) -> usize {
        use std::mem::size_of;
        self.vertices.capacity() * size_of::<Vec3>()
            + self.triangles.capacity() * size_of::<[u32; 3]>()
            + (self.starts.capacity() + self.refs.capacity()) * size_of::<u32>()
            + self
                .pyramid
                .iter()
                .map(|l| l.capacity() * size_of::<CellBounds>())
                .sum::<usize>()
    }

    /// Every surface of the mesh above `p`.
    pub fn hits(&self, p: Vec2, visit: &mut dyn FnMut(SurfaceHit)) {
        let (lo, hi) = self.ground_rect();
        if !(p.cmpge(lo).all() && p.cmple(hi).all()) {
            return;
        }
        let c = self.cell_at(p);
        let cell = (c.y * self.dims.x + c.x) as usize;
        let refs = &self.refs[self.starts[cell] as usize..self.starts[cell + 1] as usize];
        for &t in refs {
            if let Some(hit) = self.hit(&self.triangles[t as usize], p) {
                visit(hit);
            }
        }
    }

    /// Where the vertical line through `p` meets triangle `t`, if its projection holds `p`.
    /// A point on an edge two triangles share belongs to exactly one of them: each edge is
    /// evaluated with its end points in one order whichever triangle asks.
    fn hit(&self, t: &[u32; 3], p: Vec2) -> Option<SurfaceHit> {
        let v = t.map(|i| self.vertices[i as usize]);
        let area = projected_area(&self.vertices, t);
        let mut w = [0.0f64; 3];
        for (k, weight) in w.iter_mut().enumerate() {
            // The edge opposite vertex k, counter-clockwise in the plane when area > 0.
            let (i, j) = (t[(k + 1) % 3], t[(k + 2) % 3]);
            let e = edge(&self.vertices, i, j, p);
            let e = if area > 0.0 { e } else { -e };
            if e < 0.0 || (e == 0.0 && !owns_edge(&self.vertices, i, j, area > 0.0)) {
                return None;
            }
            *weight = e;
        }
        let sum = w[0] + w[1] + w[2];
        if sum <= 0.0 {
            return None;
        }
        let height = (w[0] * v[0].y as f64 + w[1] * v[1].y as f64 + w[2] * v[2].y as f64) / sum;
        let normal = (v[1] - v[0]).cross(v[2] - v[0]).normalize_or_zero();
        Some(SurfaceHit {
            height: height as f32,
            normal,
            entity: self.entity,
            grows: true,
        })
    }

    /// What the surfaces over `min..=max` are bounded by.
    pub fn bounds(&self, min: Vec2, max: Vec2) -> GroundBounds {
        let (lo, hi) = self.ground_rect();
        if max.cmplt(lo).any() || min.cmpgt(hi).any() {
            return GroundBounds::EMPTY;
        }
        let (a, b) = (self.cell_at(min), self.cell_at(max));
        // The level at which the rectangle spans at most 4 blocks a side.
        let span = (b - a).max_element();
        let level = (32 - (span / 4).leading_zeros()) as usize;
        let level = level.min(self.pyramid.len() - 1);
        let (a, b) = (a >> level as u32, b >> level as u32);
        let width = self.dims.x.div_ceil(1 << level);
        let cells = &self.pyramid[level];
        let mut acc = CellBounds::EMPTY;
        for y in a.y..=b.y {
            for x in a.x..=b.x {
                acc = acc.union(cells[(y * width + x) as usize]);
            }
        }
        if acc.min_height > acc.max_height {
            return GroundBounds::EMPTY;
        }
        GroundBounds {
            min_height: acc.min_height,
            max_height: acc.max_height,
            max_slope: acc.max_slope,
            max_surfaces: acc.upward,
            covered: false,
        }
    }
}

/// World point `v` in the frame of `plane`: (u, height, v).
fn frame(plane: GroundPlane, v: Vec3) -> Vec3 {
    let ground = plane.ground_of(v);
    let height = match plane {
        GroundPlane::Xz => v.y,
        GroundPlane::Xy => v.z,
    };
    Vec3::new(ground.x, height, ground.y)
}

/// Twice the signed area of a triangle's projection (positive counter-clockwise seen from
/// above, that is for an upward-facing front face).
fn projected_area(vertices: &[Vec3], t: &[u32; 3]) -> f64 {
    let [a, b, c] = t.map(|i| vertices[i as usize].xz().as_dvec2());
    // Counter-clockwise seen from +y with x right and z down the page is clockwise in (x, z).
    -((b - a).perp_dot(c - a))
}

/// The edge function of `i -> j` at `p` (positive on the left of the edge as seen from
/// above), computed with the end points in index order so that both triangles sharing the
/// edge get the same value, negated.
fn edge(vertices: &[Vec3], i: u32, j: u32, p: Vec2) -> f64 {
    let (lo, hi, sign) = if i < j { (i, j, 1.0) } else { (j, i, -1.0) };
    let a = vertices[lo as usize].xz().as_dvec2();
    let b = vertices[hi as usize].xz().as_dvec2();
    -sign * (b - a).perp_dot(p.as_dvec2() - a)
}

/// Whether a point exactly on edge `i -> j` belongs to the triangle on its left (the one
/// whose counter-clockwise order runs `i -> j`): a fixed rule on the edge's direction, so
/// that of two triangles sharing it exactly one owns it.
fn owns_edge(vertices: &[Vec3], i: u32, j: u32, counter_clockwise: bool) -> bool {
    let (a, b) = if counter_clockwise { (i, j) } else { (j, i) };
    let d = vertices[b as usize].xz() - vertices[a as usize].xz();
    d.x > 0.0 || (d.x == 0.0 && d.y > 0.0)
}

/// The max/min pyramid of cell bounds, down to one block.
fn pyramid(base: Vec<CellBounds>, dims: UVec2) -> Vec<Vec<CellBounds>> {
    let mut levels = Vec::new();
    let mut prev = base;
    let mut size = dims;
    while size.x > 1 || size.y > 1 {
        let next = (size + 1) / 2;
        let mut out = vec![CellBounds::EMPTY; (next.x * next.y) as usize];
        for y in 0..size.y {
            for x in 0..size.x {
                let at = ((y / 2) * next.x + x / 2) as usize;
                out[at] = out[at].union(prev[(y * size.x + x) as usize]);
            }
        }
        levels.push(std::mem::replace(&mut prev, out));
        size = next;
    }
    levels.push(prev);
    levels
}
