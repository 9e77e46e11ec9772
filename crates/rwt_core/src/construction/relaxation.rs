//! Relaxation that makes every tile's points a subset of its subdivision (paper section 5.2,
//! figure 7), finished by an exact fixed-point snap.
//!
//! Each step pairs every base point with a distinct nearby subdivision point (greedy
//! matching by distance, so two base points never share one) and moves it a fraction of the
//! way there, for all tiles at once. Subdivision points are scaled copies of base points, so
//! they move too, by `1/n` as much; the process converges in a few dozen steps.
//!
//! The pairing then defines every position exactly: `X_t[k] = floor((a 2^32 + X_c[k']) / n)`.
//! Following the pairing from point to point always ends in a cycle; a cycle's positions are
//! the fixed point of a monotone contraction on integers, found by iteration, and every other
//! point follows from its successor. The result satisfies the subset property bit for bit.

use super::progressive::{Neighbours, Placed};
use crate::geometry::BucketGrid;
use glam::DVec2;
use rayon::prelude::*;

/// Result of relaxation.
#[derive(Clone, Debug)]
pub struct Relaxed {
    /// Fixed-point positions per tile (same order as the input).
    pub positions: Vec<Vec<[u32; 2]>>,
    /// For every base point, its subdivision partner `(cell, child point index)`.
    pub partner: Vec<Vec<(u16, u16)>>,
    /// Largest distance (tile units) between a base point and its partner before the snap.
    pub residual: f64,
    /// Largest distance a point moved during relaxation and snap, relative to the hexagonal
    /// spacing of `N` points.
    pub max_shift: f64,
    /// Points that found no subdivision point with the requested clearance in the last pass.
    pub crowded: usize,
    /// The smallest clearance among those (hexagonal spacings), `min_spacing` if none.
    pub crowded_clearance: f64,
}

fn subdivision_points(points: &[Vec<DVec2>], children: &[u16], n: usize) -> Vec<(DVec2, u16, u16)> {
    let mut out = Vec::with_capacity(n * n * points[0].len());
    for (cell, &c) in children.iter().enumerate() {
        let offset = DVec2::new((cell % n) as f64, (cell / n) as f64);
        for (k, &p) in points[c as usize].iter().enumerate() {
            out.push(((offset + p) / n as f64, cell as u16, k as u16));
        }
    }
    out
}

/// Subdivision points considered for a base point: the nearest few, then a wider ring when
/// none of those has room.
const NEAR_CANDIDATES: usize = 24;
const FAR_CANDIDATES: usize = 120;

/// Unused subdivision points of one tile near `p`, nearest first (at least `count` unless
/// the tile runs out).
fn gather(
    p: DVec2,
    count: usize,
    grid: &BucketGrid,
    sub: &[(DVec2, u16, u16)],
    used: &[bool],
    start: f64,
    out: &mut Vec<(f64, u32)>,
) {
    let mut search = start;
    loop {
        out.clear();
        grid.for_each_near(p, search, |j| {
            let d = (sub[j as usize].0 - p).length_squared();
            if !used[j as usize] && d <= search * search {
                out.push((d, j));
            }
        });
        if out.len() >= count || search > 0.5 {
            break;
        }
        search *= 1.5;
    }
    out.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
}

/// Relaxes `points` (per tile, tile coordinates, in progressive order) against the
/// subdivision `children` (per tile, `n * n` child indices) and snaps the result exactly.
///
/// Each pass moves every base point onto a subdivision point: the nearest unused one that is
/// at least `min_spacing` (relative to the hexagonal spacing of `N` points) from the points
/// already placed in its tile and in every tile that may neighbour it (`neighbours`, as in
/// [`crate::progressive`]); failing that, the candidate farthest from them. Points are placed
/// in progressive order, all tiles interleaved, except that points which found no room in the
/// previous pass go first: they take their place and their neighbours, which had room, adapt
/// around them, which dissolves jams within a few passes. Subdivision points move with their
/// tiles, so passes repeat until the pairing is stable; the snap then makes it exact.
pub fn relax(
    mut points: Vec<Vec<DVec2>>,
    children: &[Vec<u16>],
    neighbours: &Neighbours,
    n: usize,
    iterations: usize,
    min_spacing: f64,
    mut on_iteration: impl FnMut(),
) -> Relaxed {
    let big_n = points[0].len();
    let tiles = points.len();
    let hex = crate::geometry::hex_spacing(big_n as f64);
    let setup = PassSetup {
        neighbours,
        r_min: min_spacing * hex,
        hex,
        sub_spacing: 1.0 / (n as f64 * (big_n as f64).sqrt()),
    };
    let original = points.clone();
    let mut residual = 0.0f64;
    let mut partner: Vec<Vec<(u16, u16)>> = vec![vec![(0, 0); big_n]; tiles];
    // Passes in a row that left the pairing unchanged: two mean positions have settled.
    let mut stable_passes = 0;
    let mut failed: Vec<(usize, usize)> = Vec::new();
    let mut worst_clearance = f64::INFINITY;
    for it in 0..=iterations {
        let subs = Subdivisions::new(&points, children, n, setup.sub_spacing);
        if it == iterations || stable_passes >= 2 {
            residual = subs.residual(&partner, &points);
            break;
        }
        let pass = setup.pass(&points, &subs, &failed);
        stable_passes = if pass.partner == partner {
            stable_passes + 1
        } else {
            0
        };
        (partner, points, failed) = (pass.partner, pass.points, pass.failed);
        worst_clearance = pass.worst_clearance;
        on_iteration();
    }
    let positions = snap(&points, &partner, children, n);
    Relaxed {
        max_shift: max_shift(&positions, &original, hex),
        positions,
        partner,
        residual,
        crowded: failed.len(),
        crowded_clearance: if failed.is_empty() {
            min_spacing
        } else {
            worst_clearance
        },
    }
}

/// Every tile's subdivision points at the current positions, with a grid over each.
struct Subdivisions {
    points: Vec<Vec<(DVec2, u16, u16)>>,
    grids: Vec<BucketGrid>,
}

impl Subdivisions {
    fn new(points: &[Vec<DVec2>], children: &[Vec<u16>], n: usize, spacing: f64) -> Self {
        let subs: Vec<Vec<(DVec2, u16, u16)>> = (0..points.len())
            .into_par_iter()
            .map(|t| subdivision_points(points, &children[t], n))
            .collect();
        let grids = subs
            .par_iter()
            .map(|sub| {
                let mut g = BucketGrid::new(DVec2::ZERO, DVec2::ONE, spacing);
                for (j, s) in sub.iter().enumerate() {
                    g.insert(s.0, j as u32);
                }
                g
            })
            .collect();
        Self {
            points: subs,
            grids,
        }
    }

    /// How far the pairing is from exact: the largest base-to-partner distance.
    fn residual(&self, partner: &[Vec<(u16, u16)>], points: &[Vec<DVec2>]) -> f64 {
        let big_n = points[0].len();
        let mut residual = 0.0f64;
        for (t, tile) in points.iter().enumerate() {
            for (k, p) in tile.iter().enumerate() {
                let (cell, kk) = partner[t][k];
                let s = self.points[t][cell as usize * big_n + kk as usize].0;
                residual = residual.max((s - *p).length());
            }
        }
        residual
    }
}

/// What every pass shares.
struct PassSetup<'a> {
    neighbours: &'a Neighbours,
    /// Clearance asked of every pick.
    r_min: f64,
    /// Hexagonal spacing of `N` points.
    hex: f64,
    /// Spacing of the subdivision points.
    sub_spacing: f64,
}

/// The result of one pass: the pairing, the moved points, the points without room.
struct Pass {
    partner: Vec<Vec<(u16, u16)>>,
    points: Vec<Vec<DVec2>>,
    failed: Vec<(usize, usize)>,
    /// Smallest clearance among the failed points, in hexagonal spacings.
    worst_clearance: f64,
}

/// Points in the order a pass places them: last pass's failures first, then the rest in
/// progressive order with all tiles interleaved.
fn placement_order(failed: &[(usize, usize)], tiles: usize, big_n: usize) -> Vec<(usize, usize)> {
    let mut was_failed = vec![vec![false; big_n]; tiles];
    for &(t, k) in failed {
        was_failed[t][k] = true;
    }
    failed
        .iter()
        .copied()
        .chain(
            (0..big_n)
                .flat_map(|k| (0..tiles).map(move |t| (t, k)))
                .filter(|&(t, k)| !was_failed[t][k]),
        )
        .collect()
}

impl PassSetup<'_> {
    /// One pass: every base point moves onto a distinct nearby subdivision point.
    fn pass(&self, points: &[Vec<DVec2>], subs: &Subdivisions, failed: &[(usize, usize)]) -> Pass {
        let (tiles, big_n) = (points.len(), points[0].len());
        let mut chosen = Placed::new(tiles, self.r_min);
        let mut used: Vec<Vec<bool>> = subs.points.iter().map(|s| vec![false; s.len()]).collect();
        let mut out = Pass {
            partner: vec![vec![(0, 0); big_n]; tiles],
            points: points.to_vec(),
            failed: Vec::new(),
            worst_clearance: f64::INFINITY,
        };
        let mut candidates: Vec<(f64, u32)> = Vec::new();
        for (t, k) in placement_order(failed, tiles, big_n) {
            let (pick, best) = self.pick(t, points[t][k], subs, &used[t], &chosen, &mut candidates);
            if pick.is_none() {
                out.failed.push((t, k));
                out.worst_clearance = out.worst_clearance.min(best.0 / self.hex);
            }
            let j = pick.unwrap_or(best.1) as usize;
            used[t][j] = true;
            let (s, cell, kk) = subs.points[t][j];
            out.partner[t][k] = (cell, kk);
            out.points[t][k] = s;
            chosen.insert(t, s);
        }
        out
    }

    /// The nearest unused subdivision point of tile `t` with the requested clearance from
    /// the points placed so far, if any, and the one with the most clearance.
    fn pick(
        &self,
        t: usize,
        p: DVec2,
        subs: &Subdivisions,
        used: &[bool],
        chosen: &Placed,
        candidates: &mut Vec<(f64, u32)>,
    ) -> (Option<u32>, (f64, u32)) {
        let mut best = (-1.0f64, 0u32);
        for count in [NEAR_CANDIDATES, FAR_CANDIDATES] {
            let (grid, sub) = (&subs.grids[t], &subs.points[t]);
            gather(
                p,
                count,
                grid,
                sub,
                used,
                1.5 * self.sub_spacing,
                candidates,
            );
            for &(_, j) in candidates.iter() {
                let c = chosen.clearance(self.neighbours, t, sub[j as usize].0, self.r_min);
                if c >= self.r_min {
                    return (Some(j), best);
                }
                if c > best.0 {
                    best = (c, j);
                }
            }
        }
        (None, best)
    }
}

/// Largest distance a point moved, in hexagonal spacings.
fn max_shift(positions: &[Vec<[u32; 2]>], original: &[Vec<DVec2>], hex: f64) -> f64 {
    let mut max_shift = 0.0f64;
    for (t, tile) in positions.iter().enumerate() {
        for (k, p) in tile.iter().enumerate() {
            let q = DVec2::new(p[0] as f64, p[1] as f64) / crate::tileset::FIXED_ONE;
            max_shift = max_shift.max((q - original[t][k]).length() / hex);
        }
    }
    max_shift
}

/// Solves `X_t[k] = floor((cell_offset * 2^32 + X_c[k']) / n)` for all points exactly.
fn snap(
    points: &[Vec<DVec2>],
    partner: &[Vec<(u16, u16)>],
    children: &[Vec<u16>],
    n: usize,
) -> Vec<Vec<[u32; 2]>> {
    let big_n = points[0].len();
    let node = |t: usize, k: usize| t * big_n + k;
    let total = points.len() * big_n;
    let succ: Vec<usize> = (0..total)
        .map(|v| {
            let (t, k) = (v / big_n, v % big_n);
            let (cell, kk) = partner[t][k];
            node(children[t][cell as usize] as usize, kk as usize)
        })
        .collect();
    let cell_of = |v: usize| {
        let (t, k) = (v / big_n, v % big_n);
        let cell = partner[t][k].0 as u64;
        [cell % n as u64, cell / n as u64]
    };
    let apply = |v: usize, x: [u64; 2]| -> [u64; 2] {
        let c = cell_of(v);
        [
            ((c[0] << 32) + x[0]) / n as u64,
            ((c[1] << 32) + x[1]) / n as u64,
        ]
    };
    let mut value: Vec<[u64; 2]> = (0..total)
        .map(|v| {
            let p = points[v / big_n][v % big_n];
            let q = |x: f64| ((x * crate::tileset::FIXED_ONE) as u64).min(u32::MAX as u64);
            [q(p.x), q(p.y)]
        })
        .collect();
    solve_along_successors(&succ, apply, &mut value);
    (0..points.len())
        .map(|t| {
            (0..big_n)
                .map(|k| {
                    let v = value[node(t, k)];
                    [v[0] as u32, v[1] as u32]
                })
                .collect()
        })
        .collect()
}

/// Makes `value[v] = apply(v, value[succ[v]])` hold at every node `v` of the functional
/// graph `succ`: on each cycle by iterating its composed map to a fixed point, then on the
/// paths that lead into it, from the cycle outwards.
fn solve_along_successors(
    succ: &[usize],
    apply: impl Fn(usize, [u64; 2]) -> [u64; 2],
    value: &mut [[u64; 2]],
) {
    let mut state = vec![0u8; succ.len()]; // 0 new, 1 on current path, 2 solved
    let mut path = Vec::new();
    for start in 0..succ.len() {
        if state[start] == 2 {
            continue;
        }
        path.clear();
        let mut v = start;
        while state[v] == 0 {
            state[v] = 1;
            path.push(v);
            v = succ[v];
        }
        let mut solved_from = path.len();
        if state[v] == 1 {
            // Cycle: path[pos..] is v -> ... -> back to v.
            let pos = path
                .iter()
                .position(|&u| u == v)
                .expect("cycle start on path");
            let cycle = &path[pos..];
            let compose = |x: [u64; 2]| cycle.iter().rev().fold(x, |acc, &u| apply(u, acc));
            let mut x = value[cycle[0]];
            for _ in 0..256 {
                let y = compose(x);
                if y == x {
                    break;
                }
                x = y;
            }
            value[cycle[0]] = x;
            for i in (1..cycle.len()).rev() {
                let next = if i + 1 < cycle.len() {
                    cycle[i + 1]
                } else {
                    cycle[0]
                };
                value[cycle[i]] = apply(cycle[i], value[next]);
            }
            for &u in cycle {
                state[u] = 2;
            }
            solved_from = pos;
        }
        for i in (0..solved_from).rev() {
            let u = path[i];
            value[u] = apply(u, value[succ[u]]);
            state[u] = 2;
        }
    }
}
