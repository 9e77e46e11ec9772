//! Query throughput: `cargo bench -p rwt_core`. Ratios between these are printed by
//! `rwt bench`, which measures everything in one run.

use divan::{Bencher, black_box};
use glam::DVec2;
use rwt_core::density::Placement;
use rwt_core::density::{Constant, ImageDensity, NoiseDensity, NoiseParams};
use rwt_core::query::{Point, Rect, Sampler};
use rwt_core::tileset::TileSet;

fn main() {
    divan::main();
}

const TILES: f64 = 16.0;
const POINTS: f64 = 500_000.0;

fn setup() -> (Sampler, Rect, Vec<Point>) {
    let set = TileSet::embedded();
    let sampler = Sampler::new(&set, 1);
    let rect = Rect::new(DVec2::ZERO, DVec2::splat(TILES)).unwrap();
    (sampler, rect, Vec::with_capacity(POINTS as usize * 2))
}

#[divan::bench(counter = divan::counter::ItemsCount::new(POINTS as usize))]
fn uniform(b: Bencher) {
    let (s, rect, mut out) = setup();
    let d = Constant(POINTS / (TILES * TILES));
    b.bench_local(|| {
        out.clear();
        black_box(s.query(rect, &d, &mut out).unwrap());
    });
}

#[divan::bench(counter = divan::counter::ItemsCount::new(POINTS as usize))]
fn image(b: Bencher) {
    let (s, rect, mut out) = setup();
    let size = 512u32;
    let map: Vec<f32> = (0..size * size)
        .map(|i| {
            0.3 + 0.7 * (((i % size) as f32 / 37.0).sin() * ((i / size) as f32 / 23.0).cos()).abs()
        })
        .collect();
    let mean = map.iter().map(|&v| v as f64).sum::<f64>() / map.len() as f64;
    let d = ImageDensity::from_values(
        size,
        size,
        &map,
        Placement {
            min: DVec2::ZERO,
            size: DVec2::splat(TILES),
            scale: POINTS / (TILES * TILES) / mean,
        },
    )
    .unwrap();
    b.bench_local(|| {
        out.clear();
        black_box(s.query(rect, &d, &mut out).unwrap());
    });
}

#[divan::bench(counter = divan::counter::ItemsCount::new(POINTS as usize))]
fn noise(b: Bencher) {
    let (s, rect, mut out) = setup();
    let d = NoiseDensity::new(NoiseParams {
        seed: 3,
        frequency: 0.2,
        octaves: 4,
        base: 0.5,
        amplitude: 0.5,
        scale: 2.0 * POINTS / (TILES * TILES),
    });
    b.bench_local(|| {
        out.clear();
        black_box(s.query(rect, &d, &mut out).unwrap());
    });
}

#[divan::bench(counter = divan::counter::ItemsCount::new(POINTS as usize))]
fn white_noise_floor(b: Bencher) {
    let mut out: Vec<Point> = Vec::with_capacity(POINTS as usize);
    b.bench_local(|| {
        out.clear();
        rwt_core::bench::white_noise_floor(POINTS as usize, TILES, &mut out);
        black_box(&out);
    });
}

#[divan::bench(sample_count = 3, counter = divan::counter::ItemsCount::new(50_000usize))]
fn bridson_fast_poisson(b: Bencher) {
    // About 50 000 points in the same square.
    let radius = (0.69 * TILES * TILES / 50_000.0).sqrt();
    b.bench_local(|| {
        black_box(
            fast_poisson::Poisson2D::new()
                .with_dimensions([TILES, TILES], radius)
                .with_seed(1)
                .generate(),
        );
    });
}
