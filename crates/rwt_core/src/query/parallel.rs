//! Parallel queries (feature `parallel`): the serial traversal's blocks of base tiles,
//! planned in its order (its splits and its pruning by density bounds) as they are taken
//! on rayon's thread pool, a window of them in flight. [`Sampler::query_par_runs`] returns each block's points as a run;
//! [`Sampler::query_par`] keeps each block's points compactly and builds them into the
//! output in order while later blocks are still being computed; [`Sampler::query_par_ordered`]
//! hands each block's points, mapped on the pool, to the caller in order with a bounded
//! number of blocks in flight, so that writing a file takes as little memory as the serial
//! query. Either way the points are exactly the serial query's, in exactly its order.

use super::prepared::CellPoint;
use super::traversal::{Frame, LEAF_BLOCK, Sink, Visit};
use super::{Point, QueryError, Rect, Sampler, TileRange};
use crate::density::{Density, sanitize};
use glam::DVec2;
use std::collections::BTreeMap;
use std::ops::ControlFlow;
use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::mpsc::{Receiver, Sender, TryRecvError};

impl Sampler {
    /// The points of `rect` for `density`, appended to `out` in the order
    /// [`Sampler::query`] gives them, computed on rayon's thread pool; returns how many.
    /// Strips of base tiles are the unit of work, so small queries gain nothing. Between
    /// calls it keeps up to 32 MiB of scratch memory for the next one.
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
        let Some(range) = self.admit(&rect, density)? else {
            return Ok(0);
        };
        let fork = Fork::new(self, rect, density, &|_| {}, &range);
        let before = out.len();
        // Each block kept compactly on the pool, built into `out` here in order.
        let ahead = KEPT_AHEAD_PER_THREAD * rayon::current_num_threads().max(1);
        fork.in_order(
            fork.blocks(range, STRIP_ROWS),
            ahead,
            |block| fork.kept(block),
            |kept| {
                kept.build_into(self, out);
                kept.give_back();
                ControlFlow::Continue(())
            },
        );
        Ok(out.len() - before)
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
        let fork = Fork::new(self, rect, density, progress, &range);
        let blocks = fork.plan(range, LEAF_BLOCK as usize);
        Ok(fork.runs(&blocks))
    }
}

/// What [`Sampler::query_par_fold`] fills a block's points into: emptied after each block
/// is consumed, its memory kept for a later block.
pub trait Buffer: Default + Send {
    /// Empties the buffer, keeping its memory.
    fn clear(&mut self);
}

impl<T: Send> Buffer for Vec<T> {
    fn clear(&mut self) {
        Vec::clear(self);
    }
}

/// Blocks computed ahead of the one [`Sampler::query_par_ordered`] hands over, per pool thread.
const BLOCKS_AHEAD_PER_THREAD: usize = 4;

/// Blocks kept ahead of the one [`Sampler::query_par`] builds, per pool thread: its blocks
/// are strips of a few tiles, so more of them keep the pool busy (a few kilobytes each).
const KEPT_AHEAD_PER_THREAD: usize = 64;

impl Sampler {
    /// The points of [`Sampler::query`], in its order, computed on rayon's pool a block of
    /// base tiles at a time: `map` turns a block's points into what the caller keeps
    /// (formatted lines, a GPU buffer) on the pool, and `consume` receives the results in
    /// order on the calling thread; returning `Break` stops the query. At most four blocks
    /// per pool thread are computed ahead of the one being consumed, so memory stays bounded
    /// however many points the query yields. `progress` is called from the pool with the
    /// fraction of base tiles done. Returns how many points were consumed.
    ///
    /// ```
    /// use glam::DVec2;
    /// use std::ops::ControlFlow;
    /// use rwt_core::{Constant, Rect, Sampler, TileSet};
    ///
    /// let sampler = Sampler::new(&TileSet::embedded(), 3);
    /// let rect = Rect::new(DVec2::ZERO, DVec2::splat(100.0)).unwrap();
    /// let mut text = String::new();
    /// let lines = |run: &[rwt_core::Point]| -> String {
    ///     run.iter().map(|p| format!("{} {}\n", p.position.x, p.position.y)).collect()
    /// };
    /// let n = sampler
    ///     .query_par_ordered(rect, &Constant(2.0), lines, |t| {
    ///         text.push_str(&t);
    ///         ControlFlow::Continue(())
    ///     }, &|_| {})
    ///     .unwrap();
    /// assert_eq!(text.lines().count(), n);
    /// ```
    pub fn query_par_ordered<D, T, M, C>(
        &self,
        rect: Rect,
        density: &D,
        map: M,
        consume: C,
        progress: &(dyn Fn(f64) + Sync),
    ) -> Result<usize, QueryError>
    where
        D: Density + Sync + ?Sized,
        T: Send,
        M: Fn(&[Point]) -> T + Sync,
        C: FnMut(T) -> ControlFlow<()>,
    {
        let start = || Vec::new();
        let add = |points: &mut Vec<Point>, p: Point| points.push(p);
        let end = |points: Vec<Point>| map(&points);
        self.query_par_blocks(rect, density, (start, add, end), consume, progress)
    }

    /// [`Sampler::query_par_ordered`] without a vector of points per block: each block
    /// adds its points to a buffer with `add` as the traversal finds them, on the pool;
    /// `consume` reads each block's buffer in order on the calling thread (`Break` stops the
    /// query), and the buffer, cleared, takes a later block's points: memory is touched
    /// once, not once a block. `progress` receives the fraction of base tiles done. Returns
    /// how many points were consumed.
    ///
    /// ```
    /// use glam::DVec2;
    /// use std::ops::ControlFlow;
    /// use rwt_core::{Constant, Rect, Sampler, TileSet};
    ///
    /// let sampler = Sampler::new(&TileSet::embedded(), 3);
    /// let rect = Rect::new(DVec2::ZERO, DVec2::splat(100.0)).unwrap();
    /// let mut xs = Vec::new();
    /// let n = sampler
    ///     .query_par_fold(
    ///         rect,
    ///         &Constant(2.0),
    ///         |x: &mut Vec<f64>, p: rwt_core::Point| x.push(p.position.x),
    ///         |x: &Vec<f64>| {
    ///             xs.extend_from_slice(x);
    ///             ControlFlow::Continue(())
    ///         },
    ///         &|_| {},
    ///     )
    ///     .unwrap();
    /// assert_eq!((xs.len(), n), (n, sampler.query_par(rect, &Constant(2.0), &mut Vec::new()).unwrap()));
    /// ```
    pub fn query_par_fold<D, T, A, C>(
        &self,
        rect: Rect,
        density: &D,
        add: A,
        mut consume: C,
        progress: &(dyn Fn(f64) + Sync),
    ) -> Result<usize, QueryError>
    where
        D: Density + Sync + ?Sized,
        T: Buffer,
        A: Fn(&mut T, Point) + Sync,
        C: FnMut(&T) -> ControlFlow<()>,
    {
        let spare = Mutex::new(Vec::<T>::new());
        let start = || {
            let mut spare = spare.lock().unwrap_or_else(|p| p.into_inner());
            spare.pop().unwrap_or_default()
        };
        let recycle = |mut buffer: T| {
            let flow = consume(&buffer);
            buffer.clear();
            spare.lock().unwrap_or_else(|p| p.into_inner()).push(buffer);
            flow
        };
        let build = (start, add, |t| t);
        self.query_par_blocks(rect, density, build, recycle, progress)
    }

    /// The ordered parallel query: `build` is how a block starts, adds a point and ends.
    fn query_par_blocks<D, T, U, S, A, E, C>(
        &self,
        rect: Rect,
        density: &D,
        (start, add, end): (S, A, E),
        mut consume: C,
        progress: &(dyn Fn(f64) + Sync),
    ) -> Result<usize, QueryError>
    where
        D: Density + Sync + ?Sized,
        U: Send,
        S: Fn() -> T + Sync,
        A: Fn(&mut T, Point) + Sync,
        E: Fn(T) -> U + Sync,
        C: FnMut(U) -> ControlFlow<()>,
    {
        let Some(range) = self.admit(&rect, density)? else {
            progress(1.0);
            return Ok(0);
        };
        let fork = Fork::new(self, rect, density, progress, &range);
        let ahead = BLOCKS_AHEAD_PER_THREAD * rayon::current_num_threads().max(1);
        let mut count = 0;
        fork.in_order(
            fork.blocks(range, LEAF_BLOCK as usize),
            ahead,
            |block| {
                let (mut built, mut n) = (start(), 0);
                fork.visit(block, &mut |p: Point| {
                    n += 1;
                    add(&mut built, p);
                });
                fork.progress.finished(&block);
                (n, end(built))
            },
            |(n, u)| {
                count += n;
                consume(u)
            },
        );
        Ok(count)
    }
}

/// Tells the consumer of [`Sampler::query_par_ordered`] that block `.1`'s task unwound, so
/// that it stops waiting for it (forgotten when the task ends normally).
struct SendOnUnwind<'a, T>(&'a Sender<(usize, Option<T>)>, usize);

impl<T> Drop for SendOnUnwind<'_, T> {
    fn drop(&mut self) {
        let _ = self.0.send((self.1, None));
    }
}

/// The result of block `i`, from `waiting` or from the channel (keeping the blocks that
/// arrive early). A pool thread takes pool work while it waits, instead of blocking a
/// thread the blocks may need.
fn next_in_order<T>(
    receiver: &Receiver<(usize, Option<T>)>,
    waiting: &mut BTreeMap<usize, Option<T>>,
    i: usize,
) -> Option<T> {
    let on_pool = rayon::current_thread_index().is_some();
    loop {
        if let Some(done) = waiting.remove(&i) {
            return done;
        }
        let (j, done) = if on_pool {
            match receiver.try_recv() {
                Ok(message) => message,
                Err(TryRecvError::Empty) => {
                    if rayon::yield_now() != Some(rayon::Yield::Executed) {
                        std::thread::yield_now();
                    }
                    continue;
                }
                Err(TryRecvError::Disconnected) => return None,
            }
        } else {
            match receiver.recv() {
                Ok(message) => message,
                Err(_) => return None,
            }
        };
        waiting.insert(j, done);
    }
}

/// The points a block kept, as their runs' frames and their places in their cell lists
/// (4 bytes a point), to be built into the output in order: whole points (56 bytes) would
/// be written, then read and written once more.
#[derive(Default)]
struct Kept {
    /// Each run's frame and the start of its points in `slots`.
    frames: Vec<(Frame, usize)>,
    /// Each point's place in its frame's cell list.
    slots: Vec<u32>,
    /// Whether the run begun last has no frame in `frames` yet.
    pending: bool,
}

/// Kept points' buffers between parallel queries, up to [`SCRATCH_BYTES`]: memory already
/// paged in, where fresh pages cost the kernel more than the points' bytes cost to write.
static SCRATCH: Mutex<Vec<Kept>> = Mutex::new(Vec::new());

/// The most memory [`SCRATCH`] keeps between queries (what 3 million points keep).
const SCRATCH_BYTES: usize = 32 << 20;

impl Sink for Kept {
    #[inline(always)]
    fn begin(&mut self, _: &Frame) {
        self.pending = true;
    }

    #[inline(always)]
    fn accept(&mut self, frame: &Frame, slot: usize, _: &CellPoint, _: DVec2) {
        if self.pending {
            self.frames.push((*frame, self.slots.len()));
            self.pending = false;
        }
        // A slot is below the ranks of its cell list, which are u32.
        self.slots.push(slot as u32);
    }
}

impl Kept {
    /// An empty one, with a buffer from [`SCRATCH`] where one is free.
    fn take() -> Self {
        let reused = SCRATCH.lock().ok().and_then(|mut free| free.pop());
        reused.unwrap_or_default()
    }

    /// Gives the buffers back to [`SCRATCH`], while it holds less than its limit.
    fn give_back(mut self) {
        self.frames.clear();
        self.slots.clear();
        self.pending = false;
        if let Ok(mut free) = SCRATCH.lock() {
            let held: usize = free.iter().map(Kept::bytes).sum();
            if held + self.bytes() <= SCRATCH_BYTES {
                free.push(self);
            }
        }
    }

    fn bytes(&self) -> usize {
        self.frames.capacity() * std::mem::size_of::<(Frame, usize)>()
            + self.slots.capacity() * std::mem::size_of::<u32>()
    }

    /// Appends the block's points to `out`, in order, run by run.
    fn build_into(&self, sampler: &Sampler, out: &mut Vec<Point>) {
        out.reserve(self.slots.len());
        for (k, &(frame, start)) in self.frames.iter().enumerate() {
            let end = self
                .frames
                .get(k + 1)
                .map_or(self.slots.len(), |next| next.1);
            let list = sampler.cell_list(frame.list);
            out.extend(self.slots[start..end].iter().map(|&slot| {
                let cp = &list[slot as usize];
                frame.point(cp, frame.position(cp, &sampler.placement))
            }));
        }
    }
}

/// Rows of base tiles in a unit of parallel work: small enough that the thread building
/// the output in order never waits long for the next one, or for the last.
const STRIP_ROWS: usize = 2;

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

impl<'a, D: Density + Sync + ?Sized> Fork<'a, D> {
    fn new(
        sampler: &'a Sampler,
        rect: Rect,
        density: &'a D,
        report: &'a (dyn Fn(f64) + Sync),
        range: &TileRange,
    ) -> Self {
        Fork {
            sampler,
            rect,
            density,
            progress: Progress {
                total: tiles(range).max(1) as f64,
                done: AtomicU64::new(0),
                report,
            },
        }
    }

    /// The blocks of base tiles in `range` that the serial traversal takes whole, in its
    /// order (see [`Plan`]), all of them.
    fn plan(&self, range: TileRange, strip_rows: usize) -> Vec<TileRange> {
        self.blocks(range, strip_rows).collect()
    }

    /// The blocks of base tiles in `range` that the serial traversal takes whole, in its
    /// order, found as they are asked for.
    fn blocks(&self, range: TileRange, strip_rows: usize) -> Plan<'_, 'a, D> {
        Plan {
            fork: self,
            stack: vec![range],
            strips: Vec::new(),
            strip_rows,
        }
    }

    /// Runs `work` on the pool for `blocks`, at most `ahead` blocks ahead of the one handed
    /// to `consume`, which receives the results in the blocks' order on this thread
    /// (returning `Break` stops it). Blocks are planned as they are spawned, so memory
    /// follows the window, not the range. A block whose task unwinds (a density that
    /// panicked) stops the handing over; the scope then re-raises the panic.
    fn in_order<T: Send>(
        &self,
        mut blocks: impl Iterator<Item = TileRange>,
        ahead: usize,
        work: impl Fn(TileRange) -> T + Sync,
        mut consume: impl FnMut(T) -> ControlFlow<()>,
    ) {
        let (sender, receiver) = std::sync::mpsc::channel();
        let stop = AtomicBool::new(false);
        rayon::in_place_scope_fifo(|scope| {
            let spawn = |i: usize, block: TileRange| {
                let (sender, work, stop) = (sender.clone(), &work, &stop);
                scope.spawn_fifo(move |_| {
                    let unwinding = SendOnUnwind(&sender, i);
                    let done = (!stop.load(Ordering::Relaxed)).then(|| work(block));
                    let _ = sender.send((i, done));
                    std::mem::forget(unwinding);
                });
            };
            let mut spawned = 0;
            for block in blocks.by_ref().take(ahead.max(1)) {
                spawn(spawned, block);
                spawned += 1;
            }
            let mut waiting = BTreeMap::new();
            // Block `i` handed over, the next one spawned, until none is in flight.
            let mut i = 0;
            while i < spawned {
                // `None`: the block's task unwound, and the scope re-raises it.
                let Some(t) = next_in_order(&receiver, &mut waiting, i) else {
                    break;
                };
                if consume(t).is_break() {
                    break;
                }
                i += 1;
                if let Some(block) = blocks.next() {
                    spawn(spawned, block);
                    spawned += 1;
                }
            }
            stop.store(true, Ordering::Relaxed);
        });
    }

    /// The points of `blocks`, a run each: halves of the list forked on the pool.
    fn runs(&self, blocks: &[TileRange]) -> Vec<Vec<Point>> {
        if blocks.is_empty() {
            return Vec::new();
        }
        if let [block] = blocks {
            let points = self.points(*block);
            self.progress.finished(block);
            return vec![points];
        }
        let (first, second) = blocks.split_at(blocks.len() / 2);
        let (mut a, b) = rayon::join(|| self.runs(first), || self.runs(second));
        a.extend(b);
        a
    }

    /// The points of a block small enough to take on one thread.
    fn points(&self, range: TileRange) -> Vec<Point> {
        let mut points = Vec::new();
        self.visit(range, &mut |p: Point| points.push(p));
        points
    }

    /// The points of a block, kept to be built later.
    fn kept(&self, range: TileRange) -> Kept {
        let mut kept = Kept::take();
        self.visit(range, &mut kept);
        kept
    }

    /// The serial traversal of a block.
    fn visit<F: Sink>(&self, range: TileRange, sink: &mut F) {
        let mut visit = Visit {
            sampler: self.sampler,
            rect: self.rect,
            density: self.density,
            emit: sink,
        };
        visit.blocks(
            range.i0,
            range.i1,
            range.j0,
            range.j1,
            self.sampler.tile_size(),
        );
    }
}

/// The blocks of a [`Fork`]'s range in the serial traversal's order: its splits, skipping
/// blocks where the density is zero (counted done at once). Lazy, so that memory follows
/// the blocks being worked on, not the rectangle: a depth-first stack of at most two
/// ranges per level, and the strips of one leaf.
struct Plan<'f, 'a, D: ?Sized> {
    fork: &'f Fork<'a, D>,
    /// Ranges still to split, the next on top.
    stack: Vec<TileRange>,
    /// Strips of the current leaf still to hand out, the next on top.
    strips: Vec<TileRange>,
    strip_rows: usize,
}

impl<D: Density + Sync + ?Sized> Iterator for Plan<'_, '_, D> {
    type Item = TileRange;

    fn next(&mut self) -> Option<TileRange> {
        loop {
            if let Some(strip) = self.strips.pop() {
                return Some(strip);
            }
            let range = self.stack.pop()?;
            let TileRange { i0, i1, j0, j1 } = range;
            if i1 <= i0 || j1 <= j0 {
                continue;
            }
            if i1 - i0 <= LEAF_BLOCK && j1 - j0 <= LEAF_BLOCK {
                // The traversal takes a leaf row by row, so strips of its rows keep its order.
                let rows = self.strip_rows as i64;
                let mut j = j0 + (j1 - j0 - 1) / rows * rows;
                loop {
                    let top = (j + rows).min(j1);
                    self.strips.push(TileRange {
                        j0: j,
                        j1: top,
                        ..range
                    });
                    if j == j0 {
                        break;
                    }
                    j -= rows;
                }
                continue;
            }
            let fork = self.fork;
            let bound = fork
                .sampler
                .block_rect(range)
                .intersect(&fork.rect)
                .map(|b| sanitize(fork.density.max_over(b.min(), b.max())));
            if !bound.is_some_and(|b| b > 0.0) {
                fork.progress.finished(&range);
                continue;
            }
            let (im, jm) = (i0 + (i1 - i0) / 2, j0 + (j1 - j0) / 2);
            let (first, second) = if i1 - i0 >= j1 - j0 {
                (TileRange { i1: im, ..range }, TileRange { i0: im, ..range })
            } else {
                (TileRange { j1: jm, ..range }, TileRange { j0: jm, ..range })
            };
            self.stack.push(second);
            self.stack.push(first);
        }
    }
}
