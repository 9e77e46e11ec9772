//! Live figures of the plugin: [`RwtStats`] and the same as Bevy diagnostics under `rwt/`.

mod plugin;

pub use plugin::RwtDiagnosticsPlugin;

use crate::layers::{AssetStatus, ScatterLayerStatus};
use bevy::diagnostic::{DiagnosticPath, Diagnostics};
use bevy::platform::time::Instant;
use bevy::prelude::*;

/// Live figures of the plugin, summed over layers (each layer's own are in its
/// [`ScatterLayerStatus`]).
#[derive(Resource, Clone, Debug, Default, PartialEq, Reflect)]
#[reflect(Resource, Clone, Debug, Default, PartialEq)]
pub struct RwtStats {
    /// Instances of entity classes alive: one entity each (promoted instances of
    /// instanced classes are counted in `live_instanced`).
    pub live_entities: usize,
    /// Instances of instanced classes alive (drawn from chunk buffers, no entity each).
    pub live_instanced: usize,
    /// Chunks loaded.
    pub loaded_chunks: usize,
    /// Chunks being generated or waiting to be.
    pub pending_tasks: usize,
    /// Instances waiting for the spawn budget (or, for instanced classes, the upload budget).
    pub queued_spawns: usize,
    /// Layers waiting for a layer file, density map or heightmap to load.
    pub layers_waiting: usize,
    /// Layers showing nothing because an asset failed to load (the error is logged, and
    /// listed in the layer's [`ScatterLayerStatus`]).
    pub layers_failed: usize,
    /// Time spent in the plugin's systems last frame, milliseconds.
    pub streaming_ms: f64,
}

impl RwtStats {
    /// Whether streaming has settled: no chunk pending, nothing waiting for a budget.
    pub fn settled(&self) -> bool {
        self.pending_tasks == 0 && self.queued_spawns == 0
    }
}

/// Diagnostic paths published by the plugin.
pub mod paths {
    use super::DiagnosticPath;
    /// Live instances.
    pub const LIVE_ENTITIES: DiagnosticPath = DiagnosticPath::const_new("rwt/live_entities");
    /// Live instances of instanced classes.
    pub const LIVE_INSTANCED: DiagnosticPath = DiagnosticPath::const_new("rwt/live_instanced");
    /// Loaded chunks.
    pub const LOADED_CHUNKS: DiagnosticPath = DiagnosticPath::const_new("rwt/loaded_chunks");
    /// Tasks in flight.
    pub const PENDING_TASKS: DiagnosticPath = DiagnosticPath::const_new("rwt/pending_tasks");
    /// Milliseconds in the plugin's systems per frame.
    pub const STREAMING_MS: DiagnosticPath = DiagnosticPath::const_new("rwt/streaming_ms");
    /// Every path.
    pub const ALL: [DiagnosticPath; 5] = [
        LIVE_ENTITIES,
        LIVE_INSTANCED,
        LOADED_CHUNKS,
        PENDING_TASKS,
        STREAMING_MS,
    ];
}

/// When the plugin's first system ran this frame.
#[derive(Resource)]
struct FrameStart(Instant);

fn start_timer(mut start: ResMut<FrameStart>) {
    start.0 = Instant::now();
}

/// Sums the layers' figures into [`RwtStats`].
fn update_stats(layers: Query<&ScatterLayerStatus>, mut stats: ResMut<RwtStats>) {
    let sum = |f: fn(&ScatterLayerStatus) -> usize| layers.iter().map(f).sum::<usize>();
    stats.live_entities = sum(|s| s.live_entities);
    stats.live_instanced = sum(|s| s.live_instanced);
    stats.loaded_chunks = sum(|s| s.loaded_chunks.len());
    stats.pending_tasks = sum(|s| s.pending_tasks);
    stats.queued_spawns = sum(|s| s.queued_spawns);
    stats.layers_waiting = sum(|s| usize::from(matches!(s.assets, AssetStatus::Waiting(_))));
    stats.layers_failed = sum(|s| usize::from(matches!(s.assets, AssetStatus::Failed(_))));
}

fn publish(mut stats: ResMut<RwtStats>, start: Res<FrameStart>, mut diagnostics: Diagnostics) {
    stats.streaming_ms = start.0.elapsed().as_secs_f64() * 1e3;
    let s = stats.clone();
    diagnostics.add_measurement(&paths::LIVE_ENTITIES, || s.live_entities as f64);
    diagnostics.add_measurement(&paths::LIVE_INSTANCED, || s.live_instanced as f64);
    diagnostics.add_measurement(&paths::LOADED_CHUNKS, || s.loaded_chunks as f64);
    diagnostics.add_measurement(&paths::PENDING_TASKS, || s.pending_tasks as f64);
    diagnostics.add_measurement(&paths::STREAMING_MS, || s.streaming_ms);
}
