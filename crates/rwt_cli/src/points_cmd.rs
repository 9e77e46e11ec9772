//! `rwt points`: the points of a rectangle, one per line, in the serial query's order
//! (large rectangles are queried on all cores, with a progress bar past a second).

use crate::spec;
use glam::DVec2;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use rayon::prelude::*;
use rwt_core::density::Density;
use rwt_core::query::{Point, Rect, Sampler};
use rwt_core::tileset::TileSet;
use std::io::Write;
use std::path::Path;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

/// Options of `rwt points`.
pub struct PointsArgs<'a> {
    /// `x0 y0 x1 y1`.
    pub rect: [f64; 4],
    /// Density spec.
    pub density: &'a str,
    /// Tiling seed.
    pub seed: u64,
    /// Base tile size in world units.
    pub tile_size: f64,
    /// Point budget.
    pub budget: usize,
    /// Output file (stdout when `None`).
    pub out: Option<&'a Path>,
    /// Tile set file (the embedded set when `None`).
    pub tileset: Option<&'a Path>,
}

/// Runs `rwt points`.
pub fn run(args: PointsArgs) -> Result<(), String> {
    let [x0, y0, x1, y1] = args.rect;
    let rect = Rect::new(DVec2::new(x0, y0), DVec2::new(x1, y1)).map_err(|e| e.to_string())?;
    if !(args.tile_size.is_finite() && args.tile_size > 0.0) {
        return Err(format!(
            "--tile-size must be positive, got {}",
            args.tile_size
        ));
    }
    let density = spec::parse(args.density, (rect.min(), rect.max()))?;
    let set = match args.tileset {
        Some(path) => crate::tileset_cmd::load(path)?,
        None => TileSet::embedded(),
    };
    let sampler = Sampler::new(&set, args.seed)
        .with_tile_size(args.tile_size)
        .with_budget(args.budget);
    let mut sink: Box<dyn Write> = match args.out {
        Some(p) => Box::new(std::io::BufWriter::new(
            std::fs::File::create(p).map_err(|e| format!("{}: {e}", p.display()))?,
        )),
        None => Box::new(std::io::BufWriter::new(std::io::stdout().lock())),
    };
    let started = Instant::now();
    let tiles = rect.area() / (args.tile_size * args.tile_size);
    let count = if tiles >= PARALLEL_TILES {
        parallel(&sampler, rect, &density, &mut sink, args.seed)?
    } else {
        serial(&sampler, rect, &density, &mut sink, args.seed)?
    };
    sink.flush().map_err(|e| format!("writing points: {e}"))?;
    eprintln!(
        "{count} points in {:.1} ms",
        started.elapsed().as_secs_f64() * 1e3
    );
    Ok(())
}

/// Rectangles of at least this many base tiles are queried on all cores.
const PARALLEL_TILES: f64 = 256.0;
/// Runs formatted together before they are written.
const WRITE_BATCH: usize = 64;

/// One point as a line: `x y class rotation level:x:y:index`.
fn write_point(sink: &mut dyn Write, p: &Point, seed: u64) -> std::io::Result<()> {
    let id = p.id;
    writeln!(
        sink,
        "{} {} {} {:.6} {}:{}:{}:{}",
        p.position.x,
        p.position.y,
        p.class,
        id.rotation(seed),
        id.level,
        id.x,
        id.y,
        id.index
    )
}

/// Streams the points out as the serial query finds them.
fn serial(
    sampler: &Sampler,
    rect: Rect,
    density: &(dyn Density + Sync),
    sink: &mut dyn Write,
    seed: u64,
) -> Result<usize, String> {
    let mut failed = None;
    let count = sampler
        .query_with(rect, density, |p| {
            if failed.is_none()
                && let Err(e) = write_point(sink, &p, seed)
            {
                failed = Some(e);
            }
        })
        .map_err(|e| e.to_string())?;
    match failed {
        Some(e) => Err(format!("writing points: {e}")),
        None => Ok(count),
    }
}

/// Queries on all cores (the same points in the same order), then writes; a progress bar
/// appears when this takes longer than a second.
fn parallel(
    sampler: &Sampler,
    rect: Rect,
    density: &(dyn Density + Sync),
    sink: &mut dyn Write,
    seed: u64,
) -> Result<usize, String> {
    let bar = LateBar::new(1000, "querying");
    let runs = sampler
        .query_par_runs_with_progress(rect, density, &|f| bar.set((f * 1000.0) as u64))
        .map_err(|e| e.to_string())?;
    let count: usize = runs.iter().map(Vec::len).sum();
    bar.phase(count as u64, "writing");
    // Lines are formatted on all cores, a batch of runs at a time, and written in order.
    let mut written = 0;
    for batch in runs.chunks(WRITE_BATCH) {
        let text: Vec<Vec<u8>> = batch
            .par_iter()
            .map(|run| {
                let mut text = Vec::with_capacity(run.len() * 64);
                for p in run {
                    // Writing to memory cannot fail.
                    let _ = write_point(&mut text, p, seed);
                }
                text
            })
            .collect();
        for t in &text {
            sink.write_all(t)
                .map_err(|e| format!("writing points: {e}"))?;
        }
        written += batch.iter().map(Vec::len).sum::<usize>();
        bar.set(written as u64);
    }
    bar.bar.finish_and_clear();
    Ok(count)
}

/// A progress bar drawn only once its work has run for a second.
struct LateBar {
    bar: ProgressBar,
    started: Instant,
    shown: AtomicBool,
}

impl LateBar {
    fn new(len: u64, message: &'static str) -> Self {
        let bar = ProgressBar::with_draw_target(Some(len), ProgressDrawTarget::hidden());
        bar.set_style(
            ProgressStyle::with_template("{msg:>9} [{bar:32}] {percent:>3}% {elapsed_precise}")
                .unwrap_or_else(|_| ProgressStyle::default_bar()),
        );
        bar.set_message(message);
        Self {
            bar,
            started: Instant::now(),
            shown: AtomicBool::new(false),
        }
    }

    fn set(&self, position: u64) {
        if self.started.elapsed().as_secs_f64() > 1.0 && !self.shown.swap(true, Ordering::Relaxed) {
            self.bar.set_draw_target(ProgressDrawTarget::stderr());
        }
        self.bar.set_position(position);
    }

    fn phase(&self, len: u64, message: &'static str) {
        self.bar.set_length(len);
        self.bar.set_message(message);
        self.set(0);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parallel_output_is_the_serial_output_byte_for_byte() {
        let sampler = Sampler::new(&TileSet::embedded(), 5).with_tile_size(0.5);
        let rect = Rect::new(DVec2::new(-3.0, 1.0), DVec2::new(17.0, 12.5)).unwrap();
        let density = spec::parse("noise:6:0.2", (rect.min(), rect.max())).unwrap();
        assert!(rect.area() / 0.25 >= PARALLEL_TILES);
        let (mut a, mut b) = (Vec::new(), Vec::new());
        let n = serial(&sampler, rect, &density, &mut a, 5).unwrap();
        let m = parallel(&sampler, rect, &density, &mut b, 5).unwrap();
        assert_eq!(n, m);
        assert!(n > 500, "{n}");
        assert_eq!(String::from_utf8(a).unwrap(), String::from_utf8(b).unwrap());
    }
}
