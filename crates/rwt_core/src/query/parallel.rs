//! Parallel queries (feature `parallel`): the serial traversal's block recursion with its
//! splits forked on rayon. Each branch collects its own points and the branches are joined
//! in the order the serial traversal visits them, so a parallel query returns exactly the
//! serial query's points in exactly its order.

use super::traversal::{LEAF_BLOCK, Visit};
use super::{Point, QueryError, Rect, Sampler, TileRange};
use crate::density::{Density, sanitize};
use glam::DVec2;
use rayon::prelude::*;
use std::sync::atomic::{AtomicU64, Ordering};

/// Points each task copies when the runs are joined.
const JOIN_GRAIN: usize = 1 << 15;

impl Sampler {
    /// The points of `rect` for `density`, appended to `out` in the order
    /// [`Sampler::query`] gives them, computed on rayon's thread pool; returns how many.
    /// Blocks of base tiles are the unit of work, so small queries gain nothing.
    ///
    /// ```
    /// use glam::DVec2;
    /// use rwt_core::{Constant, Rect, Sampler, TileSet};
    ///
    /// let sampler = Sampler::new(&TileSet::embedded(), 3);
    /// let rect = Rect::new(DVec2::ZERO, DVec2::splat(200.0)).unwrap();
    /// let (mut serial, mut parallel) = (Vec::new(), Vec::new());
    /// sampler.query(rect, &Constant(2.0), &mut serial).unwrap();
    /// sampler.query_par(rect, &Constant(2.0), &mut parallel).unwrap();
    /// assert_eq!(serial, parallel);
    /// ```
    pub fn query_par<D: Density + Sync + ?Sized>(
        &self,
        rect: Rect,
        density: &D,
        out: &mut Vec<Point>,
    ) -> Result<usize, QueryError> {
        let runs = self.query_par_runs(rect, density)?;
        // Start of each run in the joined order; the join itself runs in parallel too.
        let starts: Vec<usize> = runs
            .iter()
            .scan(0, |at, r| {
                let start = *at;
                *at += r.len();
                Some(start)
            })
            .collect();
        let count = runs.iter().map(Vec::len).sum();
        out.par_extend(
            (0..count)
                .into_par_iter()
                .with_min_len(JOIN_GRAIN)
                .map(|i| {
                    let run = starts.partition_point(|&s| s <= i) - 1;
                    runs[run][i - starts[run]]
                }),
        );
        Ok(count)
    }

    /// The points of [`Sampler::query_par`] as consecutive runs (one per block of base
    /// tiles), without joining them into one vector: read in order, the runs are exactly
    /// the serial query's points in its order. Writers that stream points out (a file, a
    /// GPU buffer) save the copy that joining costs.
    pub fn query_par_runs<D: Density + Sync + ?Sized>(
        &self,
        rect: Rect,
        density: &D,
    ) -> Result<Vec<Vec<Point>>, QueryError> {
        self.query_par_runs_with_progress(rect, density, &|_| {})
    }

    /// [`Sampler::query_par_runs`], calling `progress` from the worker threads with the
    /// fraction (0..=1) of the rectangle's base tiles done so far, as blocks finish.
    pub fn query_par_runs_with_progress<D: Density + Sync + ?Sized>(
        &self,
        rect: Rect,
        density: &D,
        progress: &(dyn Fn(f64) + Sync),
    ) -> Result<Vec<Vec<Point>>, QueryError> {
        let Some(range) = self.admit(&rect, density)? else {
            progress(1.0);
            return Ok(Vec::new());
        };
        Ok(Fork {
            sampler: self,
            rect,
            density,
            progress: Progress {
                total: tiles(&range).max(1) as f64,
                done: AtomicU64::new(0),
                report: progress,
            },
        }
        .blocks(range))
    }
}

/// Base tiles of a range.
fn tiles(range: &TileRange) -> u64 {
    ((range.i1 - range.i0).max(0) as u64).saturating_mul((range.j1 - range.j0).max(0) as u64)
}

/// Base tiles done, reported as a fraction.
struct Progress<'a> {
    total: f64,
    done: AtomicU64,
    report: &'a (dyn Fn(f64) + Sync),
}

impl Progress<'_> {
    fn finished(&self, range: &TileRange) {
        let done = self.done.fetch_add(tiles(range), Ordering::Relaxed) + tiles(range);
        (self.report)((done as f64 / self.total).min(1.0));
    }
}

/// A parallel query in progress.
struct Fork<'a, D: ?Sized> {
    sampler: &'a Sampler,
    rect: Rect,
    density: &'a D,
    progress: Progress<'a>,
}

impl<D: Density + Sync + ?Sized> Fork<'_, D> {
    /// The points of base tiles `range`, as runs in serial order (joined once at the end,
    /// not copied at every split): the serial `Visit::blocks` split, each half on its own
    /// task, the first half's runs first.
    fn blocks(&self, range: TileRange) -> Vec<Vec<Point>> {
        let TileRange { i0, i1, j0, j1 } = range;
        if i1 <= i0 || j1 <= j0 {
            return Vec::new();
        }
        if i1 - i0 <= LEAF_BLOCK && j1 - j0 <= LEAF_BLOCK {
            let run = self.serial(range);
            self.progress.finished(&range);
            return vec![run];
        }
        let s = self.sampler.tile_size();
        let block = Rect::from_ordered(
            DVec2::new(i0 as f64 * s, j0 as f64 * s),
            DVec2::new(i1 as f64 * s, j1 as f64 * s),
        );
        let Some(block) = block.intersect(&self.rect) else {
            self.progress.finished(&range);
            return Vec::new();
        };
        let bound = sanitize(self.density.max_over(block.min(), block.max()));
        if bound.is_nan() || bound <= 0.0 {
            self.progress.finished(&range);
            return Vec::new();
        }
        let (im, jm) = (i0 + (i1 - i0) / 2, j0 + (j1 - j0) / 2);
        let (first, second) = if i1 - i0 >= j1 - j0 {
            (TileRange { i1: im, ..range }, TileRange { i0: im, ..range })
        } else {
            (TileRange { j1: jm, ..range }, TileRange { j0: jm, ..range })
        };
        let (mut a, b) = rayon::join(|| self.blocks(first), || self.blocks(second));
        a.extend(b);
        a
    }

    /// The points of a block small enough to take on one thread.
    fn serial(&self, range: TileRange) -> Vec<Point> {
        let mut points = Vec::new();
        let mut emit = |p: Point| points.push(p);
        let mut visit = Visit {
            sampler: self.sampler,
            rect: self.rect,
            density: self.density,
            emit: &mut emit,
        };
        visit.blocks(
            range.i0,
            range.i1,
            range.j0,
            range.j1,
            self.sampler.tile_size(),
        );
        points
    }
}
