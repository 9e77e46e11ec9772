//! Stage 2 of the construction: Wang tiles from source tiles merged along min-cost seams,
//! with the interleaved source ranks as their first progressive order.

use super::seam::{Origin, SourcedPoint, merge};
use super::{BuildConfig, BuildError, Progress, Stage};
use crate::geometry::{BucketGrid, hex_spacing};
use crate::rng::Rng;
use crate::wang::{EdgeColors, Side};
use glam::DVec2;
use rayon::prelude::*;

/// A merged Wang tile: its points in progressive order and its seams.
pub(super) type MergedTile = (Vec<SourcedPoint>, Vec<Vec<[f32; 2]>>);

/// Every tile of the complete set, merged from its interior source and the sources of its
/// four edge colours; fails when a tile keeps fewer than `N` points.
pub(super) fn wang_tiles(
    config: &BuildConfig,
    edges: &[EdgeColors],
    sources: &[Vec<DVec2>],
    progress: &dyn Progress,
) -> Result<Vec<MergedTile>, BuildError> {
    progress.start(Stage::Merging, edges.len() as u64);
    let merged: Vec<MergedTile> = (0..edges.len())
        .into_par_iter()
        .map(|t| {
            let tile = merge_tile(config, t, edges[t], sources);
            progress.advance(1);
            tile
        })
        .collect();
    progress.finish();
    let big_n = config.points as usize;
    if let Some(short) = merged.iter().position(|m| m.0.len() < big_n) {
        return Err(BuildError::Config(format!(
            "tile {short} merged to fewer than {big_n} points; use more points"
        )));
    }
    Ok(merged)
}

/// Source `s`'s points, tagged with their origin and rank.
fn tagged(sources: &[Vec<DVec2>], s: usize, origin: Origin) -> Vec<SourcedPoint> {
    sources[s]
        .iter()
        .enumerate()
        .map(|(i, &pos)| SourcedPoint {
            pos,
            origin,
            source_rank: i as u32,
        })
        .collect()
}

/// Tile `t`: its interior source merged with the four edge sources side by side, the
/// source ranks interleaved (ties broken by a hash), thinned and smoothed to `N` points.
fn merge_tile(config: &BuildConfig, t: usize, e: EdgeColors, sources: &[Vec<DVec2>]) -> MergedTile {
    let k = config.colors as usize;
    let mut pts = tagged(sources, 2 * k + t, Origin::Interior);
    let mut seams = Vec::new();
    for side in Side::ALL {
        let c = e.side(side) as usize;
        let src = if side.is_horizontal() { c } else { k + c };
        let incoming = tagged(sources, src, Origin::Edge(side));
        let (m, seam) = merge(&pts, &incoming, side, config.edge_band);
        pts = m;
        // Tile coordinates, as a loaded set is checked to have them.
        seams.push(
            seam.iter()
                .map(|p| [p.x.clamp(0.0, 1.0) as f32, p.y.clamp(0.0, 1.0) as f32])
                .collect(),
        );
    }
    let mut rng = Rng::new(config.seed, 0x1e_0000 + t as u64);
    let mut keyed: Vec<(u32, u64, SourcedPoint)> = pts
        .into_iter()
        .map(|p| (p.source_rank, rng.next_u64(), p))
        .collect();
    keyed.sort_by_key(|a| (a.0, a.1));
    let interleaved: Vec<SourcedPoint> = keyed.into_iter().map(|x| x.2).collect();
    let mut kept = thin_seams(&interleaved, config.points as usize);
    smooth_seams(&mut kept, 0.8, 1.5, 20);
    (kept, seams)
}

/// Smallest and median per-tile normalized minimum distance right after merging.
pub(super) fn merged_rho(merged: &[MergedTile], big_n: usize) -> (f64, f64) {
    let mut r: Vec<f64> = merged
        .iter()
        .map(|m| {
            let pts: Vec<DVec2> = m.0.iter().map(|p| p.pos).collect();
            crate::analysis::rho(&pts, big_n as f64).unwrap_or(0.0)
        })
        .collect();
    r.sort_by(f64::total_cmp);
    (r[0], r[r.len() / 2])
}

/// The code stored in [`crate::tileset::Tile::origins`].
pub(super) fn origin_code(o: Origin) -> u8 {
    match o {
        Origin::Interior => 0,
        Origin::Edge(Side::North) => 1,
        Origin::Edge(Side::East) => 2,
        Origin::Edge(Side::South) => 3,
        Origin::Edge(Side::West) => 4,
    }
}

/// Removes the later of every pair that a seam left closer than the sources allow, then keeps
/// the first `n` points of the interleaved progressive order. The spacing starts at what
/// the sources guarantee and relaxes only if too few points would remain.
fn thin_seams(interleaved: &[SourcedPoint], n: usize) -> Vec<SourcedPoint> {
    let hex = hex_spacing(interleaved.len() as f64);
    for spacing in [0.7, 0.65, 0.6, 0.55, 0.5, 0.0] {
        let r = spacing * hex;
        let mut grid = BucketGrid::new(DVec2::ZERO, DVec2::ONE, r.max(1e-3));
        let mut kept: Vec<SourcedPoint> = Vec::with_capacity(n);
        for p in interleaved {
            let mut clear = true;
            grid.for_each_near(p.pos, r, |i| {
                clear &= (kept[i as usize].pos - p.pos).length_squared() >= r * r;
            });
            if clear {
                grid.insert(p.pos, kept.len() as u32);
                kept.push(*p);
                if kept.len() == n {
                    return kept;
                }
            }
        }
    }
    interleaved.iter().take(n).copied().collect()
}

/// Evens out what is left of the seams: pairs closer than `target` hexagonal spacings push
/// each other apart, for a few rounds. Points within `border` spacings of the tile edge stay
/// put, so every tile with an edge colour keeps exactly that colour's source pattern there
/// and neighbouring tiles still continue each other.
fn smooth_seams(points: &mut [SourcedPoint], target: f64, border: f64, rounds: usize) {
    let hex = hex_spacing(points.len() as f64);
    let r = target * hex;
    let fixed = border * hex;
    for _ in 0..rounds {
        let mut grid = BucketGrid::new(DVec2::ZERO, DVec2::ONE, r);
        for (i, p) in points.iter().enumerate() {
            grid.insert(p.pos, i as u32);
        }
        let moves: Vec<DVec2> = points
            .iter()
            .enumerate()
            .map(|(i, p)| {
                let m = p.pos.x.min(1.0 - p.pos.x).min(p.pos.y).min(1.0 - p.pos.y);
                if m < fixed {
                    return DVec2::ZERO;
                }
                let mut push = DVec2::ZERO;
                grid.for_each_near(p.pos, r, |j| {
                    let d = p.pos - points[j as usize].pos;
                    let len = d.length();
                    if j as usize != i && len < r && len > 0.0 {
                        push += d / len * (r - len) * 0.5;
                    }
                });
                push
            })
            .collect();
        for (p, m) in points.iter_mut().zip(moves) {
            p.pos = (p.pos + m).clamp(DVec2::ZERO, DVec2::splat(1.0 - 1e-12));
        }
    }
}
