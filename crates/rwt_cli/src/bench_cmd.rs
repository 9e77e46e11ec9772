//! `rwt bench`: query throughput and scaling, as ratios measured in one run (one thread),
//! and the parallel query's speedup.

use fast_poisson::Poisson2D;
use glam::DVec2;
use rwt_core::density::Placement;
use rwt_core::density::{Constant, Density, ImageDensity, NoiseDensity, NoiseParams};
use rwt_core::query::{Lattice, Point, Rect, Sampler};
use rwt_core::rng::Rng;
use rwt_core::tileset::TileSet;
use std::hint::black_box;
use std::time::Instant;

/// Best (smallest) wall time of `runs` runs of `f`, in seconds: noise only adds time, so the
/// minimum is the steadiest estimate on a shared machine.
fn best_time(runs: usize, mut f: impl FnMut()) -> f64 {
    let mut t: Vec<f64> = (0..runs)
        .map(|_| {
            let s = Instant::now();
            f();
            s.elapsed().as_secs_f64()
        })
        .collect();
    t.sort_by(f64::total_cmp);
    t[0]
}

/// A smooth painted-looking map: blobs and strokes, values in [0, 1].
pub fn synthetic_map(size: u32) -> Vec<f32> {
    let mut rng = Rng::new(5, 5);
    let blobs: Vec<(f64, f64, f64)> = (0..24)
        .map(|_| (rng.next_f64(), rng.next_f64(), 0.03 + 0.12 * rng.next_f64()))
        .collect();
    (0..size * size)
        .map(|i| {
            let (x, y) = (
                (i % size) as f64 / size as f64,
                (i / size) as f64 / size as f64,
            );
            let mut v: f64 = 0.15;
            for &(bx, by, r) in &blobs {
                let d2 = ((x - bx).powi(2) + (y - by).powi(2)) / (r * r);
                v += (-d2).exp();
            }
            v.min(1.0) as f32
        })
        .collect()
}

/// The 4-octave fBm density of the benchmark, averaging `d_uniform`.
fn bench_noise(d_uniform: f64) -> NoiseDensity {
    NoiseDensity::new(NoiseParams {
        seed: 3,
        frequency: 0.15,
        octaves: 4,
        base: 0.5,
        amplitude: 0.5,
        scale: 2.0 * d_uniform,
    })
}

/// Times one density (monomorphized, as a user's own density type would be).
fn measure<D: Density>(
    sampler: &Sampler,
    rect: Rect,
    runs: usize,
    out: &mut Vec<Point>,
    name: &str,
    d: &D,
) -> (String, usize, f64) {
    out.clear();
    let count = sampler.query(rect, d, out).unwrap_or(0);
    let t = best_time(runs, || {
        out.clear();
        black_box(sampler.query(rect, d, out).ok());
    });
    (name.to_string(), count, t)
}

/// What every part of the benchmark shares: one sampler over one square world.
struct Bench {
    set: TileSet,
    sampler: Sampler,
    /// Side of the world in base tiles.
    tiles: f64,
    rect: Rect,
    runs: usize,
    /// The uniform density of the throughput table.
    d_uniform: f64,
    out: Vec<Point>,
}

/// `rwt bench`.
pub fn run(quick: bool) -> Result<(), String> {
    let target = if quick { 400_000.0 } else { 2_000_000.0 };
    // A 32 x 32 tile world at about 1.5 N per tile, which uses levels 0 and 1.
    let tiles = 32.0;
    let set = TileSet::embedded();
    let sampler = Sampler::new(&set, 1).with_budget(100_000_000);
    let mut bench = Bench {
        set,
        sampler,
        tiles,
        rect: Rect::new(DVec2::ZERO, DVec2::splat(tiles)).map_err(|e| e.to_string())?,
        runs: if quick { 3 } else { 7 },
        d_uniform: target / (tiles * tiles),
        out: Vec::with_capacity(target as usize * 2),
    };
    let uniform_time = bench.throughput()?;
    bench.against_bridson(if quick { 50_000.0 } else { 200_000.0 });
    bench.scaling(uniform_time)?;
    bench.lattice()?;
    bench.parallel();
    Ok(())
}

impl Bench {
    /// Times one density over the whole world: `(name, points, seconds)`.
    fn measure<D: Density>(&mut self, name: &str, d: &D) -> (String, usize, f64) {
        measure(&self.sampler, self.rect, self.runs, &mut self.out, name, d)
    }

    /// Uniform, image and noise densities against the white-noise floor; returns the time
    /// of the uniform query.
    fn throughput(&mut self) -> Result<f64, String> {
        let (tiles, d_uniform) = (self.tiles, self.d_uniform);
        let map = synthetic_map(1024);
        let mean_map = map.iter().map(|&v| v as f64).sum::<f64>() / map.len() as f64;
        let scale = d_uniform / mean_map;
        let image = ImageDensity::from_values(
            1024,
            1024,
            &map,
            Placement {
                min: DVec2::ZERO,
                size: DVec2::splat(tiles),
                scale,
            },
        )
        .map_err(|e| e.to_string())?;
        let noise = bench_noise(d_uniform);
        let rows = vec![
            self.measure("uniform", &Constant(d_uniform)),
            self.measure("image (1024^2 map)", &image),
            self.measure("noise (4-octave fBm)", &noise),
        ];
        // White-noise floor: hashed random points written to the same output type.
        let floor_count = rows[0].1;
        let out = &mut self.out;
        let floor = best_time(self.runs, || {
            out.clear();
            rwt_core::bench::white_noise_floor(floor_count, tiles, out);
            black_box(&out);
        });
        self.print_throughput(&rows, floor_count, floor);
        Ok(rows[0].2)
    }

    fn print_throughput(&self, rows: &[(String, usize, f64)], floor_count: usize, floor: f64) {
        let floor_rate = floor_count as f64 / floor;
        say!(
            "one thread, best of {} runs each, {}x{} base tiles of {} points",
            self.runs,
            self.tiles,
            self.tiles,
            self.set.points_per_tile
        );
        say!(
            "{:<24} {:>10} {:>12} {:>14} {:>12}",
            "density",
            "points",
            "ms",
            "M points/s",
            "floor / this"
        );
        for (name, count, t) in rows {
            let rate = *count as f64 / t;
            say!(
                "{name:<24} {count:>10} {:>12.2} {:>14.1} {:>12.2}",
                t * 1e3,
                rate / 1e6,
                floor_rate / rate
            );
        }
        say!(
            "{:<24} {floor_count:>10} {:>12.2} {:>14.1} {:>12}",
            "white-noise floor",
            floor * 1e3,
            floor_rate / 1e6,
            "1.00"
        );
    }

    /// Bridson (fast_poisson) and this at the same number of points (Bridson is slow enough
    /// that the full-size count would dominate the run).
    fn against_bridson(&mut self, n_target: f64) {
        let tiles = self.tiles;
        let radius = (0.69 * tiles * tiles / n_target).sqrt();
        let mut bridson_count = 0;
        let bridson = best_time(1, || {
            let pts = Poisson2D::new()
                .with_dimensions([tiles, tiles], radius)
                .with_seed(1)
                .generate();
            bridson_count = pts.len();
            black_box(pts);
        });
        let same = Constant(bridson_count as f64 / (tiles * tiles));
        let (_, ours_count, ours_time) = self.measure("", &same);
        let ours_rate = ours_count as f64 / ours_time;
        let bridson_rate = bridson_count as f64 / bridson;
        say!(
            "fast_poisson (Bridson)   {bridson_count:>10} {:>12.2} {:>14.3}   this, {ours_count} points: {:.2} ms, {:.0}x faster",
            bridson * 1e3,
            bridson_rate / 1e6,
            ours_time * 1e3,
            ours_rate / bridson_rate
        );
    }

    /// What each seed's own lattice costs against the aligned one (the noise density, over
    /// the whole world and as the 64 chunks of 4 x 4 tiles a streaming world queries, for
    /// four seeds, the cases timed in turn): the seeded lattice's tiles are turned, so chunk
    /// borders cut their cells, and both chunks beside a border visit a cut cell. The
    /// aligned lattice's chunks moved 0.37 tiles off its cell lines show what cut cells
    /// cost it.
    fn lattice(&mut self) -> Result<(), String> {
        let noise = bench_noise(self.d_uniform);
        let (rect, out) = (self.rect, &mut self.out);
        let chunks = |offset: f64| -> Result<Vec<Rect>, String> {
            (0..64)
                .map(|k| {
                    let min = DVec2::new((k % 8) as f64, (k / 8) as f64) * 4.0 + offset;
                    Rect::new(min, min + 4.0).map_err(|e| e.to_string())
                })
                .collect()
        };
        let (on_lines, off_lines) = (chunks(0.0)?, chunks(0.37)?);
        // One run at a time: the cases take turns, so drift hits them alike.
        let mut time = |sampler: &Sampler, rects: &[Rect]| {
            best_time(1, || {
                out.clear();
                for r in rects {
                    black_box(sampler.query(*r, &noise, out).unwrap_or_default());
                }
            })
        };
        // Best times summed over the seeds: seeded whole, chunks; aligned whole, chunks,
        // chunks off the cell lines.
        let mut total = [0.0; 5];
        for seed in 1..=4 {
            let seeded = self.sampler.clone().with_seed(seed);
            let aligned = seeded.clone().with_lattice(Lattice::Aligned);
            let whole = std::slice::from_ref(&rect);
            let cases: [(&Sampler, &[Rect]); 5] = [
                (&seeded, whole),
                (&seeded, &on_lines),
                (&aligned, whole),
                (&aligned, &on_lines),
                (&aligned, &off_lines),
            ];
            let mut best = [f64::MAX; 5];
            for _ in 0..self.runs {
                for (b, (sampler, rects)) in best.iter_mut().zip(cases) {
                    *b = b.min(time(sampler, rects));
                }
            }
            for (sum, b) in total.iter_mut().zip(best) {
                *sum += b;
            }
        }
        say!(
            "seeded lattice over aligned (noise, 4 seeds): whole world {:.2}x, 4x4-tile chunks {:.2}x; \
             aligned chunks off its cell lines {:.2}x",
            total[0] / total[2],
            total[1] / total[3],
            total[4] / total[3]
        );
        Ok(())
    }

    /// The parallel query against the serial one, on the noise density (where a query's
    /// time goes into evaluating the density rather than writing points).
    fn parallel(&mut self) {
        let noise = bench_noise(self.d_uniform);
        let (sampler, rect, out) = (&self.sampler, self.rect, &mut self.out);
        let serial = best_time(self.runs, || {
            out.clear();
            black_box(sampler.query(rect, &noise, out).ok());
        });
        let parallel = best_time(self.runs, || {
            out.clear();
            black_box(sampler.query_par(rect, &noise, out).ok());
        });
        let runs = best_time(self.runs, || {
            black_box(sampler.query_par_runs(rect, &noise).ok());
        });
        say!(
            "noise (4-octave fBm) over the same world: serial {:.2} ms, parallel {:.2} ms \
             (both into a reused vector); as runs, a fresh vector per block: {:.2} ms, {:.2}x",
            serial * 1e3,
            parallel * 1e3,
            runs * 1e3,
            serial / runs
        );
        say!(
            "parallel: {} threads, speedup {:.2}",
            rayon::current_num_threads(),
            serial / parallel
        );
    }

    /// Cost against area and density, and of an all-zero density.
    fn scaling(&self, uniform_time: f64) -> Result<(), String> {
        let (sampler, runs, tiles, rect) = (&self.sampler, self.runs, self.tiles, self.rect);
        let time_of = |r: Rect, d: f64| {
            let mut o: Vec<Point> = Vec::with_capacity((d * r.area() * 1.1) as usize);
            best_time(runs, || {
                o.clear();
                black_box(sampler.query(r, &Constant(d), &mut o).ok());
            })
        };
        let half =
            Rect::new(DVec2::ZERO, DVec2::new(tiles / 2.0, tiles)).map_err(|e| e.to_string())?;
        let t_half = time_of(half, self.d_uniform);
        let t_full = time_of(rect, self.d_uniform);
        // Density doubling inside one subdivision level (3 N to 6 N per tile), on the half area.
        let level_one = 3.0 * self.set.points_per_tile as f64;
        let t_single = time_of(half, level_one);
        let t_double = time_of(half, 2.0 * level_one);
        let t_zero = best_time(runs, || {
            black_box(sampler.query(rect, &Constant(0.0), &mut Vec::new()).ok());
        });
        say!(
            "cost x area:    doubling the area takes {:.2}x the time",
            t_full / t_half
        );
        say!(
            "cost x density: doubling the density (3 N to 6 N per tile) takes {:.2}x the time",
            t_double / t_single
        );
        say!(
            "all-zero density over the whole world: {:.3} ms ({:.4} of the uniform query)",
            t_zero * 1e3,
            t_zero / uniform_time
        );
        Ok(())
    }
}
