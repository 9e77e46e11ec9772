//! The tile set construction pipeline (paper sections 4 and 5), deterministic from a seed.
//!
//! 1. progressive toroidal source tiles ([`crate::source_tile`]), one per edge colour and
//!    orientation plus one unique interior per tile;
//! 2. Wang tiles by merging sources along min-cost Voronoi seams ([`crate::seam`]);
//! 3. an initial progressive order by interleaving source ranks;
//! 4. subdivision rules ([`crate::subdivision`]);
//! 5. relaxation to the exact subset property ([`crate::relaxation`]);
//! 6. the final base ranking and the subdivision ranking ([`crate::progressive`]), both with
//!    spacing guaranteed against every possible neighbour tile.
//!
//! Independent work (source tiles, merges, relaxation steps) runs on rayon; every random
//! choice comes from a stream derived from the seed and the item, so the result does not
//! depend on the number of threads.

use crate::progressive::{
    Candidate, Lookahead, Neighbours, OFFSETS, order_by_threshold, rank, repair_prefixes,
};
use crate::rng::{Rng, hash_words, unit_f64};
use crate::seam::{Origin, SourcedPoint, merge};
use crate::source_tile::DartThrowing;
use crate::subdivision::{RulesError, find_rules};
use crate::tileset::{FIXED_ONE, FORMAT_VERSION, Tile, TileSet, TileSetError};
use crate::wang::{EdgeColors, Side, complete_set_size};
use glam::DVec2;
use rayon::prelude::*;

/// Settings of a tile set build.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BuildConfig {
    /// Seed of every random choice.
    pub seed: u64,
    /// Edge colours per orientation `K` (`K^4` tiles).
    pub colors: u8,
    /// Points per tile `N`.
    pub points: u32,
    /// Subdivision factor `n` (power of two).
    pub subdivision: u8,
    /// Spacing constant of the progressive rankings: a point of threshold `tau` keeps
    /// `alpha / sqrt(tau)` from every earlier point (paper: 0.5).
    pub alpha: f64,
    /// Spacing constant of the final prefix pass: rank `k` keeps `prefix_alpha / sqrt(k + 1)`
    /// from earlier ranks (0.7 means a normalized minimum distance of 0.65 per prefix).
    pub prefix_alpha: f64,
    /// Relaxation passes.
    pub relax_iterations: usize,
    /// Minimum distance relaxation keeps between base points, relative to the hexagonal
    /// spacing of `N` points.
    pub min_spacing: f64,
    /// Width of the seam-free band along every tile edge, as a fraction of the tile. Within
    /// it every tile with that edge colour holds the same source points; it should be at least
    /// the spacing of the sparsest prefixes that must match across edges.
    pub edge_band: f64,
    /// Initial thresholds are `order * lead`: below 1, points enter the ranking a little
    /// early, which compensates for the ones the spacing rule postpones.
    pub lead: f64,
}

impl Default for BuildConfig {
    /// The configuration of the shipped tile set.
    fn default() -> Self {
        Self {
            seed: 2006,
            colors: 2,
            points: 2048,
            subdivision: 4,
            alpha: 0.75,
            prefix_alpha: 0.70,
            relax_iterations: 30,
            min_spacing: 0.7,
            edge_band: 0.07,
            lead: 0.5,
        }
    }
}

/// The stages of a build, for progress reporting.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stage {
    /// Progressive dart throwing of the source tiles.
    SourceTiles,
    /// Seam merging of the Wang tiles.
    Merging,
    /// Subdivision rules.
    Rules,
    /// Relaxation to the subset property.
    Relaxation,
    /// Base and subdivision rankings.
    Ranking,
}

impl Stage {
    /// Human-readable name.
    pub fn name(self) -> &'static str {
        match self {
            Stage::SourceTiles => "source tiles",
            Stage::Merging => "seam merging",
            Stage::Rules => "subdivision rules",
            Stage::Relaxation => "relaxation",
            Stage::Ranking => "ranking",
        }
    }
}

/// Receives progress of a build (a CLI draws bars; tests ignore it).
pub trait Progress: Sync {
    /// A stage starts with `total` steps.
    fn start(&self, stage: Stage, total: u64);
    /// `n` steps of the current stage are done.
    fn advance(&self, n: u64);
    /// The current stage is done.
    fn finish(&self);
}

/// Ignores progress.
pub struct NoProgress;
impl Progress for NoProgress {
    fn start(&self, _: Stage, _: u64) {}
    fn advance(&self, _: u64) {}
    fn finish(&self) {}
}

/// Why a build failed.
#[derive(Debug, thiserror::Error)]
pub enum BuildError {
    /// Settings out of range.
    #[error("invalid build settings: {0}")]
    Config(String),
    /// No subdivision rules.
    #[error(transparent)]
    Rules(#[from] RulesError),
    /// The result failed validation (a bug: please report).
    #[error("built tile set is invalid: {0}")]
    Invalid(#[from] TileSetError),
}

/// Extra points thrown in every source so that each merged tile has at least `N`; the
/// surplus is cut from the end of the progressive order. Seams make the merged count vary by
/// a few `sqrt(N)`, hence the second term.
fn source_surplus(n: usize) -> f64 {
    1.08 + 2.0 / (n as f64).sqrt()
}

/// Base ranks below `points * WIDE_PREFIX_FRACTION` search the whole threshold order for a
/// point with room; first-fit within a short window jams there once the tile borders are
/// blocked by every tile that may lie next to them. Measured on the shipped set: the worst
/// prefix (quarter-octave sizes, with neighbours) went from 0.561 (23 points) to 0.642
/// (431 points); queries at 20 points per tile from rho 0.575 to 0.649. The price is paid
/// between N/8 and N/2: at 0.34 N per tile rho went from 0.670 to 0.648 and low-frequency
/// power from 1.3x to 1.7x dart throwing's. Every variant tried (wide search only on a miss,
/// farthest-point prefixes, other fractions) lost at least as much there.
const WIDE_PREFIX_FRACTION: f64 = 0.125;

/// How far ahead the base prefix pass looks after that. When no point in the window has
/// room, the one with the most room among the next 1024 keeps the shortfall small (with 64,
/// the worst prefix between 256 and 512 points fell from 0.643 to 0.631).
const PREFIX_LOOKAHEAD: Lookahead = Lookahead {
    window: 64,
    fallback: 1024,
};

/// The same for the subdivision ranking after [`SUB_WIDE_PREFIX`].
///
/// From about `3.5 N` on, no candidate has the `prefix_alpha` room: the ranking picks
/// nested subsets of a fixed, discrete set (the children's `16 N` points). With every
/// candidate entering at `N` (the paper's random order, i.e. farthest-point picks) the
/// shipped set reached, at 4 / 6 / 8.5 / 12 N, a normalized minimum distance of 0.636 /
/// 0.624 / 0.643 / 0.675 and low-frequency power 1.3x / 1.8x / 1.9x / 1.8x dart
/// throwing's. Measured in session 5 with the in-tile minimum distance of each prefix
/// (which tracks the query's to 0.002): farthest-point ranks of all `16 N` points with the
/// base points left free have the same trough (0.638 / 0.623 / 0.642), and so does a
/// weighted sample elimination order (Yuksel 2015) from `16 N` down (0.621-0.633 at 4-6 N),
/// so the base points are not the cause; a more regular `16 N` set (seam smoothing over
/// the whole tile) lifts `N` and `16 N` to 0.68 but sinks 6 N to 0.612. What helped is the
/// children's own rankings as a prior ([`SUB_CHILD_RANK_LEAD`]) with the wide first search:
/// 0.643 / 0.643 / 0.653 / 0.677, low-frequency 1.47x / 1.68x / 1.72x / 1.61x, for
/// 0.651 (was 0.683) and 1.4x (was 1.1x) at 1.5-2 N. Leads from 0.3 to 0.42 and wide
/// prefixes from 2.5 N to 3.5 N all stay between 0.638 and 0.645 at the worst density
/// (a lead of 0.6: 0.631); re-ranking again at 4.5 N or 6 N changes nothing.
///
/// Session 6 (`rwt tileset check` prints these prefixes): the trough is a capacity curve,
/// not a few bad picks: from 3.5 N to 7 N nearly every rank of every tile gets a little
/// less than the `prefix_alpha` room, none less than 0.64 of the hexagonal spacing. Ranking
/// every tile as its own only neighbour: 0.644. `prefix_alpha` 0.69 / 0.705: trough 0.645 /
/// 0.639, 1.5-2 N 0.642 / 0.656. Candidate sets from seam smoothing targets 0.6-0.75 or a
/// relaxation spacing of 0.6-0.68: 0.642-0.647 (0.6 costs 1 N its 0.668, down to 0.600).
///
/// Tried in session 4, none better in the trough:
/// - the whole order as window: no change (15 107 of the 65 536 ranks 4096..8191 miss);
/// - among the first 8 or 32 points with room, the one blocking the fewest others: 14 982;
/// - minimum-degree packing in stages from `N` or `2 N` (a one-shot independent set at
///   `4 N` spacing holds 9 600 points, but packing tightly early leaves holes too small
///   later): 0.637 / 0.623 / 0.644;
/// - weighted sample elimination from `16 N` down, neighbours averaged or summed, alone or
///   below a farthest-point prefix of `2 N` / `3 N`: 0.49 to 0.59 at 4 N, but 0.669 / 0.681
///   at 12 / 14 N;
/// - preferring candidates with fewer placed points within 3-4 radii (balance): low-frequency
///   power 1.9x -> 1.8x at 8.5 N for rho 0.631.
const SUB_PREFIX_LOOKAHEAD: Lookahead = Lookahead {
    window: 64,
    fallback: 64,
};

/// Subdivision ranks from `N` to `SUB_WIDE_PREFIX * N` search the whole threshold order for
/// a point with room, like the base ranks below [`WIDE_PREFIX_FRACTION`]; the rest is ranked
/// again around them.
const SUB_WIDE_PREFIX: f64 = 3.0;

/// A subdivision candidate that is not a base point enters the ranking at this share of
/// the density at which its own child tile shows it (`n^2 (rank in child + 1)`), or at `N`
/// if that is lower. The children's base rankings are good progressive sets at every
/// density, so this prior keeps the nested subsets balanced where farthest-point picks from
/// the fixed `16 N` points are not.
const SUB_CHILD_RANK_LEAD: f64 = 0.35;

/// A merged Wang tile: its points in progressive order and its seams.
type MergedTile = (Vec<SourcedPoint>, Vec<Vec<[f32; 2]>>);

fn origin_code(o: Origin) -> u8 {
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
    let hex = crate::geometry::hex_spacing(interleaved.len() as f64);
    for spacing in [0.7, 0.65, 0.6, 0.55, 0.5, 0.0] {
        let r = spacing * hex;
        let mut grid = crate::geometry::BucketGrid::new(DVec2::ZERO, DVec2::ONE, r.max(1e-3));
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
    let hex = crate::geometry::hex_spacing(points.len() as f64);
    let r = target * hex;
    let fixed = border * hex;
    for _ in 0..rounds {
        let mut grid = crate::geometry::BucketGrid::new(DVec2::ZERO, DVec2::ONE, r);
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

/// A tile's candidates for ranking the rest of `order` again around its first `len` ranks:
/// those keep their ranks, every other point enters no earlier than `len`.
fn around_prefix(cands: &[Candidate], order: &[usize], len: usize) -> Vec<Candidate> {
    let mut around = cands.to_vec();
    for c in &mut around {
        c.tau0 = c.tau0.max(len as f64);
        c.fixed = false;
    }
    for (rank, &i) in order[..len].iter().enumerate() {
        around[i].tau0 = rank as f64;
        around[i].fixed = true;
    }
    around
}

/// The final prefix pass of a ranking: ranks in `wide` search the whole threshold order
/// for a point with room; those picks come from anywhere in the order, so the rest is
/// ranked again around them (or the next ranks find only points that crowd them) and
/// fixed with `lookahead`. Returns the ranks that found no point with room.
fn wide_then_windowed(
    cands: &[Vec<Candidate>],
    order: &mut [Vec<usize>],
    neighbours: &Neighbours,
    config: &BuildConfig,
    lookahead: Lookahead,
    wide: std::ops::Range<usize>,
) -> usize {
    let len = cands.first().map_or(0, Vec::len);
    let whole_order = Lookahead {
        window: usize::MAX,
        fallback: lookahead.fallback,
    };
    let mut misses = repair_prefixes(
        cands,
        order,
        neighbours,
        config.prefix_alpha,
        whole_order,
        wide.clone(),
    );
    let around: Vec<Vec<Candidate>> = cands
        .iter()
        .zip(order.iter())
        .map(|(c, o)| around_prefix(c, o, wide.end))
        .collect();
    let tau = rank(&around, neighbours, |_| config.alpha, len as f64);
    for ((o, c), t) in order.iter_mut().zip(&around).zip(&tau) {
        *o = order_by_threshold(c, t);
    }
    misses += repair_prefixes(
        cands,
        order,
        neighbours,
        config.prefix_alpha,
        lookahead,
        wide.end..len,
    );
    misses
}

/// Builds a tile set.
pub fn build(
    config: &BuildConfig,
    progress: &dyn Progress,
) -> Result<(TileSet, BuildReport), BuildError> {
    let k = config.colors;
    let n = config.subdivision as usize;
    let big_n = config.points as usize;
    if !(1..=4).contains(&k) {
        return Err(BuildError::Config(format!("colors {k} not in 1..=4")));
    }
    if !n.is_power_of_two() || !(2..=8).contains(&n) {
        return Err(BuildError::Config(format!(
            "subdivision {n} not a power of two in 2..=8"
        )));
    }
    if !(16..=16_384).contains(&big_n) {
        return Err(BuildError::Config(format!(
            "points {big_n} not in 16..=16384"
        )));
    }
    if !(0.0..0.3).contains(&config.edge_band) {
        return Err(BuildError::Config(format!(
            "edge band {} not in 0..0.3",
            config.edge_band
        )));
    }
    if !(0.3..=0.85).contains(&config.alpha) {
        return Err(BuildError::Config(format!(
            "alpha {} not in 0.3..=0.85",
            config.alpha
        )));
    }
    let seed = config.seed;
    let tile_count = complete_set_size(k);
    let edges: Vec<EdgeColors> = (0..tile_count)
        .map(|i| EdgeColors::from_complete_index(i, k))
        .collect();

    // 1. Source tiles: K horizontal, K vertical, then one interior per tile.
    let source_count = 2 * k as usize + tile_count;
    progress.start(Stage::SourceTiles, source_count as u64);
    let dart = DartThrowing::new((big_n as f64 * source_surplus(big_n)).ceil() as usize);
    let sources: Vec<Vec<DVec2>> = (0..source_count)
        .into_par_iter()
        .map(|s| {
            let pts = dart.run(&mut Rng::new(seed, 0x50_0000 + s as u64));
            progress.advance(1);
            pts
        })
        .collect();
    progress.finish();
    let tagged = |s: usize, origin: Origin| -> Vec<SourcedPoint> {
        sources[s]
            .iter()
            .enumerate()
            .map(|(i, &pos)| SourcedPoint {
                pos,
                origin,
                source_rank: i as u32,
            })
            .collect()
    };

    // 2-3. Merge along seams, interleave source ranks, keep the first N.
    progress.start(Stage::Merging, tile_count as u64);
    let strip = config.edge_band;
    let merged: Vec<MergedTile> = (0..tile_count)
        .into_par_iter()
        .map(|t| {
            let e = edges[t];
            let mut pts = tagged(2 * k as usize + t, Origin::Interior);
            let mut seams = Vec::new();
            for side in Side::ALL {
                let c = e.side(side) as usize;
                let src = if side.is_horizontal() {
                    c
                } else {
                    k as usize + c
                };
                let (m, seam) = merge(&pts, &tagged(src, Origin::Edge(side)), side, strip);
                pts = m;
                seams.push(seam.iter().map(|p| [p.x as f32, p.y as f32]).collect());
            }
            let mut rng = Rng::new(seed, 0x1e_0000 + t as u64);
            let mut keyed: Vec<(u32, u64, SourcedPoint)> = pts
                .into_iter()
                .map(|p| (p.source_rank, rng.next_u64(), p))
                .collect();
            keyed.sort_by_key(|a| (a.0, a.1));
            let interleaved: Vec<SourcedPoint> = keyed.into_iter().map(|x| x.2).collect();
            progress.advance(1);
            let mut kept = thin_seams(&interleaved, big_n);
            smooth_seams(&mut kept, 0.8, 1.5, 20);
            (kept, seams)
        })
        .collect();
    progress.finish();
    if let Some(short) = merged.iter().position(|m| m.0.len() < big_n) {
        return Err(BuildError::Config(format!(
            "tile {short} merged to fewer than {big_n} points; use more points"
        )));
    }

    let merged_rho = {
        let mut r: Vec<f64> = merged
            .iter()
            .map(|m| {
                let pts: Vec<DVec2> = m.0.iter().map(|p| p.pos).collect();
                crate::analysis::rho(&pts, big_n as f64).unwrap_or(0.0)
            })
            .collect();
        r.sort_by(f64::total_cmp);
        (r[0], r[r.len() / 2])
    };
    // 4. Subdivision rules.
    progress.start(Stage::Rules, 1);
    let rules = find_rules(&edges, k, n, seed)?;
    progress.advance(1);
    progress.finish();

    // 5. Relaxation.
    progress.start(Stage::Relaxation, config.relax_iterations as u64);
    let initial: Vec<Vec<DVec2>> = merged
        .iter()
        .map(|m| m.0.iter().map(|p| p.pos).collect())
        .collect();
    let neighbours = complete_set_neighbours(&edges);
    let relaxed = crate::relaxation::relax(
        initial,
        &rules.children,
        &neighbours,
        n,
        config.relax_iterations,
        config.min_spacing,
        || progress.advance(1),
    );
    progress.finish();
    // 6. Rankings.
    progress.start(Stage::Ranking, 2);
    let unit = |p: [u32; 2]| DVec2::new(p[0] as f64, p[1] as f64) / FIXED_ONE;
    // A point's first threshold comes from its rank in its source, so a shared edge point
    // starts out the same in every tile that holds it.
    let source_scale = config.lead * big_n as f64 / dart.points as f64;
    let base_cands: Vec<Vec<Candidate>> = relaxed
        .positions
        .iter()
        .zip(&merged)
        .map(|(tile, (pts, _))| {
            tile.iter()
                .zip(pts)
                .map(|(&p, src)| Candidate {
                    pos: unit(p),
                    tau0: src.source_rank as f64 * source_scale,
                    fixed: false,
                })
                .collect()
        })
        .collect();
    let base_tau = rank(&base_cands, &neighbours, |_| config.alpha, big_n as f64);
    // order[t][new] = old; new_index[t][old] = new.
    let mut order: Vec<Vec<usize>> = (0..tile_count)
        .map(|t| order_by_threshold(&base_cands[t], &base_tau[t]))
        .collect();
    let rank_lag: Vec<(usize, f64)> = [16usize, 64, 256, 1024]
        .into_iter()
        .filter(|&r| r < big_n)
        .map(|r| {
            let lag = (0..tile_count)
                .map(|t| base_tau[t][order[t][r]] / r as f64)
                .fold(0.0f64, f64::max);
            (r, lag)
        })
        .collect();
    let wide = ((big_n as f64 * WIDE_PREFIX_FRACTION) as usize).min(big_n);
    let prefix_misses = wide_then_windowed(
        &base_cands,
        &mut order,
        &neighbours,
        config,
        PREFIX_LOOKAHEAD,
        0..wide,
    );
    let mut new_index = vec![vec![0usize; big_n]; tile_count];
    for t in 0..tile_count {
        for (new, &old) in order[t].iter().enumerate() {
            new_index[t][old] = new;
        }
    }
    progress.advance(1);

    let sub_len = n * n * big_n;
    let sub_cands: Vec<Vec<Candidate>> = (0..tile_count)
        .map(|t| {
            let mut is_base = vec![usize::MAX; sub_len];
            for (old, &(cell, kk)) in relaxed.partner[t].iter().enumerate() {
                let child = rules.children[t][cell as usize] as usize;
                is_base[cell as usize * big_n + new_index[child][kk as usize]] = new_index[t][old];
            }
            let mut cands = Vec::with_capacity(sub_len);
            for cell in 0..n * n {
                let child = rules.children[t][cell] as usize;
                let offset = DVec2::new((cell % n) as f64, (cell / n) as f64);
                for kk in 0..big_n {
                    let p = unit(relaxed.positions[child][order[child][kk]]);
                    let base_rank = is_base[cell * big_n + kk];
                    cands.push(Candidate {
                        pos: (offset + p) / n as f64,
                        tau0: if base_rank != usize::MAX {
                            base_rank as f64
                        } else {
                            // The paper's figure 8 draws them in random order; we let each
                            // enter at a share of the density where its own child shows it.
                            (SUB_CHILD_RANK_LEAD * (n * n * (kk + 1)) as f64).max(big_n as f64)
                                * (1.0
                                    + 1e-3
                                        * unit_f64(hash_words(
                                            seed,
                                            &[0x5ab, t as u64, (cell * big_n + kk) as u64],
                                        )))
                        },
                        fixed: base_rank != usize::MAX,
                    });
                }
            }
            cands
        })
        .collect();
    let sub_tau = rank(&sub_cands, &neighbours, |_| config.alpha, sub_len as f64);
    let mut sub_order: Vec<Vec<usize>> = (0..tile_count)
        .map(|t| order_by_threshold(&sub_cands[t], &sub_tau[t]))
        .collect();
    // The base points keep the first N ranks (they are fixed candidates with tau < N). As
    // for the base ranking: a whole-order search first, then the rest ranked around it.
    let wide = ((big_n as f64 * SUB_WIDE_PREFIX) as usize).clamp(big_n, sub_len);
    let sub_prefix_misses = wide_then_windowed(
        &sub_cands,
        &mut sub_order,
        &neighbours,
        config,
        SUB_PREFIX_LOOKAHEAD,
        big_n..wide,
    );
    progress.advance(1);
    progress.finish();

    let tiles: Vec<Tile> = (0..tile_count)
        .map(|t| {
            let sub_order = &sub_order[t];
            Tile {
                edges: edges[t],
                children: rules.children[t].clone(),
                points: order[t]
                    .iter()
                    .map(|&old| relaxed.positions[t][old])
                    .collect(),
                origins: order[t]
                    .iter()
                    .map(|&old| origin_code(merged[t].0[old].origin))
                    .collect(),
                subdivision: sub_order
                    .iter()
                    .map(|&j| (((j / big_n) as u32) << 16) | (j % big_n) as u32)
                    .collect(),
                seams: merged[t].1.clone(),
            }
        })
        .collect();
    let set = TileSet {
        format: FORMAT_VERSION,
        colors: k,
        subdivision: n as u8,
        points_per_tile: big_n as u32,
        seed,
        horizontal_sequences: rules.horizontal,
        vertical_sequences: rules.vertical,
        tiles,
    };
    set.validate()?;
    let report = BuildReport {
        merged_rho_min: merged_rho.0,
        merged_rho_median: merged_rho.1,
        relaxation_residual: relaxed.residual,
        relaxation_max_shift: relaxed.max_shift,
        relaxation_crowded: relaxed.crowded,
        relaxation_crowded_clearance: relaxed.crowded_clearance,
        rank_lag,
        prefix_misses,
        sub_prefix_misses,
    };
    Ok((set, report))
}

/// Measurements taken during a build.
#[derive(Clone, Debug, PartialEq)]
pub struct BuildReport {
    /// Smallest per-tile normalized minimum distance right after seam merging.
    pub merged_rho_min: f64,
    /// Median of the same.
    pub merged_rho_median: f64,
    /// Largest base-to-partner distance before the exact snap (tile units).
    pub relaxation_residual: f64,
    /// Largest distance a point moved in relaxation, in hexagonal spacings of `N` points.
    pub relaxation_max_shift: f64,
    /// Points relaxation could not give the requested clearance.
    pub relaxation_crowded: usize,
    /// Their smallest clearance, in hexagonal spacings.
    pub relaxation_crowded_clearance: f64,
    /// For some ranks `r`, the largest `tau / r` over tiles: how far the spacing rule
    /// postponed points (1 = not at all).
    pub rank_lag: Vec<(usize, f64)>,
    /// Ranks (over all tiles) where the final prefix pass found no point with the
    /// `prefix_alpha` spacing.
    pub prefix_misses: usize,
    /// The same for the subdivision ranking (ranks `N..n^2 N`).
    pub sub_prefix_misses: usize,
}
