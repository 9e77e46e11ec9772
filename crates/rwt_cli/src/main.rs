//! `rwt`: the command line of the rwt workspace.

mod draw;
mod tileset_cmd;

use clap::{Parser, Subcommand};
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
        #[arg(long)]
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
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Tileset { action } => match action {
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
            TilesetAction::Render { file, out } => {
                tileset_cmd::render_cmd(&file, &out).map(|()| true)
            }
        },
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
