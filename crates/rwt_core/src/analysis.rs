//! Point set analysis: normalized minimum distance and nearest-neighbour statistics.

use crate::geometry::{BucketGrid, hex_spacing};
use glam::DVec2;

/// Smallest distance between two distinct points, or `None` with fewer than two points.
pub fn min_distance(points: &[DVec2]) -> Option<f64> {
    nearest_neighbour_distances(points)
        .into_iter()
        .reduce(f64::min)
}

/// Distance from every point to its nearest other point (plane, no wrapping). Points
/// without any other point get `f64::INFINITY`.
pub fn nearest_neighbour_distances(points: &[DVec2]) -> Vec<f64> {
    if points.len() < 2 {
        return vec![f64::INFINITY; points.len()];
    }
    let (mut min, mut max) = (points[0], points[0]);
    for &p in points {
        min = min.min(p);
        max = max.max(p);
    }
    let area = ((max.x - min.x) * (max.y - min.y)).max(1e-300);
    let cell = (area / points.len() as f64).sqrt().max(1e-12);
    let mut grid = BucketGrid::new(min, max, cell);
    for (i, &p) in points.iter().enumerate() {
        grid.insert(p, i as u32);
    }
    points
        .iter()
        .enumerate()
        .map(|(i, &p)| {
            let mut r = cell;
            loop {
                let mut best = f64::INFINITY;
                grid.for_each_near(p, r, |j| {
                    if j as usize != i {
                        best = best.min((points[j as usize] - p).length());
                    }
                });
                if best <= r || r > (max - min).length() + cell {
                    return best;
                }
                r *= 2.0;
            }
        })
        .collect()
}

/// Normalized minimum distance `rho = d_min / sqrt(2 / (sqrt(3) * density))`: 1 for a
/// hexagonal lattice, about 0.75 for good Poisson-disk sets, near 0 for white noise.
pub fn rho(points: &[DVec2], density: f64) -> Option<f64> {
    min_distance(points).map(|d| d / hex_spacing(density))
}

/// An averaged periodogram of point sets in square windows, with its radial statistics.
///
/// Frequencies are integer multiples of `1 / side`: at those, the window of a constant
/// density has no energy, so the DC term does not leak and white noise reads 1 everywhere.
#[derive(Clone, Debug)]
pub struct Spectrum {
    /// Frequencies per axis (`size x size`, zero at `size / 2`).
    pub size: usize,
    /// Power, row-major, `v` rows of `u`; 1 is the level of white noise.
    pub power: Vec<f64>,
    /// Mean power of each annulus `[r, r + 1)` (in units of `1 / side`).
    pub radial_mean: Vec<f64>,
    /// Anisotropy of each annulus, `10 log10(variance / mean^2)` in dB. Averaging `m`
    /// periodograms puts isotropic noise at about `-10 log10(m)`; spikes stand out above.
    pub anisotropy_db: Vec<f64>,
    /// Number of periodograms averaged.
    pub windows: usize,
}

impl Spectrum {
    /// Averages the periodograms of point sets, each in its own square window
    /// `[origin, origin + side)` (points outside are ignored).
    pub fn averaged(windows: &[(DVec2, Vec<DVec2>)], side: f64, size: usize) -> Spectrum {
        let size = size.max(4) & !1;
        let half = size as i64 / 2;
        let mut power = vec![0.0f64; size * size];
        let mut used = 0;
        for (origin, pts) in windows {
            let inside: Vec<DVec2> = pts
                .iter()
                .map(|p| (*p - *origin) / side)
                .filter(|q| q.x >= 0.0 && q.y >= 0.0 && q.x < 1.0 && q.y < 1.0)
                .collect();
            if inside.is_empty() {
                continue;
            }
            used += 1;
            let mut re = vec![0.0f64; size * size];
            let mut im = vec![0.0f64; size * size];
            let mut ex = vec![(0.0f64, 0.0f64); size];
            let mut ey = vec![(0.0f64, 0.0f64); size];
            for q in &inside {
                for (axis, table) in [(q.x, &mut ex), (q.y, &mut ey)] {
                    // exp(-2 pi i u x) for u = -half..half by rotation from u = -half.
                    let step = (-std::f64::consts::TAU * axis).sin_cos();
                    let start = (std::f64::consts::TAU * axis * half as f64).sin_cos();
                    let (mut c, mut s) = (start.1, start.0);
                    for slot in table.iter_mut() {
                        *slot = (c, s);
                        let (nc, ns) = (c * step.1 - s * step.0, c * step.0 + s * step.1);
                        c = nc;
                        s = ns;
                    }
                }
                for (v, &(cy, sy)) in ey.iter().enumerate() {
                    let row = v * size;
                    for (u, &(cx, sx)) in ex.iter().enumerate() {
                        re[row + u] += cx * cy - sx * sy;
                        im[row + u] += cx * sy + sx * cy;
                    }
                }
            }
            let n = inside.len() as f64;
            for i in 0..size * size {
                power[i] += (re[i] * re[i] + im[i] * im[i]) / n;
            }
        }
        let m = used.max(1) as f64;
        for p in &mut power {
            *p /= m;
        }
        power[(half as usize) * size + half as usize] = 0.0;
        let bins = half as usize;
        let (mut sum, mut sum2, mut count) = (vec![0.0; bins], vec![0.0; bins], vec![0usize; bins]);
        for v in 0..size {
            for u in 0..size {
                let (fu, fv) = (u as f64 - half as f64, v as f64 - half as f64);
                let r = (fu * fu + fv * fv).sqrt() as usize;
                if r == 0 || r >= bins {
                    continue;
                }
                let p = power[v * size + u];
                sum[r] += p;
                sum2[r] += p * p;
                count[r] += 1;
            }
        }
        let radial_mean: Vec<f64> = (0..bins)
            .map(|r| {
                if count[r] > 0 {
                    sum[r] / count[r] as f64
                } else {
                    0.0
                }
            })
            .collect();
        let anisotropy_db = (0..bins)
            .map(|r| {
                if count[r] < 2 || radial_mean[r] <= 0.0 {
                    return f64::NAN;
                }
                let mean = radial_mean[r];
                let var = (sum2[r] / count[r] as f64 - mean * mean).max(1e-300);
                10.0 * (var / (mean * mean)).log10()
            })
            .collect();
        Spectrum {
            size,
            power,
            radial_mean,
            anisotropy_db,
            windows: used,
        }
    }

    /// Mean radial power below `fraction` of the principal frequency of `density` points per
    /// unit area (`1 / hex_spacing`), for windows of side `side`: the blue-noise "hole".
    pub fn low_frequency_power(&self, side: f64, density: f64, fraction: f64) -> f64 {
        let cutoff = fraction * side / hex_spacing(density);
        let bins: Vec<f64> = (1..self.radial_mean.len())
            .filter(|&r| (r as f64) < cutoff)
            .map(|r| self.radial_mean[r])
            .collect();
        if bins.is_empty() {
            f64::NAN
        } else {
            bins.iter().sum::<f64>() / bins.len() as f64
        }
    }

    /// Mean anisotropy (dB) over the annuli from `from` to the end, ignoring empty ones.
    pub fn mean_anisotropy(&self, from: usize) -> f64 {
        let v: Vec<f64> = self
            .anisotropy_db
            .iter()
            .skip(from)
            .copied()
            .filter(|x| x.is_finite())
            .collect();
        v.iter().sum::<f64>() / v.len().max(1) as f64
    }

    /// Largest anisotropy (dB) over the annuli from `from` on.
    pub fn max_anisotropy(&self, from: usize) -> f64 {
        self.anisotropy_db
            .iter()
            .skip(from)
            .copied()
            .filter(|x| x.is_finite())
            .fold(f64::NEG_INFINITY, f64::max)
    }
}

/// Reference point sets, to show every quality figure next to what it should be compared
/// with. All fill the square `[origin, origin + side)` with about `count` points.
pub mod reference {
    use crate::rng::Rng;
    use crate::source_tile::DartThrowing;
    use glam::DVec2;

    /// The throughput floor of a query: `count` hashed white-noise points written to `out`
    /// as query results, in the square `[0, side)^2`. Benchmarks compare queries with this.
    pub fn white_noise_floor(count: usize, side: f64, out: &mut Vec<crate::query::Point>) {
        for i in 0..count as u64 {
            let h = crate::rng::mix64(i);
            out.push(crate::query::Point {
                position: DVec2::new(
                    crate::rng::unit_f64(h),
                    crate::rng::unit_f64(h.rotate_left(32)),
                ) * side,
                id: crate::query::PointId {
                    level: 0,
                    x: 0,
                    y: 0,
                    index: i as u16,
                },
                threshold: 0.0,
                class: 0,
            });
        }
    }

    /// Uniform random points (white noise).
    pub fn white_noise(origin: DVec2, side: f64, count: usize, seed: u64) -> Vec<DVec2> {
        let mut rng = Rng::new(seed, 0x3417e);
        (0..count)
            .map(|_| origin + DVec2::new(rng.next_f64(), rng.next_f64()) * side)
            .collect()
    }

    /// One random point in each cell of a `k x k` grid, `k = round(sqrt(count))`.
    pub fn jittered_grid(origin: DVec2, side: f64, count: usize, seed: u64) -> Vec<DVec2> {
        let k = (count as f64).sqrt().round().max(1.0) as usize;
        let cell = side / k as f64;
        let mut rng = Rng::new(seed, 0x717);
        let mut out = Vec::with_capacity(k * k);
        for j in 0..k {
            for i in 0..k {
                out.push(
                    origin
                        + (DVec2::new(i as f64, j as f64)
                            + DVec2::new(rng.next_f64(), rng.next_f64()))
                            * cell,
                );
            }
        }
        out
    }

    /// Classic dart throwing (Cook 1986): random darts, each kept when it is at least `r`
    /// from every kept one, until no dart fits; `r` is set so that the saturated set has a
    /// few more than `count` points, and the first `count` (a random subset) are returned.
    /// The window is cut from a torus twice as wide, so that it has the same window effects
    /// as a window cut from an infinite set.
    pub fn dart_throwing(origin: DVec2, side: f64, count: usize, seed: u64) -> Vec<DVec2> {
        let total = 4 * count.max(1);
        let mut rng = Rng::new(seed, 0xda27);
        let pool: Vec<DVec2> = (0..total * 30)
            .map(|_| DVec2::new(rng.next_f64(), rng.next_f64()))
            .collect();
        let r = 0.75 * crate::geometry::hex_spacing(total as f64);
        let mut grid = crate::geometry::BucketGrid::new(DVec2::ZERO, DVec2::ONE, r);
        let mut kept: Vec<DVec2> = Vec::with_capacity(total + total / 8);
        for &p in &pool {
            let mut free = true;
            for shift in crate::source_tile::torus_shifts(p, r) {
                grid.for_each_near(p + shift, r, |i| {
                    free &= (kept[i as usize] - (p + shift)).length_squared() >= r * r;
                });
            }
            if free {
                grid.insert(p, kept.len() as u32);
                kept.push(p);
            }
        }
        kept.truncate(total);
        kept.into_iter()
            .map(|p| p * 2.0 - DVec2::splat(0.5))
            .filter(|q| q.x >= 0.0 && q.y >= 0.0 && q.x < 1.0 && q.y < 1.0)
            .map(|q| origin + q * side)
            .collect()
    }

    /// A single progressive toroidal tile of `per_tile` points repeated on a lattice of tiles
    /// `tile` wide (the paper's figure 2, top): blue noise inside, periodic overall.
    pub fn periodic_tiling(
        origin: DVec2,
        side: f64,
        tile: f64,
        per_tile: usize,
        seed: u64,
    ) -> Vec<DVec2> {
        let pts = DartThrowing::new(per_tile).run(&mut Rng::new(seed, 0x9e71));
        let n = (side / tile).ceil() as i64;
        let mut out = Vec::new();
        for j in 0..n {
            for i in 0..n {
                for p in &pts {
                    let q = origin + (DVec2::new(i as f64, j as f64) + *p) * tile;
                    if q.x < origin.x + side && q.y < origin.y + side {
                        out.push(q);
                    }
                }
            }
        }
        out
    }

    /// A uniform blue-noise set warped to follow `density` (inverse-CDF warping, as used by
    /// earlier methods; the paper's figure 3 shows why direct generation is better).
    /// `density` is sampled on a `res x res` grid over the window.
    pub fn warped_uniform(
        origin: DVec2,
        side: f64,
        count: usize,
        density: impl Fn(DVec2) -> f64,
        res: usize,
        seed: u64,
    ) -> Vec<DVec2> {
        let res = res.max(2);
        let cell = side / res as f64;
        let value = |i: usize, j: usize| {
            let v = density(origin + DVec2::new(i as f64 + 0.5, j as f64 + 0.5) * cell);
            if v > 0.0 { v } else { 0.0 }
        };
        let columns: Vec<f64> = (0..res)
            .map(|i| (0..res).map(|j| value(i, j)).sum())
            .collect();
        let total: f64 = columns.iter().sum();
        if total <= 0.0 {
            return Vec::new();
        }
        let invert = |cdf: &[f64], u: f64| -> f64 {
            // Piecewise-linear inverse of a cumulative histogram, in cells.
            let target = u * cdf[cdf.len() - 1];
            let k = cdf.partition_point(|&c| c < target).min(cdf.len() - 1);
            let below = if k == 0 { 0.0 } else { cdf[k - 1] };
            let width = (cdf[k] - below).max(1e-300);
            k as f64 + ((target - below) / width).clamp(0.0, 1.0)
        };
        let mut column_cdf = Vec::with_capacity(res);
        let mut acc = 0.0;
        for c in &columns {
            acc += c;
            column_cdf.push(acc);
        }
        let uniform = dart_throwing(DVec2::ZERO, 1.0, count, seed);
        uniform
            .into_iter()
            .map(|u| {
                let x = invert(&column_cdf, u.x);
                let col = (x as usize).min(res - 1);
                let mut row_cdf = Vec::with_capacity(res);
                let mut a = 0.0;
                for j in 0..res {
                    a += value(col, j);
                    row_cdf.push(a);
                }
                let y = if a > 0.0 {
                    invert(&row_cdf, u.y)
                } else {
                    u.y * res as f64
                };
                origin + DVec2::new(x, y) * cell
            })
            .collect()
    }
}
