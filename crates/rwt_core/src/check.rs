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

/// The first `k` base points of every tile of a `window x window` tiling, in world units
/// (tiles of side 1).
pub fn base_prefix_points(set: &TileSet, seed: u64, window: i64, k: usize) -> Vec<DVec2> {
    let tiling = Tiling::new(set, seed);
    let mut out = Vec::with_capacity((window * window) as usize * k);
    for j in 0..window {
        for i in 0..window {
            let t = &set.tiles[tiling.base_tile(i, j) as usize];
            for p in &t.points[..k.min(t.points.len())] {
                out.push(DVec2::new(
                    i as f64 + fixed_to_unit(p[0]),
                    j as f64 + fixed_to_unit(p[1]),
                ));
            }
        }
    }
    out
}

/// Worst normalized minimum distance of the first `k` points of every tile, measured on
/// real tilings (every tile together with its neighbours) over `seeds` seeds.
pub fn base_prefix_rho(set: &TileSet, k: usize, seeds: u64, window: i64) -> f64 {
    (0..seeds)
        .map(|s| {
            let pts = base_prefix_points(set, s, window, k);
            min_distance(&pts).unwrap_or(f64::INFINITY) / hex_spacing(k as f64)
        })
        .fold(f64::INFINITY, f64::min)
}
