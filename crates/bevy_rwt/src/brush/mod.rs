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
//! use bevy_rwt::brush::{BrushTarget, DensityBrush, RwtBrushPlugin};
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
//!     brush.targets.push(BrushTarget::new(flowers, 0, "flowers"));
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
//! use bevy_rwt::brush::{BrushTarget, DensityBrush, RwtBrushPlugin};
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
//! app.world_mut().resource_mut::<DensityBrush>().targets.push(BrushTarget::new(layer, 0, "meadow"));
//! // One dab of 5 m at full strength: about 2 instances per square metre within it.
//! app.world_mut().write_message(PaintDab { target: 0, centre: Vec2::ZERO, radius: 5.0, amount: 1.0 });
//! assert!(bevy_rwt::testing::settle(&mut app, 10_000));
//! let live = app.world().resource::<RwtStats>().live_entities;
//! assert!((20..200).contains(&live), "{live}");
//! ```

mod paint;
mod persist;
mod plugin;
mod ray;

pub use paint::blank_map;
pub use persist::{PaintedMapEntry, PaintedMaps, SavedEdits};
pub use plugin::RwtBrushPlugin;
pub use ray::ground_hit;

use crate::layers::file::LayerFileError;
use bevy::prelude::*;
use bevy::render::render_resource::TextureFormat;
use std::path::PathBuf;

/// The brush's systems (cursor, input, dabs, commands), in `Update` before
/// [`crate::RwtSystems::Viewers`]; a script that places the brush itself runs after them.
#[derive(SystemSet, Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct BrushSystems;

/// A class whose density map the brush paints: the class `class` of the layer on `layer`,
/// shown to the player as `name`. Its density must be a [`crate::LayerDensity::Image`].
#[derive(Clone, Debug, PartialEq, Reflect)]
#[reflect(Clone, Debug, PartialEq)]
pub struct BrushTarget {
    /// The layer entity.
    pub layer: Entity,
    /// The class index in the layer.
    pub class: usize,
    /// Name shown in HUDs, and the file name of its map when saved.
    pub name: String,
}

impl BrushTarget {
    /// The class `class` of `layer`, called `name`.
    pub fn new(layer: Entity, class: usize, name: impl Into<String>) -> Self {
        Self {
            layer,
            class,
            name: name.into(),
        }
    }
}

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
    /// The maps it can paint.
    pub targets: Vec<BrushTarget>,
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
    /// Outcome of the last command or dab that could fail. Reflection does not see it (the
    /// errors hold I/O and parser errors, which are not data).
    #[reflect(ignore)]
    pub last: Option<Result<String, BrushError>>,
}

impl DensityBrush {
    /// The strengths the strength key cycles through.
    pub const STRENGTHS: [f32; 4] = [0.25, 0.5, 1.0, 2.0];

    /// The selected target.
    pub fn target(&self) -> Option<&BrushTarget> {
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
            last: None,
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
    /// Restores the maps as they were before the last stroke.
    Undo,
    /// Writes every target's map as a PNG, a layer file (`*.layer.ron`) per target layer
    /// that reads the maps from beside it, and an index, [`PaintedMaps`], to the folder. The
    /// folder is a painted world another game loads: put it in the assets and load the layer
    /// files (see [`crate::layers::file`]; what they name must be in its
    /// [`crate::layers::file::NamedAssets`]). All or nothing: every file is staged first
    /// and renamed into place together, so a failure (a full disk, an unreadable map)
    /// leaves the previous save complete.
    Save(PathBuf),
    /// Reads maps written by `Save` into the targets with the same names. Every file is
    /// read and checked first: a missing, corrupt or mismatched one is an error naming it,
    /// and then the maps and the undo history stay as they were.
    Load(PathBuf),
}

/// Why a painted map's texels could not be read or written.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum MapAccess {
    /// The image asset is not loaded (or was removed).
    #[error("not loaded")]
    NotLoaded,
    /// Its texels cannot be read or written on the CPU: no CPU copy (the asset kept only on
    /// the GPU), or a format without per-texel colour access.
    #[error("not editable on the CPU (format {format:?})")]
    NotOnCpu {
        /// The image's format.
        format: TextureFormat,
    },
}

impl MapAccess {
    /// Why `image`'s texels could not be used: not loaded, or not on the CPU.
    pub(crate) fn of(image: Option<&Image>) -> Self {
        image.map_or(Self::NotLoaded, |image| Self::NotOnCpu {
            format: image.texture_descriptor.format,
        })
    }

    /// The brush error for target `target`.
    pub(crate) fn at(self, target: &str) -> BrushError {
        BrushError::MapUnavailable {
            target: target.to_string(),
            why: self,
        }
    }
}

/// Why the brush could not do something.
#[derive(Debug, thiserror::Error)]
pub enum BrushError {
    /// The target index is not in [`DensityBrush::targets`].
    #[error("no brush target {0}")]
    NoTarget(usize),
    /// The target's layer entity has no `ScatterLayer`, or no such class.
    #[error("target {target}: no such layer or class")]
    NoLayer {
        /// The target's name.
        target: String,
    },
    /// The target's class density is not a painted map.
    #[error("target {target}: its density is not an image map")]
    NotPaintable {
        /// The target's name.
        target: String,
    },
    /// The target's map cannot be painted, saved or loaded into.
    #[error("target {target}: map {why}")]
    MapUnavailable {
        /// The target's name.
        target: String,
        /// Why.
        why: MapAccess,
    },
    /// Nothing to undo.
    #[error("nothing to undo")]
    NothingToUndo,
    /// A file could not be read or written (a save leaves the previous one as it was).
    #[error(transparent)]
    File(#[from] rwt_core::files::FileError),
    /// The index or a layer file of a save is not valid.
    #[error("{}: {error}", file.display())]
    Parse {
        /// The file.
        file: std::path::PathBuf,
        /// What is wrong with it (boxed: parser errors are large).
        error: Box<SaveTextError>,
    },
    /// A saved map is not an image of at most the target's size.
    #[error("{}: {error}", file.display())]
    Decode {
        /// The file.
        file: std::path::PathBuf,
        /// Why.
        error: rwt_core::density::ImageDensityError,
    },
    /// A saved map's size is not its target's.
    #[error("{}: {}x{} map, the target's is {}x{}", file.display(), found.0, found.1, expected.0, expected.1)]
    MapSize {
        /// The file.
        file: std::path::PathBuf,
        /// Its size.
        found: (u32, u32),
        /// The target map's size.
        expected: (u32, u32),
    },
    /// A map could not be encoded as PNG.
    #[error("target {target}: cannot encode its map: {error}")]
    Encode {
        /// The target.
        target: String,
        /// The encoder's error.
        error: image::ImageError,
    },
    /// A saved edits file is damaged, cut short, or made for another point set.
    #[error("{}: {error}", file.display())]
    Edits {
        /// The file.
        file: std::path::PathBuf,
        /// Why.
        error: rwt_core::edits::EditsError,
    },
    /// Two layers have one name: their edits could not be told apart when loaded.
    #[error("two scatter layers are named {name:?}: names identify edits in a save")]
    DuplicateLayer {
        /// The name.
        name: String,
    },
    /// Two targets have one name: their maps could not be told apart when loaded.
    #[error("two brush targets are named {name:?}: names identify maps in a save")]
    DuplicateTarget {
        /// The name.
        name: String,
    },
    /// The index names a file outside its folder.
    #[error("the index names {file:?}, outside its folder")]
    OutsideFolder {
        /// The name.
        file: String,
    },
    /// The maps were saved, but these layers have no layer file: they use something a
    /// layer file cannot name (see [`crate::layers::file::NamedAssets`]).
    #[error("maps saved; no layer file for {}", join(layers))]
    LayerNotSaved {
        /// The layers, and why each has no file.
        layers: Vec<UnsavedLayer>,
    },
}

/// A layer of a save that has no layer file.
#[derive(Debug, thiserror::Error)]
#[error("{name}: {error}")]
pub struct UnsavedLayer {
    /// The layer's `Name`.
    pub name: String,
    /// Why it cannot be described.
    pub error: LayerFileError,
}

fn join(layers: &[UnsavedLayer]) -> String {
    let each: Vec<String> = layers.iter().map(ToString::to_string).collect();
    each.join("; ")
}

/// Why a text file of a save is not what it should be.
#[derive(Debug, thiserror::Error)]
pub enum SaveTextError {
    /// Not UTF-8 text.
    #[error("not UTF-8 text: {0}")]
    NotText(#[from] std::str::Utf8Error),
    /// The index is not valid RON for one (the error says where).
    #[error("invalid index: {0}")]
    Index(#[from] ron::error::SpannedError),
    /// A layer file is not valid.
    #[error("{0}")]
    Layer(#[from] LayerFileError),
}
