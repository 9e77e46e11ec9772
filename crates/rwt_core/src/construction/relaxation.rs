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
    let r_min = min_spacing * hex;
    let sub_spacing = 1.0 / (n as f64 * (big_n as f64).sqrt());
    let original = points.clone();
    let mut residual = 0.0f64;
    let mut partner: Vec<Vec<(u16, u16)>> = vec![vec![(0, 0); big_n]; tiles];
    // Passes in a row that left the pairing unchanged: two mean positions have settled.
    let mut stable_passes = 0;
    let mut failed: Vec<(usize, usize)> = Vec::new();
    let mut worst_clearance = f64::INFINITY;
    let mut candidates: Vec<(f64, u32)> = Vec::new();
    for it in 0..=iterations {
        let subs: Vec<Vec<(DVec2, u16, u16)>> = (0..tiles)
            .into_par_iter()
            .map(|t| subdivision_points(&points, &children[t], n))
            .collect();
        let sub_grids: Vec<BucketGrid> = subs
            .par_iter()
            .map(|sub| {
                let mut g = BucketGrid::new(DVec2::ZERO, DVec2::ONE, sub_spacing);
                for (j, s) in sub.iter().enumerate() {
                    g.insert(s.0, j as u32);
                }
                g
            })
            .collect();
        if it == iterations || stable_passes >= 2 {
            // Measure how far the pairing is from exact, then stop.
            residual = 0.0;
            for t in 0..tiles {
                for k in 0..big_n {
                    let (cell, kk) = partner[t][k];
                    let s = subs[t][cell as usize * big_n + kk as usize].0;
                    residual = residual.max((s - points[t][k]).length());
                }
            }
            break;
        }
        let previous = partner.clone();
        let mut chosen = Placed::new(tiles, r_min);
        let mut used: Vec<Vec<bool>> = subs.iter().map(|s| vec![false; s.len()]).collect();
        let mut next = points.clone();
        let mut was_failed = vec![vec![false; big_n]; tiles];
        for &(t, k) in &failed {
            was_failed[t][k] = true;
        }
        let order: Vec<(usize, usize)> = failed
            .iter()
            .copied()
            .chain(
                (0..big_n)
                    .flat_map(|k| (0..tiles).map(move |t| (t, k)))
                    .filter(|&(t, k)| !was_failed[t][k]),
            )
            .collect();
        let mut failed_now = Vec::new();
        worst_clearance = f64::INFINITY;
        for (t, k) in order {
            let p = points[t][k];
            let clearance = |s: DVec2| chosen.clearance(neighbours, t, s, r_min);
            let mut pick = None;
            let mut best = (-1.0f64, 0u32);
            for count in [NEAR_CANDIDATES, FAR_CANDIDATES] {
                gather(
                    p,
                    count,
                    &sub_grids[t],
                    &subs[t],
                    &used[t],
                    1.5 * sub_spacing,
                    &mut candidates,
                );
                for &(_, j) in &candidates {
                    let c = clearance(subs[t][j as usize].0);
                    if c >= r_min {
                        pick = Some(j);
                        break;
                    }
                    if c > best.0 {
                        best = (c, j);
                    }
                }
                if pick.is_some() {
                    break;
                }
            }
            if pick.is_none() {
                failed_now.push((t, k));
                worst_clearance = worst_clearance.min(best.0 / hex);
            }
            let j = pick.unwrap_or(best.1) as usize;
            used[t][j] = true;
            let (s, cell, kk) = subs[t][j];
            partner[t][k] = (cell, kk);
            next[t][k] = s;
            chosen.insert(t, s);
        }
        stable_passes = if partner == previous {
            stable_passes + 1
        } else {
            0
        };
        failed = failed_now;
        points = next;
        on_iteration();
    }
    let positions = snap(&points, &partner, children, n);
    let mut max_shift = 0.0f64;
    for (t, tile) in positions.iter().enumerate() {
        for (k, p) in tile.iter().enumerate() {
            let q = DVec2::new(p[0] as f64, p[1] as f64) / crate::tileset::FIXED_ONE;
            max_shift = max_shift.max((q - original[t][k]).length() / hex);
        }
    }
    Relaxed {
        positions,
        partner,
        residual,
        max_shift,
        crowded: failed.len(),
        crowded_clearance: if failed.is_empty() {
            min_spacing
        } else {
            worst_clearance
        },
    }
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
    let mut state = vec![0u8; total]; // 0 new, 1 on current path, 2 solved
    let mut path = Vec::new();
    for start in 0..total {
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
