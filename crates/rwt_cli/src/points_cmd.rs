//! `rwt points`: the points of a rectangle, one per line.

use crate::spec;
use glam::DVec2;
use rwt_core::query::{Rect, Sampler};
use rwt_core::tileset::TileSet;
use std::io::Write;
use std::path::Path;

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
    let mut failed = None;
    let started = std::time::Instant::now();
    let count = sampler
        .query_with(rect, &density, |p| {
            if failed.is_none() {
                let id = p.id;
                if let Err(e) = writeln!(
                    sink,
                    "{} {} {} {:.6} {}:{}:{}:{}",
                    p.position.x,
                    p.position.y,
                    p.class,
                    id.rotation(args.seed),
                    id.level,
                    id.x,
                    id.y,
                    id.index
                ) {
                    failed = Some(e);
                }
            }
        })
        .map_err(|e| e.to_string())?;
    if let Some(e) = failed {
        return Err(format!("writing points: {e}"));
    }
    sink.flush().map_err(|e| format!("writing points: {e}"))?;
    eprintln!(
        "{count} points in {:.1} ms",
        started.elapsed().as_secs_f64() * 1e3
    );
    Ok(())
}
