//! The tile set construction pipeline (paper sections 4 and 5), deterministic from a seed.
//! Compiled with the `build` feature: games that only query a shipped set need none of it.
//!
//! [`build`] runs the paper's stages, one call each:
//! 1. progressive toroidal source tiles (`crate::dart_throwing`), one per edge colour and
//!    orientation plus one unique interior per tile;
//! 2. Wang tiles by merging sources along min-cost Voronoi seams (`seam`, `merging`),
//!    keeping the first `N` of the interleaved source ranks;
//! 3. subdivision rules (`subdivision`);
//! 4. relaxation to the exact subset property (`relaxation`);
//! 5. the final base ranking and the subdivision ranking (`ranking`, on
//!    `progressive`), both with spacing guaranteed against every possible neighbour tile.
//!
//! Independent work (source tiles, merges, relaxation steps) runs on rayon; every random
//! choice comes from a stream derived from the seed and the item, so the result does not
//! depend on the number of threads.

mod merging;
mod progressive;
mod ranking;
mod relaxation;
mod seam;
mod subdivision;

pub use crate::dart_throwing::DartThrowing;
pub use subdivision::RulesError;

use crate::rng::Rng;
use crate::tileset::{FORMAT_VERSION, Tile, TileSet, TileSetError};
use crate::wang::{EdgeColors, complete_set_size};
use glam::DVec2;
use merging::MergedTile;
use progressive::complete_set_neighbours;
use ranking::Rankings;
use rayon::prelude::*;
use relaxation::Relaxed;
use subdivision::Rules;

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

impl BuildConfig {
    /// Checks that the settings are in the ranges the builder supports.
    pub fn validate(&self) -> Result<(), BuildError> {
        let bad = |msg: String| Err(BuildError::Config(msg));
        let (k, n, big_n) = (self.colors, self.subdivision as usize, self.points as usize);
        if !(1..=4).contains(&k) {
            return bad(format!("colors {k} not in 1..=4"));
        }
        if !n.is_power_of_two() || !(2..=8).contains(&n) {
            return bad(format!("subdivision {n} not a power of two in 2..=8"));
        }
        if !(16..=16_384).contains(&big_n) {
            return bad(format!("points {big_n} not in 16..=16384"));
        }
        if !(0.0..0.3).contains(&self.edge_band) {
            return bad(format!("edge band {} not in 0..0.3", self.edge_band));
        }
        if !(0.3..=0.85).contains(&self.alpha) {
            return bad(format!("alpha {} not in 0.3..=0.85", self.alpha));
        }
        Ok(())
    }

    /// Points thrown in every source tile: a few more than `N`, so that each merged tile has
    /// at least `N`; the surplus is cut from the end of the progressive order. Seams make
    /// the merged count vary by a few `sqrt(N)`, hence the second term.
    fn source_points(&self) -> usize {
        let n = self.points as f64;
        (n * (1.08 + 2.0 / n.sqrt())).ceil() as usize
    }
}

/// Builds a tile set: the paper's pipeline, one call per stage.
pub fn build(
    config: &BuildConfig,
    progress: &dyn Progress,
) -> Result<(TileSet, BuildReport), BuildError> {
    config.validate()?;
    let edges: Vec<EdgeColors> = (0..complete_set_size(config.colors))
        .map(|i| EdgeColors::from_complete_index(i, config.colors))
        .collect();
    let sources = source_tiles(config, edges.len(), progress);
    let merged = merging::wang_tiles(config, &edges, &sources, progress)?;
    let rules = subdivision_rules(config, &edges, progress)?;
    let neighbours = complete_set_neighbours(&edges);
    let relaxed = relax(config, &merged, &rules, &neighbours, progress);
    let rankings = ranking::rank_tiles(config, &merged, &relaxed, &rules, &neighbours, progress);
    let set = assemble(config, &edges, &rules, &merged, &relaxed, &rankings);
    set.validate()?;
    let report = BuildReport::new(&merged, config.points as usize, &relaxed, &rankings);
    Ok((set, report))
}

/// Stage 1: progressive dart throwing of `2 K` edge sources (K horizontal, K vertical)
/// and one interior source per tile.
fn source_tiles(config: &BuildConfig, tiles: usize, progress: &dyn Progress) -> Vec<Vec<DVec2>> {
    let count = 2 * config.colors as usize + tiles;
    progress.start(Stage::SourceTiles, count as u64);
    let dart = DartThrowing::new(config.source_points());
    let sources = (0..count)
        .into_par_iter()
        .map(|s| {
            let pts = dart.run(&mut Rng::new(config.seed, 0x50_0000 + s as u64));
            progress.advance(1);
            pts
        })
        .collect();
    progress.finish();
    sources
}

/// Stage 3: subdivision rules.
fn subdivision_rules(
    config: &BuildConfig,
    edges: &[EdgeColors],
    progress: &dyn Progress,
) -> Result<Rules, BuildError> {
    progress.start(Stage::Rules, 1);
    let rules = subdivision::find_rules(
        edges,
        config.colors,
        config.subdivision as usize,
        config.seed,
    )?;
    progress.advance(1);
    progress.finish();
    Ok(rules)
}

/// Stage 4: relaxation of the merged points to the exact subset property.
fn relax(
    config: &BuildConfig,
    merged: &[MergedTile],
    rules: &Rules,
    neighbours: &progressive::Neighbours,
    progress: &dyn Progress,
) -> Relaxed {
    progress.start(Stage::Relaxation, config.relax_iterations as u64);
    let initial: Vec<Vec<DVec2>> = merged
        .iter()
        .map(|m| m.0.iter().map(|p| p.pos).collect())
        .collect();
    let relaxed = relaxation::relax(
        initial,
        &rules.children,
        neighbours,
        config.subdivision as usize,
        config.relax_iterations,
        config.min_spacing,
        || progress.advance(1),
    );
    progress.finish();
    relaxed
}

/// The tile set from the stages' results: points and origins in base-rank order, the
/// subdivision ranking as `cell << 16 | child point index`.
fn assemble(
    config: &BuildConfig,
    edges: &[EdgeColors],
    rules: &Rules,
    merged: &[MergedTile],
    relaxed: &Relaxed,
    rankings: &Rankings,
) -> TileSet {
    let big_n = config.points as usize;
    let tiles: Vec<Tile> = (0..edges.len())
        .map(|t| {
            let order = &rankings.order[t];
            Tile {
                edges: edges[t],
                children: rules.children[t].clone(),
                points: order.iter().map(|&old| relaxed.positions[t][old]).collect(),
                origins: order
                    .iter()
                    .map(|&old| merging::origin_code(merged[t].0[old].origin))
                    .collect(),
                subdivision: rankings.sub_order[t]
                    .iter()
                    .map(|&j| (((j / big_n) as u32) << 16) | (j % big_n) as u32)
                    .collect(),
                seams: merged[t].1.clone(),
            }
        })
        .collect();
    TileSet {
        format: FORMAT_VERSION,
        colors: config.colors,
        subdivision: config.subdivision,
        points_per_tile: config.points,
        seed: config.seed,
        horizontal_sequences: rules.horizontal.clone(),
        vertical_sequences: rules.vertical.clone(),
        tiles,
    }
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

impl BuildReport {
    fn new(merged: &[MergedTile], big_n: usize, relaxed: &Relaxed, rankings: &Rankings) -> Self {
        let (merged_rho_min, merged_rho_median) = merging::merged_rho(merged, big_n);
        Self {
            merged_rho_min,
            merged_rho_median,
            relaxation_residual: relaxed.residual,
            relaxation_max_shift: relaxed.max_shift,
            relaxation_crowded: relaxed.crowded,
            relaxation_crowded_clearance: relaxed.crowded_clearance,
            rank_lag: rankings.rank_lag.clone(),
            prefix_misses: rankings.prefix_misses,
            sub_prefix_misses: rankings.sub_prefix_misses,
        }
    }
}
