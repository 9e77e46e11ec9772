//! How good can every prefix of one nested point sequence be, with no tiles at all? The
//! reference for the trough between levels: a sequence of `POINTS` points on the unit torus
//! whose every prefix of 50 points or more is scored by its normalized minimum distance,
//! first in farthest-point order (each point at the emptiest spot of a fine jittered grid),
//! then after `STEPS` steps of gradient ascent on a soft minimum of those scores with the
//! order kept (positions made for nested packing, free of any tile constraint).
//!
//! `cargo run --release -p rwt_core --example nested_bound` (`POINTS=600`, `STEPS=1500`,
//! `SEED=1`).
use glam::DVec2;
use rwt_core::rng::Rng;

/// Prefixes shorter than this are not scored (a handful of points on a torus is no set).
const FIRST_SCORED: usize = 50;
/// Hexagonal spacing of one point on the unit area: rho = distance / (this / sqrt(k)).
const HEX_ONE: f64 = 1.074_570_1;
/// Sharpness of the soft minimum (scores are near 0.7, so 60 weights the worst pairs).
const SOFTNESS: f64 = 60.0;

fn env(name: &str, default: usize) -> usize {
    std::env::var(name)
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(default)
}

/// Shortest torus offset from `b` to `a`.
fn wrap(a: DVec2, b: DVec2) -> DVec2 {
    let d = a - b;
    d - d.round()
}

/// Farthest-point order over a jittered `side x side` grid of candidates.
fn farthest_point(count: usize, side: usize, rng: &mut Rng) -> Vec<DVec2> {
    let grid: Vec<DVec2> = (0..side * side)
        .map(|i| {
            let cell = DVec2::new((i % side) as f64, (i / side) as f64);
            (cell + DVec2::new(rng.next_f64(), rng.next_f64())) / side as f64
        })
        .collect();
    let mut gap = vec![f64::INFINITY; grid.len()];
    let mut next = rng.below(grid.len());
    let mut out = Vec::with_capacity(count);
    for _ in 0..count {
        let p = grid[next];
        out.push(p);
        for (g, q) in gap.iter_mut().zip(&grid) {
            *g = g.min(wrap(*q, p).length_squared());
        }
        next = (0..grid.len())
            .max_by(|&a, &b| gap[a].total_cmp(&gap[b]))
            .expect("a grid");
    }
    out
}

/// The scored pairs `(i, j, weight)`: a pair first appears in the prefix of `j + 1` points
/// (`i < j`), whose normalized minimum distance is `distance * weight`.
fn scored_pairs(count: usize) -> Vec<(usize, usize, f64)> {
    (FIRST_SCORED - 1..count)
        .flat_map(|j| (0..j).map(move |i| (i, j, ((j + 1) as f64).sqrt() / HEX_ONE)))
        .collect()
}

/// The worst prefix score of `points`.
fn worst(points: &[DVec2], pairs: &[(usize, usize, f64)]) -> f64 {
    pairs
        .iter()
        .map(|&(i, j, w)| wrap(points[i], points[j]).length() * w)
        .fold(f64::INFINITY, f64::min)
}

/// One ascent step on the soft minimum of every pair's score; each point moves at most
/// `step`. Returns the worst score before the step.
fn ascend(points: &mut [DVec2], pairs: &[(usize, usize, f64)], step: f64) -> f64 {
    let low = worst(points, pairs);
    let mut grad = vec![DVec2::ZERO; points.len()];
    for &(i, j, w) in pairs {
        let d = wrap(points[i], points[j]);
        let len = d.length().max(1e-12);
        let weight = (-SOFTNESS * (len * w - low)).exp();
        if weight > 1e-9 {
            let push = d * (weight * w / len);
            grad[i] += push;
            grad[j] -= push;
        }
    }
    let largest = grad.iter().map(|g| g.length()).fold(1e-30, f64::max);
    for (p, g) in points.iter_mut().zip(&grad) {
        *p = (*p + *g * (step / largest)).rem_euclid(DVec2::ONE);
    }
    low
}

fn main() {
    let count = env("POINTS", 600).max(FIRST_SCORED + 1);
    let steps = env("STEPS", 1500);
    let mut rng = Rng::new(env("SEED", 1) as u64, 0x6e57);
    let mut points = farthest_point(count, 300, &mut rng);
    let pairs = scored_pairs(count);
    println!(
        "{count} points on the torus, every prefix of {FIRST_SCORED} or more: worst normalized minimum distance"
    );
    let start = worst(&points, &pairs);
    println!("  farthest-point order:                      {start:.3}");
    let step = 2e-4 * (1000.0 / count as f64).sqrt();
    let mut best = start;
    for _ in 0..steps {
        best = best.max(ascend(&mut points, &pairs, step));
    }
    best = best.max(worst(&points, &pairs));
    println!("  after {steps} ascent steps, order kept:       {best:.3}");
}
