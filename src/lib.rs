//! What the examples share: the scripted smoke session that lets CI run each example in a
//! real renderer ([`smoke`]), a fly camera ([`fly_camera`]) and a text HUD ([`hud`]).
//!
//! Run an example as a user would (`cargo run --release --example open_world`), or as CI
//! does: `RWT_SCREENSHOT=out.png cargo run --example open_world` plays the example's script,
//! saves a screenshot, prints `rwt-smoke: ... instances N` and exits with status 0.

pub mod fly_camera;
pub mod foliage;
pub mod hud;
pub mod smoke;
pub mod terrain;

use bevy::prelude::*;
use bevy::window::{PresentMode, WindowResolution};

/// Everything an example needs from here.
pub mod prelude {
    pub use crate::fly_camera::{FlyCamera, FlyCameraPlugin};
    pub use crate::hud::{Hud, HudPlugin};
    pub use crate::smoke::{CountedInstance, LiveInstances, Smoke, SmokePlugin, SmokeReport};
    pub use crate::{example_plugins, textons_dir};
}

/// Bevy's default plugins with a 1280 x 720 window titled `title`; without vsync while a
/// smoke session runs, so software rendering stays quick.
pub fn example_plugins(title: &str) -> impl PluginGroup {
    let smoke = smoke::Smoke::from_env();
    let (width, height, present_mode) = if smoke.active() {
        (1280, 720, PresentMode::AutoNoVsync)
    } else {
        (1280, 720, PresentMode::AutoVsync)
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

/// Where the texton images live (`assets/textons`, drawn by `scripts/make_textons.py`).
pub fn textons_dir() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/textons")
}
