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
//! ## How it is built
//!
//! [`RwtPlugin`] is a group of small plugins, each registering its own systems in one of
//! the [`RwtSystems`] sets (in order: `Viewers`, `Plan`, `Collect`, `Apply`, `Stats`):
//!
//! | plugin | module | does |
//! |---|---|---|
//! | [`viewers::RwtViewersPlugin`] | [`viewers`] | lays every [`RwtViewer`] on the ground |
//! | [`layers::RwtLayersPlugin`] | [`layers`] | layer files (`*.layer.ron`) and asset status |
//! | [`streaming::RwtStreamingPlugin`] | [`streaming`] | chunks, generation tasks, budgeted spawns, repainting |
//! | [`diagnostics::RwtDiagnosticsPlugin`] | [`diagnostics`] | [`RwtStats`] and `rwt/` diagnostics |
//! | [`instancing::RwtInstancingPlugin`] | [`instancing`] | instanced classes: mesh checks, one instanced draw per chunk (wind, fade-in) |
//! | [`gizmos::RwtGizmosPlugin`] (opt-in) | [`gizmos`] | chunk and tile outlines |
//!
//! The data path from a painted map to an instance: a brush writes the map (`Image`) and a
//! [`DensityMapPainted`] message → `repaint` forgets the snapshots that read the map and
//! marks the chunks under the stroke stale → `plan_chunks` resolves the map into an
//! [`rwt_core::ImageDensity`] and starts a query task per stale chunk → `collect_results`
//! diffs the points by [`rwt_core::PointId`] → `apply_budget` spawns what appeared and
//! despawns what went. `docs/ARCHITECTURE.md` draws it whole.
//!
//! ## Acting on the world
//!
//! A game changes single instances through their stable identity, without storing the
//! world: [`edits`] ([`edits::EditInstance`] to remove, restore or reclass one instance; a
//! [`edits::ScatterEdits`] set per layer, saved by the brush), [`footprints`] (a
//! [`footprints::Footprint`] on any entity clears the ground under it), [`picking`]
//! ([`picking::ScatterPicking`]: the instance a ray hits) and promotion
//! ([`ScatterClass::with_promotion`]: near instances of an instanced class become entities
//! with the class's components). Each module's page has a worked example.
//!
//! ```
//! use bevy::prelude::*;
//! use bevy_rwt::prelude::*;
//!
//! let mut app = App::new();
//! app.add_plugins((MinimalPlugins, bevy::asset::AssetPlugin::default(), RwtPlugin::default()));
//! app.finish();
//! app.cleanup();
//! app.world_mut().spawn((RwtViewer::all_around(), Transform::default(), GlobalTransform::default()));
//! let trees = ScatterClass::new(LayerDensity::Constant(0.05), Handle::default(), Handle::default());
//! let stumps = ScatterClass::new(LayerDensity::Constant(0.0), Handle::default(), Handle::default());
//! let layer = app.world_mut().spawn(ScatterLayer::new(vec![trees, stumps])).id();
//! let settle = |app: &mut App| {
//!     for _ in 0..500 {
//!         app.update();
//!         let stats = app.world().resource::<RwtStats>();
//!         if stats.live_instances > 0 && stats.pending_tasks == 0 && stats.queued_spawns == 0 {
//!             break;
//!         }
//!         std::thread::sleep(std::time::Duration::from_millis(2));
//!     }
//! };
//! settle(&mut app);
//! // Chop a tree: a stump (class 1) takes its place, now and whenever its chunk comes back.
//! let tree = *app.world_mut().query::<&ScatterInstance>().iter(app.world()).next().unwrap();
//! app.world_mut().write_message(EditInstance::reclass(layer, tree.id, 1));
//! settle(&mut app);
//! let edits = app.world().get::<ScatterEdits>(layer).unwrap();
//! assert_eq!(edits.len(), 1);
//! let now = app.world_mut().query::<&ScatterInstance>().iter(app.world())
//!     .find(|i| i.id == tree.id).copied().unwrap();
//! assert_eq!(now.class, 1);
//! ```
//!
//! ## Names
//!
//! - `Rwt*`: the plugin and its parts, their resources, system sets and the viewer marker
//!   ([`RwtPlugin`], [`RwtSettings`], [`RwtSystems`], [`RwtStats`], [`RwtViewer`]);
//! - `Scatter*`: components and assets that describe a layer and what it places
//!   ([`ScatterLayer`], [`ScatterClass`], [`ScatterInstance`], [`ScatterLayerStatus`],
//!   [`layers::file::ScatterLayerSource`]);
//! - plain names for the values inside them and for messages ([`LayerDensity`],
//!   [`HeightSource`], [`ClassLook`], [`GroundPlane`], [`ViewCone`], [`ChunkLoaded`]).
//!
//! ## Errors
//!
//! A layer whose layer file, density map or heightmap cannot load does not stream; the
//! plugin logs an error naming the layer and the asset, its [`ScatterLayerStatus`] lists
//! what failed, and [`RwtStats::layers_failed`] counts it.
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
//!
//! ## Headless
//!
//! The plugin needs no window or renderer: servers and tests run it on `MinimalPlugins`,
//! and [`RwtStats`] says what streamed.
//!
//! ```
//! use bevy::prelude::*;
//! use bevy_rwt::prelude::*;
//!
//! let mut app = App::new();
//! app.add_plugins((MinimalPlugins, bevy::asset::AssetPlugin::default(), RwtPlugin::default()))
//!     .init_asset::<Mesh>()
//!     .init_asset::<StandardMaterial>();
//! app.finish();
//! app.cleanup();
//! app.world_mut().spawn((RwtViewer::all_around(), Transform::default(), GlobalTransform::default()));
//! let stones = ScatterClass::new(LayerDensity::Constant(0.5), Handle::default(), Handle::default());
//! let grass = ScatterClass::instanced(LayerDensity::Constant(20.0), Handle::default(), InstancedMaterial::default());
//! let streaming = StreamingConfig { chunk_size: 16.0, load_distance: 32.0, unload_distance: 40.0, near_distance: 16.0 };
//! app.world_mut().spawn(ScatterLayer::new(vec![stones, grass]).with_streaming(streaming));
//! // Chunks are generated on the async compute pool: run frames until they have landed.
//! for _ in 0..10_000 {
//!     app.update();
//!     let stats = app.world().resource::<RwtStats>();
//!     if stats.live_instances > 0 && stats.pending_tasks == 0 && stats.queued_spawns == 0 {
//!         break;
//!     }
//!     std::thread::sleep(std::time::Duration::from_millis(1));
//! }
//! let stats = app.world().resource::<RwtStats>();
//! // About 0.5 stones (entities) and 20 blades (instanced, no entities) per square unit.
//! let ratio = stats.live_instanced as f64 / stats.live_instances as f64;
//! assert!((ratio - 40.0).abs() < 4.0, "{stats:?}");
//! ```

#[cfg(feature = "brush")]
pub mod brush;
pub mod diagnostics;
pub mod edits;
mod entities;
pub mod footprints;
pub mod gizmos;
pub mod instancing;
pub mod layers;
pub mod look;
pub mod picking;
mod settings;
pub mod streaming;
pub mod viewers;

use bevy::ecs::schedule::{InternedScheduleLabel, ScheduleLabel};
use bevy::prelude::*;
pub use diagnostics::RwtStats;
pub use instancing::{Bender, InstancedChunk, RwtFadeIn, RwtInstancingPlugin, RwtWind};
pub use layers::{
    AssetStatus, DEFAULT_SCALE_VARIATION, DEFAULT_TILE_SIZE, HeightSource, LayerDensity, Promotion,
    ScatterClass, ScatterInstance, ScatterLayer, ScatterLayerStatus,
};
pub use look::{
    ClassLook, GroundPlane, InstanceInserter, InstancedLook, InstancedMaterial, InstancedShadows,
    MeshLod, Pose,
};
pub use rwt_core;
use rwt_core::tileset::TileSet;
pub use settings::{RwtSettings, RwtSystems};
use std::sync::Arc;
pub use streaming::{ChunkLoaded, ChunkUnloaded, DensityMapPainted};
pub use viewers::{RwtViewer, ViewCone};

/// Everything a game needs.
pub mod prelude {
    #[cfg(feature = "brush")]
    pub use crate::brush::{
        BrushCommand, BrushSystems, BrushTarget, DensityBrush, PaintDab, RwtBrushPlugin,
    };
    pub use crate::edits::{EditInstance, InstanceEdit, ScatterEdits};
    pub use crate::footprints::{Footprint, FootprintShape};
    pub use crate::gizmos::{RwtGizmos, RwtGizmosPlugin};
    pub use crate::layers::file::{NamedAssets, ScatterLayerAsset, ScatterLayerSource};
    pub use crate::picking::{PickFilter, ScatterHit, ScatterPicking};
    pub use crate::{
        AssetStatus, Bender, ChunkLoaded, ChunkUnloaded, ClassLook, DensityMapPainted, GroundPlane,
        HeightSource, InstancedChunk, InstancedMaterial, InstancedShadows, LayerDensity, RwtFadeIn,
        RwtPlugin, RwtSettings, RwtStats, RwtSystems, RwtViewer, RwtWind, ScatterClass,
        ScatterInstance, ScatterLayer, ScatterLayerStatus, ViewCone,
    };
    pub use rwt_core::streaming::{Falloff, StreamingConfig};
}

/// The plugin: viewers, layers, streaming and diagnostics. Builder-style settings.
pub struct RwtPlugin {
    settings: RwtSettings,
    schedule: InternedScheduleLabel,
    tile_set: Option<Arc<TileSet>>,
}

impl Default for RwtPlugin {
    fn default() -> Self {
        Self {
            settings: RwtSettings::default(),
            schedule: Update.intern(),
            tile_set: None,
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

    /// Most instances of instanced classes handed to their chunk entities per frame.
    pub fn with_upload_budget(mut self, n: usize) -> Self {
        self.settings.upload_budget = n;
        self
    }

    /// Most generation tasks in flight per layer.
    pub fn with_max_tasks(mut self, n: usize) -> Self {
        self.settings.max_tasks_in_flight = n.max(1);
        self
    }

    /// Samples this tile set instead of the shipped one (e.g. one built with `rwt tileset
    /// build` and loaded with [`TileSet::from_ron_bytes`]).
    pub fn with_tile_set(mut self, set: TileSet) -> Self {
        self.tile_set = Some(Arc::new(set));
        self
    }
}

impl Plugin for RwtPlugin {
    fn build(&self, app: &mut App) {
        let schedule = self.schedule;
        app.insert_resource(self.settings.clone()).configure_sets(
            schedule,
            (
                RwtSystems::Viewers,
                RwtSystems::Plan,
                RwtSystems::Collect,
                RwtSystems::Apply,
                RwtSystems::Stats,
            )
                .chain(),
        );
        let tile_set = self
            .tile_set
            .clone()
            .unwrap_or_else(|| Arc::new(TileSet::embedded()));
        app.add_plugins((
            viewers::RwtViewersPlugin { schedule },
            layers::RwtLayersPlugin { schedule },
            streaming::RwtStreamingPlugin { schedule, tile_set },
            diagnostics::RwtDiagnosticsPlugin { schedule },
            instancing::RwtInstancingPlugin { schedule },
        ));
    }
}
