//! Stage 5 of the construction: the final progressive rankings (paper figures 5 and 8).
//! The base ranking orders each tile's relaxed points; the subdivision ranking orders the
//! `n^2 N` points of its children, base points first. Both run in threshold space over all
//! tiles at once ([`super::progressive::rank`]), then fix their prefixes rank by rank so
//! that every prefix keeps its spacing against every possible neighbour tile.
//!
//! The constants below were tuned on the shipped set; `docs/construction-notes.md` keeps
//! the measurements behind them.

use super::merging::MergedTile;
use super::progressive::{
    Candidate, Lookahead, Neighbours, order_by_threshold, rank, repair_prefixes,
};
use super::relaxation::Relaxed;
use super::subdivision::Rules;
use super::{BuildConfig, Progress, Stage};
use crate::rng::{hash_words, unit_f64};
use crate::tileset::FIXED_ONE;
use glam::DVec2;

/// Base ranks below `N * WIDE_PREFIX_FRACTION` search the whole threshold order for a point
/// with room: first-fit within a short window jams there once the tile borders are blocked
/// by every tile that may lie next to them.
const WIDE_PREFIX_FRACTION: f64 = 0.125;

/// How far ahead the base prefix pass looks after the wide prefix; when no point in the
/// window has room, the roomiest of the next 1024 keeps the shortfall small.
const PREFIX_LOOKAHEAD: Lookahead = Lookahead {
    window: 64,
    fallback: 1024,
};

/// The same for the subdivision ranking after [`SUB_WIDE_PREFIX`]. From about `3.5 N` on
/// no candidate has the full room (the ranking picks nested subsets of the children's fixed
/// `16 N` points), and the roomiest nearby pick is as good as any wider search.
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

/// The rankings of every tile, with what the build reports of them.
pub(super) struct Rankings {
    /// `order[t][rank]` = index of the merged point.
    pub order: Vec<Vec<usize>>,
    /// `sub_order[t][rank]` = `cell * N + child rank` of the subdivision point.
    pub sub_order: Vec<Vec<usize>>,
    /// For some ranks `r`, the largest `tau / r` over tiles.
    pub rank_lag: Vec<(usize, f64)>,
    /// Base ranks with no point of full room.
    pub prefix_misses: usize,
    /// Subdivision ranks with no point of full room.
    pub sub_prefix_misses: usize,
}

/// Ranks every tile's base points, then its subdivision points.
pub(super) fn rank_tiles(
    config: &BuildConfig,
    merged: &[MergedTile],
    relaxed: &Relaxed,
    rules: &Rules,
    neighbours: &Neighbours,
    progress: &dyn Progress,
) -> Rankings {
    progress.start(Stage::Ranking, 2);
    let base = base_candidates(config, merged, relaxed);
    let (order, rank_lag, prefix_misses) = base_ranking(config, &base, neighbours);
    progress.advance(1);
    let sub = subdivision_candidates(config, relaxed, rules, &order);
    let (sub_order, sub_prefix_misses) = subdivision_ranking(config, &sub, neighbours);
    progress.advance(1);
    progress.finish();
    Rankings {
        order,
        sub_order,
        rank_lag,
        prefix_misses,
        sub_prefix_misses,
    }
}

/// A fixed-point tile position as a point of the unit square.
fn unit(p: [u32; 2]) -> DVec2 {
    DVec2::new(p[0] as f64, p[1] as f64) / FIXED_ONE
}

/// Each tile's relaxed points. A point's first threshold comes from its rank in its
/// source, so a shared edge point starts out the same in every tile that holds it.
fn base_candidates(
    config: &BuildConfig,
    merged: &[MergedTile],
    relaxed: &Relaxed,
) -> Vec<Vec<Candidate>> {
    let source_scale = config.lead * config.points as f64 / config.source_points() as f64;
    relaxed
        .positions
        .iter()
        .zip(merged)
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
        .collect()
}

/// The base ranking: thresholds over all tiles, then the prefix pass. Returns the order,
/// the rank lag of the threshold pass and the prefix misses.
fn base_ranking(
    config: &BuildConfig,
    cands: &[Vec<Candidate>],
    neighbours: &Neighbours,
) -> (Vec<Vec<usize>>, Vec<(usize, f64)>, usize) {
    let big_n = config.points as usize;
    let tau = rank(cands, neighbours, |_| config.alpha, big_n as f64);
    let mut order: Vec<Vec<usize>> = cands
        .iter()
        .zip(&tau)
        .map(|(c, t)| order_by_threshold(c, t))
        .collect();
    let rank_lag: Vec<(usize, f64)> = [16usize, 64, 256, 1024]
        .into_iter()
        .filter(|&r| r < big_n)
        .map(|r| {
            let lag = (0..cands.len())
                .map(|t| tau[t][order[t][r]] / r as f64)
                .fold(0.0f64, f64::max);
            (r, lag)
        })
        .collect();
    let wide = ((big_n as f64 * WIDE_PREFIX_FRACTION) as usize).min(big_n);
    let misses = wide_then_windowed(
        cands,
        &mut order,
        neighbours,
        config,
        PREFIX_LOOKAHEAD,
        0..wide,
    );
    (order, rank_lag, misses)
}

/// The first threshold of a subdivision candidate that is not a base point: a share of
/// the density at which its own child shows it (the paper's figure 8 draws them in random
/// order), with a hashed hair of jitter against ties.
fn child_rank_prior(config: &BuildConfig, t: usize, j: usize, rank_in_child: usize) -> f64 {
    let n = config.subdivision as usize;
    (SUB_CHILD_RANK_LEAD * (n * n * (rank_in_child + 1)) as f64).max(config.points as f64)
        * (1.0 + 1e-3 * unit_f64(hash_words(config.seed, &[0x5ab, t as u64, j as u64])))
}

/// Each tile's `n^2 N` subdivision points (its children's points in their base order, cell
/// by cell): the tile's own base points are fixed at their base ranks.
fn subdivision_candidates(
    config: &BuildConfig,
    relaxed: &Relaxed,
    rules: &Rules,
    order: &[Vec<usize>],
) -> Vec<Vec<Candidate>> {
    let n = config.subdivision as usize;
    let big_n = config.points as usize;
    let sub_len = n * n * big_n;
    // new_index[t][old] = new: a merged point's base rank.
    let new_index: Vec<Vec<usize>> = order
        .iter()
        .map(|o| {
            let mut inverse = vec![0usize; big_n];
            for (new, &old) in o.iter().enumerate() {
                inverse[old] = new;
            }
            inverse
        })
        .collect();
    (0..order.len())
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
                    let fixed = base_rank != usize::MAX;
                    cands.push(Candidate {
                        pos: (offset + p) / n as f64,
                        tau0: if fixed {
                            base_rank as f64
                        } else {
                            child_rank_prior(config, t, cell * big_n + kk, kk)
                        },
                        fixed,
                    });
                }
            }
            cands
        })
        .collect()
}

/// The subdivision ranking: thresholds over all tiles, then the prefix pass from rank `N`
/// (the base points keep the first `N` ranks: they are fixed candidates with `tau < N`).
fn subdivision_ranking(
    config: &BuildConfig,
    cands: &[Vec<Candidate>],
    neighbours: &Neighbours,
) -> (Vec<Vec<usize>>, usize) {
    let big_n = config.points as usize;
    let sub_len = cands.first().map_or(0, Vec::len);
    let tau = rank(cands, neighbours, |_| config.alpha, sub_len as f64);
    let mut order: Vec<Vec<usize>> = cands
        .iter()
        .zip(&tau)
        .map(|(c, t)| order_by_threshold(c, t))
        .collect();
    let wide = ((big_n as f64 * SUB_WIDE_PREFIX) as usize).clamp(big_n, sub_len);
    let misses = wide_then_windowed(
        cands,
        &mut order,
        neighbours,
        config,
        SUB_PREFIX_LOOKAHEAD,
        big_n..wide,
    );
    (order, misses)
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
