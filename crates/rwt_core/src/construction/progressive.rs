//! Progressive ranking with a spacing guarantee across tile borders (paper section 4,
//! figure 5; section 5.2, figure 8).
//!
//! The paper fixes ranks one at a time, giving rank `i` to the first point (in the
//! interleaved source order) whose distance to the points already ranked exceeds
//! `alpha / sqrt(i)`. We do the same in *threshold space* and for all tiles at once:
//! each point has a threshold `tau` (it appears once a tile holds `tau` points per unit
//! area). Points are visited in increasing `tau`; a point closer than `alpha / sqrt(tau)` to
//! an accepted point is postponed to exactly the threshold at which that distance becomes
//! acceptable, `alpha^2 / d^2`. Distances are measured within the tile *and* against every
//! tile that can lie next to it at each of the 8 neighbour offsets, which is what makes the
//! guarantee hold in any tiling, including across corners where Wang tiles do not constrain
//! diagonal neighbours (the "corner problem"). Postponing only removes points from prefixes,
//! so it can never create a close pair.
//!
//! Invariant: any two accepted points `p, q` that can be neighbours satisfy
//! `|p - q| >= alpha / sqrt(max(tau_p, tau_q))`, except points pushed to `cap` (the full
//! set, where every point must be present anyway).

use crate::geometry::BucketGrid;
use crate::wang::EdgeColors;
use glam::DVec2;
use std::cmp::Reverse;
use std::collections::BinaryHeap;

/// A point to rank.
#[derive(Clone, Copy, Debug)]
pub struct Candidate {
    /// Position in the tile frame `[0, 1)^2`.
    pub pos: DVec2,
    /// Earliest threshold (the order it would have without conflicts).
    pub tau0: f64,
    /// Already ranked (accepted at `tau0` without checks), e.g. base points of a subdivision.
    pub fixed: bool,
}

/// The 8 neighbour offsets, in the order of [`Neighbours`] entries.
pub const OFFSETS: [(i32, i32); 8] = [
    (1, 0),
    (-1, 0),
    (0, 1),
    (0, -1),
    (1, 1),
    (-1, 1),
    (1, -1),
    (-1, -1),
];

/// For each tile, for each offset in [`OFFSETS`], the tiles that may lie there.
pub type Neighbours = Vec<[Vec<u16>; 8]>;

struct Accepted {
    grid: BucketGrid,
    points: Vec<DVec2>,
}

impl Accepted {
    fn min_distance(&self, p: DVec2, r: f64, brute_force_cells: f64) -> f64 {
        let mut best2 = r * r;
        if (r / brute_force_cells) > 8.0 && self.points.len() < 4096 {
            for q in &self.points {
                best2 = best2.min((*q - p).length_squared());
            }
        } else {
            self.grid.for_each_near(p, r, |i| {
                best2 = best2.min((self.points[i as usize] - p).length_squared());
            });
        }
        best2.sqrt()
    }
}

/// Points placed so far in every tile of a set, for spacing checks that include every tile
/// that may lie next to a tile. Shared by the rankings and by relaxation.
pub struct Placed {
    tiles: Vec<Accepted>,
    cell: f64,
}

impl Placed {
    /// No points yet, in `tiles` tiles, indexed with cells of about `cell` (the smallest
    /// spacing that will be checked).
    pub fn new(tiles: usize, cell: f64) -> Self {
        Self {
            tiles: (0..tiles)
                .map(|_| Accepted {
                    grid: BucketGrid::new(DVec2::ZERO, DVec2::ONE, cell),
                    points: Vec::new(),
                })
                .collect(),
            cell,
        }
    }

    /// Places `p` in tile `t`.
    pub fn insert(&mut self, t: usize, p: DVec2) {
        let acc = &mut self.tiles[t];
        acc.grid.insert(p, acc.points.len() as u32);
        acc.points.push(p);
    }

    /// Distance from `p` (in tile `t`'s frame) to the nearest point placed in `t` or in any
    /// tile that may lie at any of the 8 offsets, capped at `r`.
    pub fn clearance(&self, neighbours: &Neighbours, t: usize, p: DVec2, r: f64) -> f64 {
        let mut d = self.tiles[t].min_distance(p, r, self.cell);
        for (o, &(dx, dy)) in OFFSETS.iter().enumerate() {
            let shifted = p - DVec2::new(dx as f64, dy as f64);
            // Only offsets whose tile the disc reaches.
            if shifted.x < -d || shifted.x > 1.0 + d || shifted.y < -d || shifted.y > 1.0 + d {
                continue;
            }
            for &u in &neighbours[t][o] {
                d = d.min(self.tiles[u as usize].min_distance(shifted, d, self.cell));
            }
        }
        d
    }
}

/// Assigns thresholds to every candidate of every tile; returns `tau` per candidate.
///
/// `alpha` is the spacing constant (the paper uses 0.5; 0.75 keeps the normalized minimum
/// distance of every prefix near 0.7), `cap` the largest threshold (the full density).
pub fn rank(
    tiles: &[Vec<Candidate>],
    neighbours: &Neighbours,
    alpha: impl Fn(f64) -> f64,
    cap: f64,
) -> Vec<Vec<f64>> {
    let mut placed = Placed::new(tiles.len(), alpha(cap) / cap.sqrt());
    let mut tau: Vec<Vec<f64>> = tiles.iter().map(|c| vec![f64::NAN; c.len()]).collect();
    let mut heap = BinaryHeap::new();
    for (t, cands) in tiles.iter().enumerate() {
        for (i, c) in cands.iter().enumerate() {
            if c.fixed {
                tau[t][i] = c.tau0;
                placed.insert(t, c.pos);
            } else {
                let tau0 = c.tau0.clamp(1e-9, cap);
                heap.push(Reverse((tau0.to_bits(), t as u32, i as u32)));
            }
        }
    }
    while let Some(Reverse((bits, t, i))) = heap.pop() {
        let (t, i) = (t as usize, i as usize);
        let tau_now = f64::from_bits(bits);
        let p = tiles[t][i].pos;
        let a = alpha(tau_now);
        let r = a / tau_now.sqrt();
        let d = placed.clearance(neighbours, t, p, r);
        if d < r && tau_now < cap {
            // Postpone to where this distance is allowed: `alpha` never grows with tau, so
            // `a^2 / d^2` never overshoots that threshold.
            let wanted = if d > 0.0 { a * a / (d * d) } else { cap };
            let next = wanted.max(tau_now * (1.0 + 1e-12)).min(cap);
            heap.push(Reverse((next.to_bits(), t as u32, i as u32)));
            continue;
        }
        tau[t][i] = tau_now;
        placed.insert(t, p);
    }
    tau
}

/// How far ahead in the threshold order the prefix pass looks for a point with room.
#[derive(Clone, Copy, Debug)]
pub struct Lookahead {
    /// Window (in points) searched for the first point with room; `usize::MAX` searches the
    /// whole remaining order.
    pub window: usize,
    /// When no point in the window has room: the one with the most room among this many.
    pub fallback: usize,
}

/// For each tile `u`: the tiles whose candidates a point placed in `u` constrains, with the
/// offset that takes `u`'s frame to theirs (the tile itself first, offset zero).
fn constrained_by(neighbours: &Neighbours) -> Vec<Vec<(usize, DVec2)>> {
    let mut affects: Vec<Vec<(usize, DVec2)>> = (0..neighbours.len())
        .map(|u| vec![(u, DVec2::ZERO)])
        .collect();
    for (t, around) in neighbours.iter().enumerate() {
        for (o, &(dx, dy)) in OFFSETS.iter().enumerate() {
            for &u in &around[o] {
                affects[u as usize].push((t, DVec2::new(dx as f64, dy as f64)));
            }
        }
    }
    affects
}

/// The paper's figure 5 in rank space, on top of a threshold order: ranks are fixed one at a
/// time, in lockstep over all tiles, and rank `k` goes to the first point (in `order`, within
/// the [`Lookahead`]) that keeps `alpha / sqrt(k + 1)` from the tile's earlier ranks and from
/// those of every tile that may neighbour it. When none does, the one with the most room
/// takes it. Only ranks in `ranks` are fixed; the earlier ones are kept as they are (for a
/// subdivision, its base points). `order[t]` is rewritten in place; returns how many ranks
/// found no such point.
pub fn repair_prefixes(
    tiles: &[Vec<Candidate>],
    order: &mut [Vec<usize>],
    neighbours: &Neighbours,
    alpha: f64,
    lookahead: Lookahead,
    ranks: std::ops::Range<usize>,
) -> usize {
    let len = order.iter().map(Vec::len).min().unwrap_or(0);
    let (fixed, until) = (ranks.start.min(len), ranks.end.min(len));
    let radius = |k: usize| alpha / ((k + 1) as f64).sqrt();
    let affects = constrained_by(neighbours);
    let grids = candidate_grids(tiles, radius(len));
    // Clearance of every candidate, kept up to date as points are placed. A point only
    // updates candidates within the current radius, so a stored value is exact when it is
    // below the radius in force when its nearest point was placed, and at least that radius
    // otherwise: enough, since the radius only shrinks.
    let mut clearance: Vec<Vec<f64>> = tiles.iter().map(|c| vec![f64::INFINITY; c.len()]).collect();
    let place = |clearance: &mut [Vec<f64>], t: usize, p: DVec2, reach: f64| {
        for &(v, offset) in &affects[t] {
            let q = p + offset;
            if q.x < -reach || q.x > 1.0 + reach || q.y < -reach || q.y > 1.0 + reach {
                continue;
            }
            let (room, cands) = (&mut clearance[v], &tiles[v]);
            grids[v].for_each_near(q, reach, |i| {
                let c = &mut room[i as usize];
                *c = c.min((cands[i as usize].pos - q).length());
            });
        }
    };
    // Picks are recorded apart from `order` and the rest appended at the end, so a pick from
    // far down the order costs nothing to move.
    let mut taken: Vec<Vec<bool>> = tiles.iter().map(|c| vec![false; c.len()]).collect();
    let mut picked: Vec<Vec<usize>> = order.iter().map(|o| o[..fixed].to_vec()).collect();
    for (t, o) in order.iter().enumerate() {
        for &i in &o[..fixed] {
            taken[t][i] = true;
            place(&mut clearance, t, tiles[t][i].pos, radius(fixed));
        }
    }
    let mut cursor = vec![fixed; tiles.len()];
    let mut misses = 0;
    for k in fixed..until {
        let r = radius(k);
        for t in 0..tiles.len() {
            let (o, room, done) = (&order[t], &clearance[t], &taken[t]);
            while cursor[t] < o.len() && done[o[cursor[t]]] {
                cursor[t] += 1;
            }
            let untaken = || o[cursor[t]..].iter().copied().filter(|&i| !done[i]);
            let pick = match untaken().take(lookahead.window).find(|&i| room[i] >= r) {
                Some(i) => i,
                None => {
                    misses += 1;
                    // The most room among the next `fallback`; the earliest among equals.
                    let roomiest = untaken()
                        .take(lookahead.fallback)
                        .reduce(|a, b| if room[b] > room[a] { b } else { a });
                    let Some(i) = roomiest else { continue };
                    i
                }
            };
            taken[t][pick] = true;
            picked[t].push(pick);
            place(&mut clearance, t, tiles[t][pick].pos, r);
        }
    }
    for ((o, picked), taken) in order.iter_mut().zip(picked).zip(&taken) {
        *o = picks_first(o, picked, taken);
    }
    misses
}

/// Each tile's candidates in a grid of `cell`-wide buckets.
fn candidate_grids(tiles: &[Vec<Candidate>], cell: f64) -> Vec<BucketGrid> {
    tiles
        .iter()
        .map(|cands| {
            let mut grid = BucketGrid::new(DVec2::ZERO, DVec2::ONE, cell);
            for (i, c) in cands.iter().enumerate() {
                grid.insert(c.pos, i as u32);
            }
            grid
        })
        .collect()
}

/// `picked` in its order, then the rest of `order` that was not taken, in theirs.
fn picks_first(order: &[usize], mut picked: Vec<usize>, taken: &[bool]) -> Vec<usize> {
    picked.extend(order.iter().copied().filter(|&i| !taken[i]));
    picked
}

/// Turns thresholds into a rank order: indices sorted by `(tau, tau0, index)`.
pub fn order_by_threshold(cands: &[Candidate], tau: &[f64]) -> Vec<usize> {
    let mut order: Vec<usize> = (0..cands.len()).collect();
    order.sort_by(|&a, &b| {
        tau[a]
            .total_cmp(&tau[b])
            .then(cands[a].tau0.total_cmp(&cands[b].tau0))
            .then(a.cmp(&b))
    });
    order
}

/// Which tiles may lie at each neighbour offset of each tile, for a complete set with
/// independent edge hashing: edge neighbours share the colour, diagonal ones are free.
pub fn complete_set_neighbours(tiles: &[EdgeColors]) -> Neighbours {
    tiles
        .iter()
        .map(|t| {
            std::array::from_fn(|o| {
                let (dx, dy) = OFFSETS[o];
                (0..tiles.len() as u16)
                    .filter(|&u| {
                        let u = &tiles[u as usize];
                        match (dx, dy) {
                            (1, 0) => u.west == t.east,
                            (-1, 0) => u.east == t.west,
                            (0, 1) => u.south == t.north,
                            (0, -1) => u.north == t.south,
                            _ => true,
                        }
                    })
                    .collect()
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;

    #[test]
    fn accepted_points_respect_the_threshold_spacing() {
        let mut rng = Rng::new(5, 0);
        let cands: Vec<Candidate> = (0..600)
            .map(|i| Candidate {
                pos: DVec2::new(rng.next_f64(), rng.next_f64()),
                tau0: i as f64 * 0.5,
                fixed: false,
            })
            .collect();
        // One tile that neighbours itself on every side: a periodic tiling.
        let neighbours: Neighbours = vec![std::array::from_fn(|_| vec![0])];
        let alpha = 0.7;
        let cap = 600.0;
        let tau = rank(std::slice::from_ref(&cands), &neighbours, |_| alpha, cap);
        for a in 0..cands.len() {
            for b in a + 1..cands.len() {
                let t = tau[0][a].max(tau[0][b]);
                if t >= cap {
                    continue;
                }
                let mut d = cands[a].pos - cands[b].pos;
                d -= d.round();
                assert!(d.length() >= alpha / t.sqrt() - 1e-12, "pair {a} {b}");
            }
        }
        assert!(tau[0].iter().all(|t| t.is_finite()));
    }
}
