//! Whole-set checks used by `rwt tileset check` and the tests.

use crate::analysis::min_distance;
use crate::geometry::hex_spacing;
use crate::tileset::{TileSet, fixed_to_unit};
use crate::tiling::Tiling;
use glam::DVec2;

/// Edge colour mismatches between adjacent tiles of level `level` in a window of
/// `window x window` base tiles (all levels share the same edges at the base borders).
pub fn edge_violations(set: &TileSet, seed: u64, level: u32, window: i64) -> usize {
    let tiling = Tiling::new(set, seed);
    let side = window * (set.subdivision as i64).pow(level);
    let at = |i: i64, j: i64| set.tiles[tiling.tile_at(level, i, j) as usize].edges;
    let mut bad = 0;
    for j in -side / 2..side / 2 {
        for i in -side / 2..side / 2 {
            let t = at(i, j);
            bad += usize::from(t.east != at(i + 1, j).west);
            bad += usize::from(t.north != at(i, j + 1).south);
        }
    }
    bad
}

/// The first `k` points of every tile of a `window x window` tiling, in world units (tiles
/// of side 1), where `point(tile, rank)` gives a rank's position in the tile's fixed-point
/// frame.
fn tiled_prefix(
    set: &TileSet,
    seed: u64,
    window: i64,
    k: usize,
    point: impl Fn(usize, usize) -> [u32; 2],
) -> Vec<DVec2> {
    let tiling = Tiling::new(set, seed);
    let mut out = Vec::with_capacity((window * window) as usize * k);
    for j in 0..window {
        for i in 0..window {
            let t = tiling.base_tile(i, j) as usize;
            for rank in 0..k {
                let p = point(t, rank);
                out.push(DVec2::new(
                    i as f64 + fixed_to_unit(p[0]),
                    j as f64 + fixed_to_unit(p[1]),
                ));
            }
        }
    }
    out
}

/// The first `k` base points of every tile of a `window x window` tiling, in world units
/// (tiles of side 1).
pub fn base_prefix_points(set: &TileSet, seed: u64, window: i64, k: usize) -> Vec<DVec2> {
    let k = k.min(set.points_per_tile as usize);
    tiled_prefix(set, seed, window, k, |t, rank| set.tiles[t].points[rank])
}

/// The first `k` points of every tile's subdivision ranking (what a query at `k` points per
/// tile shows between the base level and the next) in a `window x window` tiling, in world
/// units (tiles of side 1).
pub fn subdivision_prefix_points(set: &TileSet, seed: u64, window: i64, k: usize) -> Vec<DVec2> {
    let k = k.min(set.subdivision_len());
    tiled_prefix(set, seed, window, k, |t, rank| {
        set.subdivision_point_fixed(t, set.tiles[t].subdivision[rank])
    })
}

fn worst_rho(points: impl Fn(u64) -> Vec<DVec2>, k: usize, seeds: u64) -> f64 {
    (0..seeds)
        .map(|s| min_distance(&points(s)).unwrap_or(f64::INFINITY) / hex_spacing(k as f64))
        .fold(f64::INFINITY, f64::min)
}

/// Worst normalized minimum distance of the first `k` points of every tile, measured on
/// real tilings (every tile together with its neighbours) over `seeds` seeds.
pub fn base_prefix_rho(set: &TileSet, k: usize, seeds: u64, window: i64) -> f64 {
    worst_rho(|s| base_prefix_points(set, s, window, k), k, seeds)
}

/// The same for the first `k` points of every tile's subdivision ranking (`N <= k <= n^2
/// N`): the quality of uniform densities between two levels.
pub fn subdivision_prefix_rho(set: &TileSet, k: usize, seeds: u64, window: i64) -> f64 {
    worst_rho(|s| subdivision_prefix_points(set, s, window, k), k, seeds)
}
