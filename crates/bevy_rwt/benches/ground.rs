//! Ground given as a function against the same ground as a mesh:
//! `cargo bench -p bevy_rwt --bench ground`.
//!
//! open_world's grass and flower densities (their noise and painted-like constants, height
//! range and level of detail) streamed along a flight over open_world's terrain function,
//! first on the function itself, then on a triangulated mesh of it (1.6 m quads, over
//! 200 000 triangles). Prints, for each, the time per point of the chunks the flight
//! generates, and for the mesh how long indexing it took and how many bytes it holds:
//!
//! `ground source=function points=N ns_per_point=X`
//! `ground source=mesh triangles=T points=N ns_per_point=Y build_ms=B bytes=M`

use bevy::prelude::*;
use bevy_rwt::GroundPlane;
use bevy_rwt::ground::{FunctionGround, GroundRule, GroundSettings, SharedGround, SurfaceMesh};
use bevy_rwt::rwt_core::density::{Constant, Density, NoiseDensity, NoiseParams};
use bevy_rwt::rwt_core::streaming::{ChunkSet, Falloff, StreamingConfig, Viewer};
use bevy_rwt::rwt_core::{Sampler, TileSet};
use glam::DVec2;
use noise::{Fbm, MultiFractal, NoiseFn, Perlin};
use std::sync::Arc;
use std::time::Instant;

/// open_world's water level and terrain (`src/terrain.rs`): fBm of Perlin noise, about
/// +-150 m over kilometre-wide hills.
const WATER: f32 = -30.0;

fn terrain() -> impl Fn(Vec2) -> f32 + Send + Sync + 'static {
    let hills = Fbm::<Perlin>::new(7).set_octaves(6);
    move |p: Vec2| 150.0 * hills.get([p.x as f64 / 2200.0, p.y as f64 / 2200.0]) as f32
}

/// The flight: along x from -300 to 300 m, 8 m a step.
const FLIGHT: (f32, f32, f32) = (-300.0, 300.0, 8.0);
/// Half the mesh's extent: the flight's load distance and a chunk beyond.
const HALF: Vec2 = Vec2::new(460.0, 160.0);
const QUAD: f32 = 1.6;

fn main() {
    let height = Arc::new(terrain());
    let function: SharedGround = Arc::new(FunctionGround::new(height.clone()));
    let (points, ns) = fly(&function);
    println!("ground source=function points={points} ns_per_point={ns:.1}");

    let (vertices, indices) = triangulate(height.as_ref());
    let started = Instant::now();
    let mesh = SurfaceMesh::from_world(vertices, &indices, GroundPlane::Xz, false, None)
        .expect("a valid mesh");
    let build_ms = started.elapsed().as_secs_f64() * 1e3;
    let (triangles, bytes) = (mesh.triangles(), mesh.bytes());
    let ground: SharedGround = Arc::new(bevy_rwt::ground::SurfaceGround::new(vec![(
        Arc::new(mesh),
        true,
    )]));
    let (mesh_points, mesh_ns) = fly(&ground);
    println!(
        "ground source=mesh triangles={triangles} points={mesh_points} ns_per_point={mesh_ns:.1} build_ms={build_ms:.1} bytes={bytes}"
    );
    println!(
        "ground ratio mesh/function ns_per_point={:.2} build_ms_per_100k_triangles={:.1} bytes_per_triangle={:.1}",
        mesh_ns / ns,
        build_ms * 1e5 / triangles as f64,
        bytes as f64 / triangles as f64
    );
}

/// A grid of `QUAD` quads over `-HALF..HALF`, two triangles each, counter-clockwise seen
/// from above.
fn triangulate(height: &dyn Fn(Vec2) -> f32) -> (Vec<Vec3>, Vec<u32>) {
    let n = (2.0 * HALF / QUAD).ceil().as_uvec2();
    let mut vertices = Vec::new();
    for j in 0..=n.y {
        for i in 0..=n.x {
            let p = -HALF + Vec2::new(i as f32, j as f32) * QUAD;
            vertices.push(Vec3::new(p.x, height(p), p.y));
        }
    }
    let at = |i: u32, j: u32| j * (n.x + 1) + i;
    let mut indices = Vec::new();
    for j in 0..n.y {
        for i in 0..n.x {
            let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
            indices.extend([a, c, b, a, d, c]);
        }
    }
    (vertices, indices)
}

/// One layer as open_world streams it.
struct Layer {
    densities: Vec<Box<dyn Density>>,
    tile_size: f64,
    seed: u64,
    streaming: StreamingConfig,
    falloff: Falloff,
    range: (f32, f32),
}

/// open_world's grass (up to 140 blades a square metre) and flowers (five classes).
fn layers() -> Vec<Layer> {
    let grass = NoiseDensity::new(NoiseParams {
        seed: 3,
        frequency: 1.0 / 120.0,
        octaves: 3,
        base: 0.45,
        amplitude: 0.9,
        scale: 140.0,
    });
    let streaming = |load: f64| StreamingConfig {
        chunk_size: 16.0,
        load_distance: load,
        unload_distance: load + 20.0,
        near_distance: 24.0,
    };
    vec![
        Layer {
            densities: vec![Box::new(grass)],
            tile_size: 4.0,
            seed: 3,
            streaming: streaming(120.0),
            falloff: Falloff::new(35.0, 115.0),
            range: (WATER + 0.3, 105.0),
        },
        Layer {
            densities: (0..5)
                .map(|_| Box::new(Constant(2.0)) as Box<dyn Density>)
                .collect(),
            tile_size: 8.0,
            seed: 5,
            streaming: streaming(100.0),
            falloff: Falloff::new(30.0, 95.0),
            range: (WATER + 0.5, 100.0),
        },
    ]
}

/// Generates every chunk the flight loads, at its level of detail, on `ground`: the points
/// and the time per point.
fn fly(ground: &SharedGround) -> (usize, f64) {
    let tiles = TileSet::embedded();
    let (mut points, mut seconds) = (0usize, 0.0f64);
    for layer in layers() {
        let sampler = Sampler::new(&tiles, layer.seed).with_tile_size(layer.tile_size);
        let rule = GroundRule::new(
            ground.clone(),
            GroundSettings {
                range: Some(layer.range),
                seed: layer.seed,
                ..GroundSettings::default()
            },
        );
        let mut chunks = ChunkSet::default();
        let (from, to, step) = FLIGHT;
        let mut x = from;
        while x <= to {
            let viewers = [Viewer::omni(DVec2::new(x as f64, 0.0))];
            let size = layer.streaming.chunk_size;
            for chunk in chunks.update(&layer.streaming, &viewers).load {
                let factor = layer
                    .falloff
                    .factor(layer.falloff.chunk_band(chunk, size, &viewers));
                let scaled: Vec<_> = layer
                    .densities
                    .iter()
                    .map(|d| bevy_rwt::rwt_core::density::Scale(d.as_ref(), factor))
                    .collect();
                let started = Instant::now();
                let out = rule
                    .points(&sampler, chunk.rect(size), &scaled)
                    .expect("in budget");
                seconds += started.elapsed().as_secs_f64();
                points += out.len();
            }
            x += step;
        }
    }
    (points, seconds * 1e9 / points.max(1) as f64)
}
