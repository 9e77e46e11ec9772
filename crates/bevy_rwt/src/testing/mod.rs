//! Headless apps for tests, benchmarks and tools (feature `testing`): the plugin without a
//! window or a renderer, viewers moved by hand, and frames run until streaming settles.
//!
//! ```
//! use bevy::prelude::*;
//! use bevy_rwt::prelude::*;
//! use bevy_rwt::testing::{headless_app, settle, spawn_viewer};
//!
//! let mut app = headless_app(RwtPlugins::default());
//! spawn_viewer(&mut app, Vec3::ZERO);
//! let stones = ScatterClass::new(LayerDensity::Constant(0.5), Handle::default(), Handle::default());
//! app.world_mut().spawn(ScatterLayer::new(vec![stones]));
//! assert!(settle(&mut app, 10_000));
//! assert!(app.world().resource::<RwtStats>().live_entities > 100);
//! ```

pub mod glb;

pub use crate::instancing::{CullingCheck, CullingReport};

use crate::diagnostics::RwtStats;
use crate::viewers::RwtViewer;
use bevy::app::PluginGroup;
use bevy::asset::AssetPlugin;
use bevy::prelude::*;
use std::time::Duration;

/// An app with `MinimalPlugins`, the asset plugin and `plugins`, finished and ready to run
/// frames (classes may hold default mesh and material handles: nothing draws them).
pub fn headless_app(plugins: impl PluginGroup) -> App {
    headless_app_with(plugins, |_| {})
}

/// [`headless_app`], with `extra` adding plugins or resources before the app is finished.
pub fn headless_app_with(plugins: impl PluginGroup, extra: impl FnOnce(&mut App)) -> App {
    let mut app = App::new();
    app.add_plugins((MinimalPlugins, AssetPlugin::default(), plugins));
    extra(&mut app);
    app.finish();
    app.cleanup();
    app
}

/// A viewer streaming all around `at` (both transforms set: no propagation runs headless).
pub fn spawn_viewer(app: &mut App, at: Vec3) -> Entity {
    app.world_mut()
        .spawn((
            RwtViewer::all_around(),
            Transform::from_translation(at),
            GlobalTransform::from_translation(at),
        ))
        .id()
}

/// Moves a viewer (both transforms).
pub fn move_viewer(app: &mut App, viewer: Entity, at: Vec3) {
    let mut e = app.world_mut().entity_mut(viewer);
    if let Some(mut t) = e.get_mut::<Transform>() {
        *t = Transform::from_translation(at);
    }
    if let Some(mut t) = e.get_mut::<GlobalTransform>() {
        *t = GlobalTransform::from_translation(at);
    }
}

/// Runs frames until `done` holds (then `true`) or `max` frames have run (`false`), with a
/// millisecond between frames for the generation tasks.
pub fn run_until(app: &mut App, max: usize, done: impl Fn(&App) -> bool) -> bool {
    for _ in 0..max {
        app.update();
        if done(app) {
            return true;
        }
        std::thread::sleep(Duration::from_millis(1));
    }
    false
}

/// Runs frames until no chunk is pending and nothing waits for a budget in two frames in a
/// row (the second lets the last spawns land); whether it settled within `max` frames.
/// Needs [`RwtStats`] (`RwtDiagnosticsPlugin`).
pub fn settle(app: &mut App, max: usize) -> bool {
    let idle = |app: &App| {
        let s = app.world().resource::<RwtStats>();
        s.settled()
    };
    for _ in 0..max {
        app.update();
        if idle(app) {
            app.update();
            if idle(app) {
                return true;
            }
        }
        std::thread::sleep(Duration::from_millis(1));
    }
    false
}
