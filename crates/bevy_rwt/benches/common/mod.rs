//! What the headless benchmarks share: an app without a renderer, and a viewer to fly.

use bevy::prelude::*;
use bevy_rwt::prelude::*;
pub use bevy_rwt::testing::move_viewer;
use bevy_rwt::testing::{headless_app as app_with, spawn_viewer};

/// A headless app with `plugins`, and a viewer that streams all around it; returns the app
/// and the viewer.
pub fn headless_app(plugins: RwtPlugins) -> (App, Entity) {
    let mut app = app_with(plugins);
    let viewer = spawn_viewer(&mut app, Vec3::ZERO);
    (app, viewer)
}
