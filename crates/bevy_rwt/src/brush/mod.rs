//! The density brush: paint the maps a layer streams from, in the running game.
//!
//! [`RwtBrushPlugin`] turns the cursor into a brush on the ground: it casts the cursor's ray
//! against the selected layer's [`crate::HeightSource`], paints into (left button) or erases
//! from (right button) the selected class's density map, and tells the plugin which region
//! changed ([`crate::DensityMapPainted`]), so only the chunks under the stroke re-scatter.
//! The wheel sets the size, a key the strength, digit keys the class; recent strokes can be
//! undone; the maps save to PNG files, with the layer files that read them and a RON index,
//! and load again, in this game or another one. A gizmo circle shows the brush when Bevy's
//! gizmos are there.
//!
//! Everything the mouse does is also a message, for scripts, tools and tests:
//! [`PaintDab`] paints one dab, [`BrushCommand`] undoes, saves and loads.
//!
//! ```no_run
//! use bevy::prelude::*;
//! use bevy_rwt::brush::{DensityBrush, RwtBrushPlugin};
//! use bevy_rwt::save::NamedMap;
//! use bevy_rwt::prelude::*;
//!
//! fn setup(mut commands: Commands, mut images: ResMut<Assets<Image>>, mut brush: ResMut<DensityBrush>) {
//!     // A blank 512 x 512 map over 512 x 512 m: flowers grow where it is painted.
//!     let map = bevy_rwt::brush::blank_map(&mut images, 512, Rect::from_center_size(Vec2::ZERO, Vec2::splat(512.0)), 4.0);
//!     let density = LayerDensity::Image(map);
//!     let flowers = commands.spawn((
//!         Name::new("flowers"),
//!         ScatterLayer::new(vec![ScatterClass::instanced(density, Handle::default(), InstancedShading::default())]),
//!     )).id();
//!     brush.targets.push(NamedMap::new(flowers, 0, "flowers"));
//!     brush.enabled = true;
//! }
//!
//! App::new()
//!     .add_plugins((DefaultPlugins, RwtPlugins::default().build().enable::<RwtBrushPlugin>()))
//!     .add_systems(Startup, setup)
//!     .run();
//! ```
//!
//! A script paints without a mouse (here headless):
//!
//! ```
//! use bevy::prelude::*;
//! use bevy_rwt::brush::{DensityBrush, RwtBrushPlugin};
//! use bevy_rwt::save::NamedMap;
//! use bevy_rwt::prelude::*;
//!
//! let mut app = App::new();
//! app.add_plugins((MinimalPlugins, bevy::asset::AssetPlugin::default(), RwtPlugins::default().build().enable::<RwtBrushPlugin>()))
//!     .init_asset::<Mesh>()
//!     .init_asset::<StandardMaterial>();
//! app.finish();
//! app.cleanup();
//! let mut images = app.world_mut().resource_mut::<Assets<Image>>();
//! let map = bevy_rwt::brush::blank_map(&mut images, 64, Rect::from_center_size(Vec2::ZERO, Vec2::splat(64.0)), 2.0);
//! let density = LayerDensity::Image(map);
//! let class = ScatterClass::new(density, Handle::default(), Handle::default());
//! let layer = app.world_mut().spawn(ScatterLayer::new(vec![class])).id();
//! app.world_mut().spawn((RwtViewer::all_around(), Transform::default(), GlobalTransform::default()));
//! app.world_mut().resource_mut::<DensityBrush>().targets.push(NamedMap::new(layer, 0, "meadow"));
//! // One dab of 5 m at full strength: about 2 instances per square metre within it.
//! app.world_mut().write_message(PaintDab { target: 0, centre: Vec2::ZERO, radius: 5.0, amount: 1.0 });
//! assert!(bevy_rwt::testing::settle(&mut app, 10_000));
//! let live = app.world().resource::<RwtStats>().live_entities;
//! assert!((20..200).contains(&live), "{live}");
//! ```

mod paint;
mod plugin;
mod ray;

pub use paint::blank_map;
pub use plugin::RwtBrushPlugin;
pub use ray::ground_hit;

use crate::save::{MapError, NamedMap};
use bevy::prelude::*;
use std::path::PathBuf;

/// The brush's systems (cursor, input, dabs, commands), in `Update` before
/// [`crate::save::SaveSystems`] and [`crate::RwtSystems::Viewers`]; a script that places the
/// brush itself runs after them.
#[derive(SystemSet, Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct BrushSystems;

/// The keys and buttons of the brush (`None` turns one off).
#[derive(Clone, Debug, Reflect)]
#[reflect(Clone, Debug)]
pub struct BrushKeys {
    /// Turns the brush on and off.
    pub toggle: Option<KeyCode>,
    /// Paints while held.
    pub paint: MouseButton,
    /// Erases while held.
    pub erase: MouseButton,
    /// Cycles through [`DensityBrush::STRENGTHS`].
    pub strength: Option<KeyCode>,
    /// Undoes the last stroke.
    pub undo: Option<KeyCode>,
    /// Saves the maps to [`DensityBrush::save_dir`].
    pub save: Option<KeyCode>,
    /// Loads the maps from [`DensityBrush::save_dir`].
    pub load: Option<KeyCode>,
    /// Whether the wheel sets the size, and digits 1-9 select the target.
    pub wheel_and_digits: bool,
}

impl Default for BrushKeys {
    fn default() -> Self {
        Self {
            toggle: Some(KeyCode::KeyB),
            paint: MouseButton::Left,
            erase: MouseButton::Right,
            strength: Some(KeyCode::KeyT),
            undo: Some(KeyCode::KeyZ),
            save: Some(KeyCode::F5),
            load: Some(KeyCode::F9),
            wheel_and_digits: true,
        }
    }
}

/// The brush's settings and state.
#[derive(Resource, Debug, Reflect)]
#[reflect(Resource, Debug)]
pub struct DensityBrush {
    /// Whether the cursor paints (the mouse is the game's otherwise).
    pub enabled: bool,
    /// The maps it can paint (each a class whose density is a [`crate::LayerDensity::Image`]).
    pub targets: Vec<NamedMap>,
    /// Index of the selected target.
    pub selected: usize,
    /// Radius in world units.
    pub radius: f32,
    /// Smallest and largest radius the wheel reaches.
    pub radius_range: (f32, f32),
    /// Map value added per second at the brush centre (erasing removes as much).
    pub strength: f32,
    /// Strokes kept for undo.
    pub undo_depth: usize,
    /// Where [`BrushCommand::Save`] and [`BrushCommand::Load`] from the keys go.
    pub save_dir: PathBuf,
    /// Whether a save writes the layer file of every target's layer beside its maps (turn
    /// it off for layers a file cannot describe, e.g. classes made of sprites in code: the
    /// maps and the index are saved alone, without an error).
    pub layer_files: bool,
    /// Key bindings.
    pub keys: BrushKeys,
    /// The ground point under the cursor (updated while enabled).
    pub cursor: Option<Vec3>,
    /// Height of the gizmo circle above the ground (above the grass, so that it shows).
    pub circle_lift: f32,
}

impl DensityBrush {
    /// The strengths the strength key cycles through.
    pub const STRENGTHS: [f32; 4] = [0.25, 0.5, 1.0, 2.0];

    /// The selected target.
    pub fn target(&self) -> Option<&NamedMap> {
        self.targets.get(self.selected)
    }
}

impl Default for DensityBrush {
    fn default() -> Self {
        Self {
            enabled: false,
            targets: Vec::new(),
            selected: 0,
            radius: 6.0,
            radius_range: (0.5, 200.0),
            strength: 1.0,
            undo_depth: 32,
            save_dir: PathBuf::from("painted"),
            layer_files: true,
            keys: BrushKeys::default(),
            cursor: None,
            circle_lift: 0.8,
        }
    }
}

/// One dab of paint: adds `amount` (negative erases) at `centre` (ground x, z) of target
/// `target`'s map, fading smoothly to nothing at `radius`. Dabs in consecutive frames make
/// one stroke (one undo step).
#[derive(Message, Clone, Copy, Debug, PartialEq, Reflect)]
#[reflect(Clone, Debug, PartialEq)]
pub struct PaintDab {
    /// Index into [`DensityBrush::targets`].
    pub target: usize,
    /// Ground position (x, z).
    pub centre: Vec2,
    /// Radius in world units.
    pub radius: f32,
    /// Map value added at the centre.
    pub amount: f32,
}

/// What the brush can be asked to do besides painting.
#[derive(Message, Clone, Debug, PartialEq, Reflect)]
#[reflect(Clone, Debug, PartialEq)]
pub enum BrushCommand {
    /// Restores the maps as they were before the last stroke. Answered by a
    /// [`BrushOutcome`].
    Undo,
    /// Saves the world with every target's map ([`crate::save::SaveWorld`], with
    /// [`DensityBrush::layer_files`]) to the folder: the maps as PNGs, a layer file
    /// (`*.layer.ron`) per target layer that reads them from beside it, the edits of every
    /// named layer and an index. The folder is a painted world another game loads: put it
    /// in the assets and load the layer files (see [`crate::layers::file`]; what they name
    /// must be in its [`crate::layers::file::NamedAssets`]). Answered by a
    /// [`crate::save::WorldSaved`].
    Save(PathBuf),
    /// Loads a folder written by `Save` ([`crate::save::LoadWorld`], into the targets with
    /// the same names). Answered by a [`crate::save::WorldLoaded`]; strokes before a load
    /// that succeeded cannot be undone.
    Load(PathBuf),
}

/// What a dab or an undo came to (saves and loads answer with
/// [`crate::save::WorldSaved`] and [`crate::save::WorldLoaded`]).
#[derive(Message, Debug)]
pub enum BrushOutcome {
    /// A stroke was undone; `strokes_left` more can be.
    Undone {
        /// Strokes that can still be undone.
        strokes_left: usize,
    },
    /// A dab or an undo failed.
    Failed(BrushError),
}

/// Why the brush could not paint or undo.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum BrushError {
    /// The target index is not in [`DensityBrush::targets`].
    #[error("no brush target {0}")]
    NoTarget(usize),
    /// The target's map cannot be painted.
    #[error(transparent)]
    Map(#[from] MapError),
    /// Nothing to undo.
    #[error("nothing to undo")]
    NothingToUndo,
}
