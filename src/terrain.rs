//! The showcase's unbounded terrain: a noise height field, shaded by slope and height, and
//! the ground mesh that follows the camera (fine near it, coarse to the horizon).

use bevy::asset::RenderAssetUsages;
use bevy::mesh::{Indices, PrimitiveTopology};
use bevy::prelude::*;
use bevy_rwt::HeightSource;
use noise::{Fbm, MultiFractal, NoiseFn, Perlin};
use std::sync::Arc;

/// Water level: valleys below it are lakes, where nothing grows.
pub const WATER: f32 = -30.0;
/// Texel-free ground colours (linear RGB).
const GRASS: Vec3 = Vec3::new(0.055, 0.13, 0.03);
const DRY: Vec3 = Vec3::new(0.16, 0.15, 0.05);
const ROCK: Vec3 = Vec3::new(0.17, 0.155, 0.135);
const SAND: Vec3 = Vec3::new(0.42, 0.36, 0.22);
const SNOW: Vec3 = Vec3::new(0.85, 0.87, 0.9);

/// The height field: fBm of Perlin noise, about +-150 m over kilometre-wide hills.
#[derive(Resource, Clone)]
pub struct Terrain {
    hills: Arc<Fbm<Perlin>>,
    patches: Arc<Perlin>,
}

impl Terrain {
    /// The terrain of `seed`.
    pub fn new(seed: u32) -> Self {
        Self {
            hills: Arc::new(Fbm::<Perlin>::new(seed).set_octaves(6)),
            patches: Arc::new(Perlin::new(seed + 1)),
        }
    }

    /// Ground height at `p` (x, z).
    pub fn height(&self, p: Vec2) -> f32 {
        150.0 * self.hills.get([p.x as f64 / 2200.0, p.y as f64 / 2200.0]) as f32
    }

    /// The height as the plugin reads it.
    pub fn source(&self) -> HeightSource {
        let terrain = self.clone();
        HeightSource::Function(Arc::new(move |p| terrain.height(p)))
    }

    /// The ground colour at `p` with height `h` and normal `n`: grass with dry patches,
    /// rock on steep slopes, sand on shores, snow on the heights.
    fn color(&self, p: Vec2, h: f32, n: Vec3) -> Vec3 {
        let steep = ((0.93 - n.y) / 0.15).clamp(0.0, 1.0);
        let dry = (self.patches.get([p.x as f64 / 90.0, p.y as f64 / 90.0]) as f32 * 1.5 + 0.2)
            .clamp(0.0, 1.0);
        let shore = ((WATER + 3.0 - h) / 3.0).clamp(0.0, 1.0);
        let snow = ((h - 105.0) / 15.0).clamp(0.0, 1.0) * (1.0 - steep * 0.7);
        GRASS
            .lerp(DRY, dry * 0.6)
            .lerp(ROCK, steep)
            .lerp(SAND, shore)
            .lerp(SNOW, snow)
    }
}

/// The ground grid's lines on one axis, as offsets from its centre: every 2 m to 240 m, then
/// 6 % farther apart each to 6 km. Each offset is on a lattice of its own spacing, so the
/// near lines stay put when the grid is re-centred on a multiple of 16 m.
fn grid_offsets() -> Vec<f32> {
    let mut half = vec![0.0f32];
    let mut step = 2.0f32;
    while *half.last().expect("non-empty") < 6000.0 {
        let last = *half.last().expect("non-empty");
        if last >= 240.0 {
            step = (step * 1.06).min(120.0);
        }
        half.push(((last + step) / 2.0).round() * 2.0);
    }
    let mut axis: Vec<f32> = half.iter().rev().map(|v| -v).collect();
    axis.extend(&half[1..]);
    axis
}

/// The ground mesh centred on `centre`: positions, normals and colours from the terrain.
pub fn ground_mesh(terrain: &Terrain, centre: Vec2) -> Mesh {
    let axis = grid_offsets();
    let n = axis.len();
    let heights: Vec<f32> = (0..n * n)
        .map(|k| terrain.height(centre + Vec2::new(axis[k % n], axis[k / n])))
        .collect();
    let at = |i: usize, j: usize| {
        let p = centre + Vec2::new(axis[i], axis[j]);
        Vec3::new(p.x, heights[j * n + i], p.y)
    };
    let mut positions = Vec::with_capacity(n * n);
    let mut normals = Vec::with_capacity(n * n);
    let mut colors = Vec::with_capacity(n * n);
    for j in 0..n {
        for i in 0..n {
            let (l, r) = (at(i.saturating_sub(1), j), at((i + 1).min(n - 1), j));
            let (d, u) = (at(i, j.saturating_sub(1)), at(i, (j + 1).min(n - 1)));
            let normal = (u - d).cross(r - l).normalize_or(Vec3::Y);
            let p = at(i, j);
            let c = terrain.color(p.xz(), p.y, normal);
            positions.push(p.to_array());
            normals.push(normal.to_array());
            colors.push([c.x, c.y, c.z, 1.0]);
        }
    }
    let mut indices = Vec::with_capacity((n - 1) * (n - 1) * 6);
    for j in 0..n - 1 {
        for i in 0..n - 1 {
            let a = (j * n + i) as u32;
            let (b, c, d) = (a + 1, a + n as u32, a + n as u32 + 1);
            indices.extend_from_slice(&[a, c, b, b, c, d]);
        }
    }
    Mesh::new(
        PrimitiveTopology::TriangleList,
        RenderAssetUsages::default(),
    )
    .with_inserted_attribute(Mesh::ATTRIBUTE_POSITION, positions)
    .with_inserted_attribute(Mesh::ATTRIBUTE_NORMAL, normals)
    .with_inserted_attribute(Mesh::ATTRIBUTE_COLOR, colors)
    .with_inserted_indices(Indices::U32(indices))
}

/// How far the camera may stray from the ground mesh's centre before it is rebuilt.
pub const GROUND_RECENTRE: f32 = 48.0;

/// The lattice point the ground mesh is centred on for a camera at `eye`.
pub fn ground_centre(eye: Vec2) -> Vec2 {
    (eye / 16.0).round() * 16.0
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_ground_grid_is_fine_near_and_reaches_the_horizon() {
        let axis = grid_offsets();
        assert!(axis.windows(2).all(|w| w[1] > w[0]), "increasing");
        let centre = axis.len() / 2;
        assert_eq!(axis[centre], 0.0);
        assert!(
            axis[centre + 1..]
                .iter()
                .take(100)
                .all(|v| v % 2.0 == 0.0 && *v <= 240.0)
        );
        assert!(
            *axis.last().unwrap() >= 6000.0 && axis.len() < 500,
            "{}",
            axis.len()
        );
        // Symmetric.
        assert!(axis.iter().zip(axis.iter().rev()).all(|(a, b)| *a == -*b));
    }
}
