//! `rwt points`: the points of a rectangle, one per line, in the serial query's order
//! (large rectangles are queried on all cores, with a progress bar past a second). The query
//! is admitted before `--out` is opened, and the file is replaced atomically: a refused or
//! failed run leaves an existing file as it was.

use crate::spec;
use glam::DVec2;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use rwt_core::density::Density;
use rwt_core::files::AtomicFile;
use rwt_core::query::{Lattice, Point, Rect, Sampler};
use rwt_core::tileset::TileSet;
use std::io::Write;
use std::ops::ControlFlow;
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
    /// How the seed places the tiling.
    pub lattice: Lattice,
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
    let density = spec::parse(args.density, (rect.min(), rect.max())).map_err(|e| e.to_string())?;
    let set = match args.tileset {
        Some(path) => crate::tileset_cmd::load(path)?,
        None => TileSet::embedded(),
    };
    let sampler = Sampler::new(&set, args.seed)
        .with_lattice(args.lattice)
        .with_tile_size(args.tile_size)
        .with_budget(args.budget);
    // Refused queries stop here, before any output exists.
    sampler.admits(&rect, &density).map_err(|e| e.to_string())?;
    let started = Instant::now();
    let parallel = rect.area() / (args.tile_size * args.tile_size) >= PARALLEL_TILES;
    let query = Query {
        sampler: &sampler,
        rect,
        density: &density,
        seed: args.seed,
    };
    let count = match args.out {
        Some(path) => {
            let mut file = AtomicFile::create(path).map_err(|e| e.to_string())?;
            let count = query.write(&mut file, parallel)?;
            file.commit().map_err(|e| e.to_string())?;
            count
        }
        None => {
            let mut out = std::io::BufWriter::new(std::io::stdout().lock());
            let count = query.write(&mut out, parallel)?;
            out.flush().map_err(|e| format!("writing points: {e}"))?;
            count
        }
    };
    eprintln!(
        "{count} points in {:.1} ms",
        started.elapsed().as_secs_f64() * 1e3
    );
    Ok(())
}

/// Rectangles of at least this many base tiles are queried on all cores.
const PARALLEL_TILES: f64 = 256.0;

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

/// An admitted query and the seed its rotations are hashed with.
struct Query<'a> {
    sampler: &'a Sampler,
    rect: Rect,
    density: &'a (dyn Density + Sync),
    seed: u64,
}

impl Query<'_> {
    /// Writes the points to `sink`, serially or on all cores; returns how many.
    fn write(&self, sink: &mut dyn Write, parallel: bool) -> Result<usize, String> {
        if parallel {
            self.parallel(sink)
        } else {
            self.serial(sink)
        }
    }

    /// Streams the points out as the serial query finds them.
    fn serial(&self, sink: &mut dyn Write) -> Result<usize, String> {
        let mut failed = None;
        let count = self
            .sampler
            .query_with(self.rect, self.density, |p| {
                if failed.is_none()
                    && let Err(e) = write_point(sink, &p, self.seed)
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

    /// Queries and formats on all cores (the same points in the same order, a block of base
    /// tiles at a time, a few blocks ahead of the one written: memory stays small however
    /// many points there are); a progress bar appears when this takes longer than a second.
    fn parallel(&self, sink: &mut dyn Write) -> Result<usize, String> {
        let bar = LateBar::new(1000, "points");
        let add = |text: &mut Vec<u8>, p: Point| {
            // Writing to memory cannot fail.
            let _ = write_point(text, &p, self.seed);
        };
        let mut failed = None;
        let count = self
            .sampler
            .query_par_fold(
                self.rect,
                self.density,
                add,
                |text| match sink.write_all(text) {
                    Ok(()) => ControlFlow::Continue(()),
                    Err(e) => {
                        failed = Some(e);
                        ControlFlow::Break(())
                    }
                },
                &|f| bar.set((f * 1000.0) as u64),
            )
            .map_err(|e| e.to_string())?;
        bar.bar.finish_and_clear();
        match failed {
            Some(e) => Err(format!("writing points: {e}")),
            None => Ok(count),
        }
    }
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
        let query = Query {
            sampler: &sampler,
            rect,
            density: &density,
            seed: 5,
        };
        let (mut a, mut b) = (Vec::new(), Vec::new());
        let n = query.write(&mut a, false).unwrap();
        let m = query.write(&mut b, true).unwrap();
        assert_eq!(n, m);
        assert!(n > 500, "{n}");
        assert_eq!(String::from_utf8(a).unwrap(), String::from_utf8(b).unwrap());
    }
}
