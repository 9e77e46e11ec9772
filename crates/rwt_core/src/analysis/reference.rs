//! Reference point sets, to show every quality figure next to what it should be compared
//! with. All fill the square `[origin, origin + side)` with about `count` points.

#[cfg(feature = "build")]
use crate::dart_throwing::DartThrowing;
use crate::rng::Rng;
use glam::DVec2;

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
                    + (DVec2::new(i as f64, j as f64) + DVec2::new(rng.next_f64(), rng.next_f64()))
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
    // Darts drawn as they are thrown: 30 per kept point would be 480 bytes each held.
    let pool = (0..total * 30).map(|_| DVec2::new(rng.next_f64(), rng.next_f64()));
    let r = 0.75 * crate::geometry::hex_spacing(total as f64);
    let mut grid = crate::geometry::BucketGrid::new(DVec2::ZERO, DVec2::ONE, r);
    let mut kept: Vec<DVec2> = Vec::with_capacity(total + total / 8);
    for p in pool {
        let mut free = true;
        for shift in crate::geometry::torus_shifts(p, r) {
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

#[cfg(feature = "build")]
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
