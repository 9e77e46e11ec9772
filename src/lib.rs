//! What the examples share:
//! - the open world that `open_world`, `web` and `multiplayer` stream ([`world`]), the
//!   asset pack its vegetation is made of ([`pack`]), its forests ([`forest`]) and the
//!   cabin players place ([`cabin`]);
//! - the scripted smoke session that lets CI run each example in a real renderer
//!   ([`smoke`]), and frames captured and compared by the examples that check themselves
//!   ([`frame_check`]);
//! - a fly camera ([`fly_camera`]), a text HUD ([`hud`]) and the brush's last answer for it
//!   ([`brush_status`]);
//! - the field of grass the cost benchmarks time ([`grass_field`]) and their frame timing
//!   ([`frame_clock`]);
//! - the files the examples write for the asset server ([`generated`]).
//!
//! Run an example as a user would (`cargo run --release --example open_world`), or as CI
//! does: `RWT_SCREENSHOT=out.png cargo run --example open_world` plays the example's script,
//! saves a screenshot, prints `rwt-smoke: ... instances N` and exits with status 0.

pub mod brush_status;
pub mod cabin;
pub mod fly_camera;
pub mod foliage;
pub mod forest;
pub mod frame_check;
pub mod frame_clock;
pub mod generated;
pub mod grass_field;
pub mod hud;
pub mod pack;
pub mod smoke;
pub mod terrain;
pub mod tuft;
pub mod world;

use bevy::prelude::*;
use bevy::window::{PresentMode, WindowResolution};

/// Everything an example needs from here.
pub mod prelude {
    pub use crate::brush_status::{BrushStatus, BrushStatusPlugin};
    pub use crate::fly_camera::{FlyCamera, FlyCameraPlugin};
    pub use crate::hud::{Hud, HudPlugin};
    pub use crate::smoke::{CountedInstance, LiveInstances, Smoke, SmokePlugin, SmokeReport};
    pub use crate::{example_plugins, textons_dir};
}

/// Bevy's default plugins with a window titled `title`, 1280 x 720 unless
/// `RWT_WINDOW=WIDTHxHEIGHT` asks for another size (CI's smoke runs render a quarter of the
/// pixels on the CPU); without vsync while a smoke session runs, so software rendering
/// stays quick.
pub fn example_plugins(title: &str) -> impl PluginGroup {
    let smoke = smoke::Smoke::from_env();
    let (width, height) = window_size_from_env().unwrap_or((1280, 720));
    let present_mode = if smoke.active() {
        PresentMode::AutoNoVsync
    } else {
        PresentMode::AutoVsync
    };
    DefaultPlugins.set(WindowPlugin {
        primary_window: Some(Window {
            title: title.to_string(),
            resolution: WindowResolution::new(width, height),
            present_mode,
            ..default()
        }),
        ..default()
    })
}

/// `RWT_WINDOW=WIDTHxHEIGHT`, when set to a size of 64 to 4096 pixels a side.
fn window_size_from_env() -> Option<(u32, u32)> {
    let text = std::env::var("RWT_WINDOW").ok()?;
    let (w, h) = text.trim().split_once('x')?;
    let size = |v: &str| v.parse::<u32>().ok().filter(|v| (64..=4096).contains(v));
    Some((size(w)?, size(h)?))
}

/// Where the texton images live (`assets/textons`, drawn by `scripts/make_textons.py`).
pub fn textons_dir() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/textons")
}

/// The README's examples, compiled and run as doctests (`cargo test --doc`).
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
pub struct ReadmeDoctests;

/// The guide's Rust examples, compiled (and run, where not `no_run`) as doctests: one item
/// per page of `docs/guide` (`tests/docs.rs` checks that none is left out).
#[cfg(doctest)]
pub mod guide {
    #[doc = include_str!("../docs/guide/acting.md")]
    pub struct Acting;
    #[doc = include_str!("../docs/guide/assets.md")]
    pub struct Assets;
    #[doc = include_str!("../docs/guide/examples.md")]
    pub struct Examples;
    #[doc = include_str!("../docs/guide/ground.md")]
    pub struct Ground;
    #[doc = include_str!("../docs/guide/instanced.md")]
    pub struct Instanced;
    #[doc = include_str!("../docs/guide/library.md")]
    pub struct Library;
    #[doc = include_str!("../docs/guide/multiplayer.md")]
    pub struct Multiplayer;
    #[doc = include_str!("../docs/guide/plugin.md")]
    pub struct Plugin;
    #[doc = include_str!("../docs/guide/python.md")]
    pub struct Python;
    #[doc = include_str!("../docs/guide/README.md")]
    pub struct Contents;
    #[doc = include_str!("../docs/guide/reliability.md")]
    pub struct Reliability;
    #[doc = include_str!("../docs/guide/speed.md")]
    pub struct Speed;
    #[doc = include_str!("../docs/guide/stippling.md")]
    pub struct Stippling;
    #[doc = include_str!("../docs/guide/tile-set.md")]
    pub struct TileSet;
}
