//! # bevy_rwt: blue-noise vegetation streamed around your cameras
//!
//! Add [`RwtPlugin`], mark cameras with [`RwtViewer`], and spawn [`ScatterLayer`]s. Each
//! layer places instances of its classes on the ground (x, z) with recursive Wang tile blue
//! noise ([`rwt_core`]): chunks around the viewers are generated on the async compute pool,
//! instances are spawned and despawned within a per-frame budget and share their classes'
//! mesh and material handles (Bevy batches them), painted density maps re-query only the
//! chunks they cover, and level of detail by density only ever adds instances between the
//! existing ones as a viewer approaches.
//!
//! ```no_run
//! use bevy::prelude::*;
//! use bevy_rwt::prelude::*;
//!
//! fn setup(mut commands: Commands, mut meshes: ResMut<Assets<Mesh>>, mut materials: ResMut<Assets<StandardMaterial>>) {
//!     commands.spawn((Camera3d::default(), RwtViewer::default(), Transform::from_xyz(0.0, 2.0, 0.0)));
//!     let bush = ScatterClass::new(
//!         LayerDensity::Constant(0.5), // instances per square unit
//!         meshes.add(Sphere::new(0.3)),
//!         materials.add(Color::srgb(0.2, 0.5, 0.2)),
//!     );
//!     commands.spawn(ScatterLayer::new(vec![bush]).with_falloff(40.0, 200.0));
//! }
//!
//! App::new()
//!     .add_plugins((DefaultPlugins, RwtPlugin::default().with_spawn_budget(4_000)))
//!     .add_systems(Startup, setup)
//!     .run();
//! ```

pub mod debug;
pub mod image_density;
pub mod layer;
pub mod layer_asset;
pub mod streaming;

use bevy::diagnostic::{Diagnostic, Diagnostics, RegisterDiagnostic};
use bevy::ecs::schedule::{InternedScheduleLabel, ScheduleLabel};
use bevy::prelude::*;
pub use layer::{
    ClassLook, HeightSource, InstanceInserter, LayerDensity, ScatterClass, ScatterInstance,
    ScatterLayer,
};
pub use rwt_core;
use rwt_core::streaming::ChunkCoord;
use std::time::Instant;

/// Everything a game needs.
pub mod prelude {
    pub use crate::debug::{RwtGizmos, RwtGizmosPlugin};
    pub use crate::layer_asset::{ScatterLayerAsset, ScatterLayerSource};
    pub use crate::{
        ChunkLoaded, ChunkUnloaded, ClassLook, HeightSource, LayerDensity, RwtPlugin, RwtSettings,
        RwtStats, RwtSystems, RwtViewer, ScatterClass, ScatterInstance, ScatterLayer, ViewCone,
    };
    pub use rwt_core::streaming::StreamingConfig;
}

/// Which directions a viewer streams in.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ViewCone {
    /// Every direction (top-down views, or to be ready for any turn).
    All,
    /// A wedge of this half-angle (radians) around the view direction.
    Fixed(f32),
    /// The horizontal half-angle of the entity's perspective `Projection`, plus `margin`
    /// radians for turning; every direction for other projections.
    Camera {
        /// Extra half-angle beyond the projection's.
        margin: f32,
    },
}

/// Marks an entity (usually a camera) around which layers are streamed. Chunks near it are
/// always loaded; farther ones where its view cone, laid on the ground, reaches them.
#[derive(Component, Clone, Copy, Debug)]
#[require(Transform)]
pub struct RwtViewer {
    /// Directions streamed.
    pub cone: ViewCone,
}

impl RwtViewer {
    /// A viewer that streams in every direction.
    pub fn all_around() -> Self {
        Self {
            cone: ViewCone::All,
        }
    }
}

impl Default for RwtViewer {
    /// The camera's own view cone plus 15 degrees on each side.
    fn default() -> Self {
        Self {
            cone: ViewCone::Camera {
                margin: 15f32.to_radians(),
            },
        }
    }
}

/// A chunk's instances were generated (or regenerated) and queued for spawning.
#[derive(Message, Clone, Copy, Debug, PartialEq)]
pub struct ChunkLoaded {
    /// The layer entity.
    pub layer: Entity,
    /// The chunk.
    pub chunk: ChunkCoord,
    /// Instances the chunk holds now.
    pub instances: usize,
}

/// A chunk left every viewer's unload distance; its instances are being despawned.
#[derive(Message, Clone, Copy, Debug, PartialEq)]
pub struct ChunkUnloaded {
    /// The layer entity.
    pub layer: Entity,
    /// The chunk.
    pub chunk: ChunkCoord,
}

/// Budgets of the streaming systems.
#[derive(Resource, Clone, Debug)]
pub struct RwtSettings {
    /// Most instances spawned per frame (all layers).
    pub spawn_budget: usize,
    /// Most instances despawned per frame (all layers).
    pub despawn_budget: usize,
    /// Most chunk generation tasks in flight per layer.
    pub max_tasks_in_flight: usize,
    /// Length of the view wedge drawn from a viewer on the ground.
    pub footprint_reach: f64,
}

impl Default for RwtSettings {
    fn default() -> Self {
        Self {
            spawn_budget: 5_000,
            despawn_budget: 10_000,
            max_tasks_in_flight: 8,
            footprint_reach: 1.0e4,
        }
    }
}

/// Live figures of the plugin (also published as Bevy diagnostics under `rwt/`).
#[derive(Resource, Clone, Debug, Default, PartialEq)]
pub struct RwtStats {
    /// Instances alive.
    pub live_instances: usize,
    /// Chunks loaded.
    pub loaded_chunks: usize,
    /// Chunks being generated or waiting to be.
    pub pending_tasks: usize,
    /// Instances waiting for the spawn budget.
    pub queued_spawns: usize,
    /// Time spent in the plugin's systems last frame, milliseconds.
    pub streaming_ms: f64,
}

/// The plugin's system sets, in order.
#[derive(SystemSet, Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum RwtSystems {
    /// Viewers to ground positions.
    Viewers,
    /// Chunk planning and task start.
    Plan,
    /// Finished tasks to spawn and despawn queues.
    Collect,
    /// Budgeted spawning and despawning.
    Apply,
    /// Statistics.
    Stats,
}

/// The plugin: streaming plus statistics. Builder-style settings.
pub struct RwtPlugin {
    settings: RwtSettings,
    schedule: InternedScheduleLabel,
}

impl Default for RwtPlugin {
    fn default() -> Self {
        Self {
            settings: RwtSettings::default(),
            schedule: Update.intern(),
        }
    }
}

impl RwtPlugin {
    /// Runs the systems in another schedule (default `Update`).
    pub fn in_schedule(mut self, schedule: impl ScheduleLabel) -> Self {
        self.schedule = schedule.intern();
        self
    }

    /// Most instances spawned per frame.
    pub fn with_spawn_budget(mut self, n: usize) -> Self {
        self.settings.spawn_budget = n;
        self
    }

    /// Most instances despawned per frame.
    pub fn with_despawn_budget(mut self, n: usize) -> Self {
        self.settings.despawn_budget = n;
        self
    }

    /// Most generation tasks in flight per layer.
    pub fn with_max_tasks(mut self, n: usize) -> Self {
        self.settings.max_tasks_in_flight = n.max(1);
        self
    }
}

/// Diagnostic paths published by the plugin.
pub mod diagnostics {
    use bevy::diagnostic::DiagnosticPath;
    /// Live instances.
    pub const LIVE_INSTANCES: DiagnosticPath = DiagnosticPath::const_new("rwt/live_instances");
    /// Loaded chunks.
    pub const LOADED_CHUNKS: DiagnosticPath = DiagnosticPath::const_new("rwt/loaded_chunks");
    /// Tasks in flight.
    pub const PENDING_TASKS: DiagnosticPath = DiagnosticPath::const_new("rwt/pending_tasks");
    /// Milliseconds in the plugin's systems per frame.
    pub const STREAMING_MS: DiagnosticPath = DiagnosticPath::const_new("rwt/streaming_ms");
}

#[derive(Resource)]
struct FrameStart(Instant);

fn start_timer(mut start: ResMut<FrameStart>) {
    start.0 = Instant::now();
}

fn publish(mut stats: ResMut<RwtStats>, start: Res<FrameStart>, mut diagnostics: Diagnostics) {
    stats.streaming_ms = start.0.elapsed().as_secs_f64() * 1e3;
    let s = stats.clone();
    diagnostics.add_measurement(&diagnostics::LIVE_INSTANCES, || s.live_instances as f64);
    diagnostics.add_measurement(&diagnostics::LOADED_CHUNKS, || s.loaded_chunks as f64);
    diagnostics.add_measurement(&diagnostics::PENDING_TASKS, || s.pending_tasks as f64);
    diagnostics.add_measurement(&diagnostics::STREAMING_MS, || s.streaming_ms);
}

impl Plugin for RwtPlugin {
    fn build(&self, app: &mut App) {
        app.insert_resource(self.settings.clone())
            .init_resource::<RwtStats>()
            .insert_resource(FrameStart(Instant::now()))
            .add_message::<ChunkLoaded>()
            .add_message::<ChunkUnloaded>()
            .configure_sets(
                self.schedule,
                (
                    RwtSystems::Viewers,
                    RwtSystems::Plan,
                    RwtSystems::Collect,
                    RwtSystems::Apply,
                    RwtSystems::Stats,
                )
                    .chain(),
            )
            .add_systems(self.schedule, start_timer.before(RwtSystems::Viewers))
            .add_systems(self.schedule, publish.after(RwtSystems::Stats));
        for path in [
            diagnostics::LIVE_INSTANCES,
            diagnostics::LOADED_CHUNKS,
            diagnostics::PENDING_TASKS,
            diagnostics::STREAMING_MS,
        ] {
            app.register_diagnostic(Diagnostic::new(path));
        }
        app.add_plugins(streaming::StreamingPlugin {
            schedule: self.schedule,
        });
    }
}
