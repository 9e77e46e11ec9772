//! `rwt`: the command line of the rwt workspace.

/// `println!` that ignores a closed standard output (`rwt ... | head`) instead of panicking.
macro_rules! say {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let _ = writeln!(std::io::stdout(), $($arg)*);
    }};
}

mod analyse_cmd;
mod bench_cmd;
mod draw;
mod points_cmd;
mod spec;
mod stipple_cmd;
mod tileset_cmd;
mod zoneplate_cmd;

use clap::{Parser, Subcommand};
use rwt_core::Lattice;
use rwt_core::construction::BuildConfig;
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Parser)]
#[command(
    name = "rwt",
    version,
    about = "Recursive Wang tiles for real-time blue noise"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Build, check or render tile sets.
    Tileset {
        #[command(subcommand)]
        action: TilesetAction,
    },
    /// Points of a rectangle for a density: `x y class rotation level:x:y:index` per line.
    Points {
        /// The rectangle: x0 y0 x1 y1.
        #[arg(long, required = true, num_args = 4, value_names = ["X0", "Y0", "X1", "Y1"], allow_negative_numbers = true, value_parser = finite)]
        rect: Vec<f64>,
        /// `const:V` (points per unit area), `image:PATH[:V]`, `dark:PATH[:V]` or
        /// `noise:V[:FREQ[:OCTAVES[:SEED]]]`; images are stretched over the rectangle, their
        /// luma times alpha (transparent is empty). A path may contain `:`; one ending in
        /// `:NUMBER` goes in double quotes: `image:"a:5":500`.
        #[arg(long)]
        density: String,
        /// Tiling seed: each seed turns and moves the whole tiling, so that two seeds give
        /// independent point sets.
        #[arg(long, default_value_t = 0)]
        seed: u64,
        /// Lay the tiles of every seed on one grid, unturned (where points were before
        /// seeds turned the tiling).
        #[arg(long)]
        aligned_lattice: bool,
        /// Width of a base tile in world units.
        #[arg(long, default_value_t = 1.0, value_parser = finite)]
        tile_size: f64,
        /// Refuse queries that may produce more points than this.
        #[arg(long, default_value_t = rwt_core::query::DEFAULT_BUDGET)]
        budget: usize,
        /// Output file (default: standard output).
        #[arg(long)]
        out: Option<PathBuf>,
        /// Tile set file built by `rwt tileset build` (default: the embedded set).
        #[arg(long)]
        tileset: Option<PathBuf>,
    },
    /// Normalized minimum distance, spectrum and anisotropy of a point file, beside dart
    /// throwing, a jittered grid and white noise computed in the same run.
    Analyse {
        /// Points, `x y` first on each line.
        file: PathBuf,
        /// Draw points, spectrum, radial power and anisotropy to this PNG.
        #[arg(long)]
        plot: Option<PathBuf>,
    },
    /// Stipple an image: dots with blue-noise spacing whose ink matches the image's tone.
    Stipple {
        /// Input image.
        image: PathBuf,
        /// Output .svg or .png (antialiased).
        #[arg(long)]
        out: PathBuf,
        /// Number of dots (default: one per four image pixels; the radius follows).
        #[arg(long, conflicts_with = "radius")]
        points: Option<usize>,
        /// Dot radius in image pixels (the number of dots follows).
        #[arg(long, value_parser = finite)]
        radius: Option<f64>,
        /// Darkness exponent: darkness = (contrast * (1 - grey))^gamma.
        #[arg(long, default_value_t = 1.0, value_parser = finite)]
        gamma: f64,
        /// Darkness multiplier (see --gamma).
        #[arg(long, default_value_t = 1.0, value_parser = finite)]
        contrast: f64,
        /// Tiling seed.
        #[arg(long, default_value_t = 0)]
        seed: u64,
        /// Output pixels per image pixel.
        #[arg(long, default_value_t = 2.0, value_parser = finite)]
        scale: f64,
        /// Refuse stipples of more dots than this.
        #[arg(long, default_value_t = rwt_core::stipple::DEFAULT_MAX_DOTS)]
        max_dots: usize,
        /// Refuse rendered rasters of more pixels than this.
        #[arg(long, default_value_t = rwt_core::stipple::DEFAULT_MAX_RASTER_PIXELS)]
        max_raster_pixels: u64,
        /// Refuse images of more pixels than this.
        #[arg(long, default_value_t = rwt_core::stipple::DEFAULT_MAX_IMAGE_PIXELS)]
        max_image_pixels: u64,
    },
    /// The paper's anti-aliasing test: the zone plate sin(x^2 + y^2) at one sample per pixel
    /// with a Gaussian reconstruction, for rwt, a regular grid, jittering, white noise, dart
    /// throwing and Owen-scrambled Sobol, against a supersampled reference: PSNR, and the
    /// error's low band (aliasing) and high band (noise).
    Zoneplate {
        /// Pixels on a side.
        #[arg(long, default_value_t = 512)]
        size: usize,
        /// Seed of every pattern.
        #[arg(long, default_value_t = 0)]
        seed: u64,
        /// Write the reference and each pattern's image side by side to this PNG.
        #[arg(long)]
        out: Option<PathBuf>,
    },
    /// Throughput and scaling of queries, as ratios measured in one run.
    Bench {
        /// Smaller, faster run.
        #[arg(long)]
        quick: bool,
    },
}

#[derive(Subcommand)]
enum TilesetAction {
    /// Build a tile set (deterministic for a seed).
    Build {
        /// Output RON file.
        #[arg(long)]
        out: PathBuf,
        /// Seed of every random choice.
        #[arg(long, default_value_t = BuildConfig::default().seed)]
        seed: u64,
        /// Edge colours per orientation (K^4 tiles).
        #[arg(long, default_value_t = BuildConfig::default().colors)]
        colors: u8,
        /// Points per tile.
        #[arg(long, default_value_t = BuildConfig::default().points)]
        points: u32,
        /// Subdivision factor n (n x n children).
        #[arg(long, default_value_t = BuildConfig::default().subdivision)]
        subdivision: u8,
    },
    /// Validate a tile set and print its quality figures; exits non-zero when invalid.
    Check {
        /// Tile set file.
        file: PathBuf,
        /// Also fail when a prefix's normalized minimum distance is below this.
        #[arg(long, value_parser = finite)]
        min_rho: Option<f64>,
    },
    /// Draw the tiles (seams, origins, edge colours) and a two-level subdivision.
    Render {
        /// Tile set file.
        file: PathBuf,
        /// Output PNG.
        #[arg(long)]
        out: PathBuf,
    },
}

fn main() -> ExitCode {
    // Ctrl-C, SIGTERM and SIGHUP end the program without leaving half-written files: the
    // targets keep their previous bytes.
    let _ = ctrlc::set_handler(|| {
        rwt_core::files::remove_temporaries();
        eprintln!("interrupted: no output was changed");
        std::process::exit(130);
    });
    let result = match Cli::parse().command {
        Command::Tileset { action } => tileset(action),
        Command::Points {
            rect,
            density,
            seed,
            aligned_lattice,
            tile_size,
            budget,
            out,
            tileset,
        } => points_cmd::run(points_cmd::PointsArgs {
            rect: [rect[0], rect[1], rect[2], rect[3]],
            density: &density,
            seed,
            lattice: match aligned_lattice {
                true => Lattice::Aligned,
                false => Lattice::Seeded,
            },
            tile_size,
            budget,
            out: out.as_deref(),
            tileset: tileset.as_deref(),
        })
        .map(|()| true),
        Command::Analyse { file, plot } => analyse_cmd::run(&file, plot.as_deref()).map(|()| true),
        Command::Stipple {
            image,
            out,
            points,
            radius,
            gamma,
            contrast,
            seed,
            scale,
            max_dots,
            max_raster_pixels,
            max_image_pixels,
        } => stipple_cmd::run(&stipple_cmd::StippleArgs {
            image: &image,
            out: &out,
            points,
            radius,
            tone: rwt_core::stipple::ToneMap { gamma, contrast },
            seed,
            scale,
            limits: rwt_core::stipple::StippleLimits {
                max_dots,
                max_raster_pixels,
                max_image_pixels,
            },
        })
        .map(|()| true),
        Command::Bench { quick } => bench_cmd::run(quick).map(|()| true),
        Command::Zoneplate { size, seed, out } => {
            zoneplate_cmd::run(size, seed, out.as_deref()).map(|()| true)
        }
    };
    match result {
        Ok(true) => ExitCode::SUCCESS,
        Ok(false) => ExitCode::FAILURE,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(2)
        }
    }
}

/// A number option's value: finite (NaN and infinities are refused where they are typed,
/// not turned into nonsense later).
fn finite(text: &str) -> Result<f64, String> {
    match text.trim().parse::<f64>() {
        Ok(v) if v.is_finite() => Ok(v),
        Ok(v) => Err(format!("{v} is not a finite number")),
        Err(e) => Err(e.to_string()),
    }
}

/// `rwt tileset ...`: whether it succeeded (a check may fail without an error).
fn tileset(action: TilesetAction) -> Result<bool, String> {
    match action {
        TilesetAction::Build {
            out,
            seed,
            colors,
            points,
            subdivision,
        } => tileset_cmd::build_cmd(
            &out,
            BuildConfig {
                seed,
                colors,
                points,
                subdivision,
                ..BuildConfig::default()
            },
        )
        .map(|()| true),
        TilesetAction::Check { file, min_rho } => tileset_cmd::check_cmd(&file, min_rho),
        TilesetAction::Render { file, out } => tileset_cmd::render_cmd(&file, &out).map(|()| true),
    }
}
