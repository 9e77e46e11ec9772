//! # bevy_rwt: blue-noise vegetation streamed around your cameras
//!
//! Add [`RwtPlugins`], mark cameras with [`RwtViewer`], and spawn [`ScatterLayer`]s. Each
//! layer places instances of its classes on the ground (x, z) with recursive Wang tile blue
//! noise ([`rwt_core`]): chunks around the viewers are generated on the async compute pool,
//! instances are spawned and despawned within a per-frame budget and share their classes'
//! mesh and material handles (Bevy batches them), painted density maps re-query only the
//! chunks they cover, and level of detail by density only ever adds instances between the
//! existing ones as a viewer approaches.
//!
//! ## How it is built
//!
//! [`RwtPlugins`] is a group of small plugins, each registering its own systems in one of
//! the [`RwtSystems`] sets (in order: `Viewers`, `Plan`, `Collect`, `Apply`, `Stats`) of
//! one schedule; each can be disabled or used alone (see [`RwtPlugins`]):
//!
//! | plugin | module | does |
//! |---|---|---|
//! | [`viewers::RwtViewersPlugin`] | [`viewers`] | lays every [`RwtViewer`] on the ground |
//! | [`layers::RwtLayersPlugin`] | [`layers`] | layer files (`*.layer.ron`) and asset status |
//! | [`streaming::RwtStreamingPlugin`] | [`streaming`] | chunks, generation tasks, budgeted spawns, repainting |
//! | [`diagnostics::RwtDiagnosticsPlugin`] | [`diagnostics`] | [`RwtStats`] and `rwt/` diagnostics |
//! | [`instancing::RwtInstancingPlugin`] | [`instancing`] | instanced classes: mesh checks, one instanced draw per chunk (wind, fade-in) |
//! | [`gizmos::RwtGizmosPlugin`] (disabled) | [`gizmos`] | chunk and tile outlines |
//! | `brush::RwtBrushPlugin` (disabled; feature `brush`) | `brush` | paints density maps; saves and loads them with the edits |
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
//! app.add_plugins((MinimalPlugins, bevy::asset::AssetPlugin::default(), RwtPlugins::default()));
//! app.finish();
//! app.cleanup();
//! app.world_mut().spawn((RwtViewer::all_around(), Transform::default(), GlobalTransform::default()));
//! let trees = ScatterClass::new(LayerDensity::Constant(0.05), Handle::default(), Handle::default());
//! let stumps = ScatterClass::new(LayerDensity::Constant(0.0), Handle::default(), Handle::default());
//! let layer = app.world_mut().spawn(ScatterLayer::new(vec![trees, stumps])).id();
//! // Runs frames until the chunks have streamed (see `bevy_rwt::testing`, feature `testing`).
//! let settle = |app: &mut App| assert!(bevy_rwt::testing::settle(app, 2_000));
//! settle(&mut app);
//! // Chop a tree: a stump (class 1) takes its place, now and whenever its chunk comes back.
//! let tree = *app.world_mut().query::<&ScatterEntity>().iter(app.world()).next().unwrap();
//! app.world_mut().write_message(EditInstance::reclass(layer, tree.id, 1));
//! settle(&mut app);
//! let edits = app.world().get::<ScatterEdits>(layer).unwrap();
//! assert_eq!(edits.len(), 1);
//! let now = app.world_mut().query::<&ScatterEntity>().iter(app.world())
//!     .find(|i| i.id == tree.id).copied().unwrap();
//! assert_eq!(now.class, 1);
//! ```
//!
//! ## Tuning live, and saving scenes
//!
//! Every component, resource and message derives `Reflect` and is registered, so an
//! inspector (`bevy-inspector-egui`'s `WorldInspectorPlugin`) shows and edits layers,
//! classes, settings, statistics and viewers, and Bevy scenes can hold them. A layer edited
//! in place (its seed, tile size, streaming distances, fall-off, densities, instanced
//! shading) streams anew with its new settings. Code is not data: custom densities, height
//! functions and inserters are skipped by reflection.
//!
//! ## Names
//!
//! - `Rwt*`: the plugin and its parts, their resources, system sets and the viewer marker
//!   ([`RwtPlugins`], [`RwtSettings`], [`RwtSystems`], [`RwtStats`], [`RwtViewer`]);
//! - `Scatter*`: components and assets that describe a layer and what it places
//!   ([`ScatterLayer`], [`ScatterClass`], [`ScatterEntity`]: an instance that is an entity,
//!   [`ScatterLayerStatus`], [`layers::file::ScatterLayerSource`]); instances of instanced
//!   classes live in chunk buffers and are counted apart (`live_entities` beside
//!   `live_instanced`);
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
//!     .add_plugins((DefaultPlugins, RwtPlugins::default().with_spawn_budget(4_000)))
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
//! app.add_plugins((MinimalPlugins, bevy::asset::AssetPlugin::default(), RwtPlugins::default()))
//!     .init_asset::<Mesh>()
//!     .init_asset::<StandardMaterial>();
//! app.finish();
//! app.cleanup();
//! app.world_mut().spawn((RwtViewer::all_around(), Transform::default(), GlobalTransform::default()));
//! let stones = ScatterClass::new(LayerDensity::Constant(0.5), Handle::default(), Handle::default());
//! let grass = ScatterClass::instanced(LayerDensity::Constant(20.0), Handle::default(), InstancedShading::default());
//! let streaming = StreamingConfig { chunk_size: 16.0, load_distance: 32.0, unload_distance: 40.0, near_distance: 16.0 };
//! app.world_mut().spawn(ScatterLayer::new(vec![stones, grass]).with_streaming(streaming));
//! // Chunks are generated on the async compute pool: run frames until they have landed.
//! assert!(bevy_rwt::testing::settle(&mut app, 10_000));
//! let stats = app.world().resource::<RwtStats>();
//! // About 0.5 stones (entities) and 20 blades (instanced, no entities) per square unit.
//! let ratio = stats.live_instanced as f64 / stats.live_entities as f64;
//! assert!((ratio - 40.0).abs() < 4.0, "{stats:?}");
//! ```

#[cfg(feature = "brush")]
pub mod brush;
pub mod diagnostics;
pub mod edits;
mod entities;
pub mod footprints;
pub mod gizmos;
pub mod ground;
pub mod impostor;
pub mod instancing;
pub mod layers;
pub mod look;
pub mod picking;
pub mod save;
mod settings;
pub mod streaming;
#[cfg(feature = "testing")]
pub mod testing;
pub mod viewers;

use bevy::app::PluginGroupBuilder;
use bevy::ecs::schedule::{InternedScheduleLabel, ScheduleLabel};
use bevy::prelude::*;
pub use diagnostics::{RwtDiagnosticsPlugin, RwtStats};
pub use instancing::{
    Bender, CascadeCasters, InstanceCulling, InstancedChunk, RwtFadeIn, RwtInstancingPlugin,
    RwtWind,
};
pub use layers::RwtLayersPlugin;
pub use layers::{
    AssetFailure, AssetProblem, AssetStatus, DEFAULT_SCALE_VARIATION, DEFAULT_TILE_SIZE, GroundMap,
    HeightSource, KeepOut, LayerAsset, LayerDensity, LayerRef, Promotion, ScatterClass,
    ScatterEntity, ScatterLayer, ScatterLayerStatus,
};
pub use look::{
    ClassLook, Footing, GroundPlane, Impostor, InstanceInserter, InstancedLook, InstancedShading,
    InstancedShadows, InstancedThinning, MeshLod, Pose, Stance,
};
pub use rwt_core;
use rwt_core::tileset::TileSet;
pub use settings::{RwtSettings, RwtSystems};
use std::sync::Arc;
pub use streaming::RwtStreamingPlugin;
pub use streaming::{ChunkLoaded, ChunkUnloaded, DensityMapPainted, RwtTileSet};
pub use viewers::{RwtViewer, RwtViewersPlugin, ViewCone};

/// Everything a game needs.
pub mod prelude {
    #[cfg(feature = "brush")]
    pub use crate::brush::{
        BrushCommand, BrushOutcome, BrushSystems, DensityBrush, PaintDab, RwtBrushPlugin,
    };
    pub use crate::edits::{EditInstance, InstanceEdit, ScatterEdits};
    pub use crate::footprints::{Footprint, FootprintShape};
    pub use crate::gizmos::{RwtGizmos, RwtGizmosPlugin};
    pub use crate::ground::{ScatterSurface, SurfacePolicy};
    pub use crate::layers::file::{NamedAssets, ScatterLayerAsset, ScatterLayerSource};
    pub use crate::picking::{PickFilter, ScatterHit, ScatterPicking};
    pub use crate::save::{LoadWorld, NamedMap, RwtSavePlugin, SaveWorld, WorldLoaded, WorldSaved};
    pub use crate::{
        AssetStatus, Bender, CascadeCasters, ChunkLoaded, ChunkUnloaded, ClassLook,
        DensityMapPainted, GroundMap, GroundPlane, HeightSource, Impostor, InstanceCulling,
        InstancedChunk, InstancedShading, InstancedShadows, InstancedThinning, LayerDensity,
        RwtDiagnosticsPlugin, RwtFadeIn, RwtInstancingPlugin, RwtLayersPlugin, RwtPlugins,
        RwtSettings, RwtStats, RwtStreamingPlugin, RwtSystems, RwtViewer, RwtViewersPlugin,
        RwtWind, ScatterClass, ScatterEntity, ScatterLayer, ScatterLayerStatus, ViewCone,
    };
    pub use rwt_core::Lattice;
    pub use rwt_core::streaming::{Falloff, StreamingConfig};
}

/// The plugin group: viewers, layers, streaming, diagnostics and instancing, all in one
/// schedule (`Update` by default, or the one given to [`RwtPlugins::new`]); builder-style
/// settings. The brush (feature `brush`) and the gizmos are in the group but disabled: enable
/// them with [`PluginGroupBuilder::enable`].
///
/// Each part can be disabled (`.build().disable::<RwtDiagnosticsPlugin>()`) or used alone,
/// built with the schedule of its systems (`RwtStreamingPlugin::new(FixedUpdate)`).
///
/// | part | without it |
/// |---|---|
/// | [`viewers::RwtViewersPlugin`] | nothing streams |
/// | [`layers::RwtLayersPlugin`] | layer files do not load (layers made in code stream) |
/// | [`streaming::RwtStreamingPlugin`] | nothing is placed |
/// | [`diagnostics::RwtDiagnosticsPlugin`] | no [`RwtStats`], no `rwt/` diagnostics |
/// | [`instancing::RwtInstancingPlugin`] | instanced classes stream and are counted, not drawn |
/// | [`save::RwtSavePlugin`] | no world saves (the brush adds it back) |
/// | [`gizmos::RwtGizmosPlugin`] (disabled) | no chunk and tile outlines |
/// | `brush::RwtBrushPlugin` (disabled; feature `brush`) | no painting |
///
/// ```
/// use bevy::prelude::*;
/// use bevy_rwt::prelude::*;
///
/// let mut app = App::new();
/// app.add_plugins((MinimalPlugins, bevy::asset::AssetPlugin::default()))
///     .add_plugins(
///         RwtPlugins::new(FixedUpdate)
///             .with_spawn_budget(2_000)
///             .build()
///             .disable::<RwtDiagnosticsPlugin>(),
///     );
/// assert!(!app.world().contains_resource::<RwtStats>());
/// assert_eq!(app.world().resource::<RwtSettings>().spawn_budget, 2_000);
/// ```
pub struct RwtPlugins {
    settings: RwtSettings,
    schedule: InternedScheduleLabel,
    tile_set: Option<Arc<TileSet>>,
}

impl Default for RwtPlugins {
    fn default() -> Self {
        Self::new(Update)
    }
}

impl RwtPlugins {
    /// The group, every part's systems in `schedule`.
    pub fn new(schedule: impl ScheduleLabel) -> Self {
        Self {
            settings: RwtSettings::default(),
            schedule: schedule.intern(),
            tile_set: None,
        }
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

impl PluginGroup for RwtPlugins {
    fn build(self) -> PluginGroupBuilder {
        let schedule = self.schedule;
        let mut streaming = streaming::RwtStreamingPlugin::new(schedule);
        if let Some(set) = self.tile_set {
            streaming = streaming.with_tile_set(set);
        }
        let group = PluginGroupBuilder::start::<Self>()
            .add(RwtSettingsPlugin(self.settings))
            .add(viewers::RwtViewersPlugin::new(schedule))
            .add(layers::RwtLayersPlugin::new(schedule))
            .add(streaming)
            .add(diagnostics::RwtDiagnosticsPlugin::new(schedule))
            .add(instancing::RwtInstancingPlugin::new(schedule))
            .add(save::RwtSavePlugin::new(schedule))
            .add(gizmos::RwtGizmosPlugin)
            .disable::<gizmos::RwtGizmosPlugin>();
        #[cfg(feature = "brush")]
        let group = group
            .add(brush::RwtBrushPlugin::new(schedule))
            .disable::<brush::RwtBrushPlugin>();
        group
    }
}

/// Inserts the group's [`RwtSettings`] (part of [`RwtPlugins`]; parts used alone get the
/// defaults, or the resource the app inserts).
pub struct RwtSettingsPlugin(pub RwtSettings);

impl Plugin for RwtSettingsPlugin {
    fn build(&self, app: &mut App) {
        app.insert_resource(self.0.clone());
    }
}

/// The README's examples, compiled and run as doctests (`cargo test --doc`).
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
pub struct ReadmeDoctests;
