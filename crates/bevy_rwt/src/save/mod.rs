//! Saving a world: what the player changed — chopped trees, cleared ground, painted
//! density maps — written to a folder as one transaction and read back into a running game.
//!
//! Send [`SaveWorld`] or [`LoadWorld`]; [`RwtSavePlugin`] answers each with [`WorldSaved`]
//! or [`WorldLoaded`], which carry a typed [`SaveError`] when it failed. A save holds
//! - the per-instance edits ([`crate::edits::ScatterEdits`]) of every layer that has a
//!   `Name` (names tie a save to the layers of the game that loads it);
//! - the density maps it names ([`NamedMap`]) as 16-bit grey PNGs, and, if asked, the layer
//!   file of each of their layers (reading the maps from beside it): a painted world another
//!   game loads as assets;
//! - an index, [`PaintedMaps`] (`painted.ron`), of where each lies.
//!
//! Every file is staged and synced, then all are renamed into place together
//! ([`rwt_core::files::SaveTransaction`]): a full disk, an unreadable map or a crash leaves
//! the previous save complete. A load reads and checks every file first and changes the
//! world only when all of it is good. The density brush ([`crate::brush`], feature `brush`)
//! saves and loads through this module; a game without it saves the same way.
//!
//! ```
//! use bevy::prelude::*;
//! use bevy_rwt::edits::{EditInstance, ScatterEdits};
//! use bevy_rwt::prelude::*;
//! use bevy_rwt::save::{LoadWorld, SaveWorld, WorldLoaded, WorldSaved};
//!
//! let mut app = App::new();
//! app.add_plugins((MinimalPlugins, bevy::asset::AssetPlugin::default(), RwtPlugins::default()))
//!     .init_asset::<Mesh>()
//!     .init_asset::<StandardMaterial>();
//! app.finish();
//! app.cleanup();
//! let trees = ScatterClass::new(LayerDensity::Constant(0.05), Handle::default(), Handle::default());
//! let forest = app.world_mut().spawn((Name::new("forest"), ScatterLayer::new(vec![trees]))).id();
//! app.world_mut().spawn((RwtViewer::all_around(), Transform::default(), GlobalTransform::default()));
//! assert!(bevy_rwt::testing::settle(&mut app, 10_000));
//! // The player chops a tree.
//! let tree = app.world_mut().query::<&ScatterEntity>().iter(app.world()).next().unwrap().id;
//! app.world_mut().write_message(EditInstance::remove(forest, tree));
//! app.update();
//! let dir = std::env::temp_dir().join(format!("rwt-save-doc-{}", std::process::id()));
//! app.world_mut().write_message(SaveWorld::to(&dir));
//! app.update();
//! let saved = app.world_mut().resource_mut::<Messages<WorldSaved>>().drain().last().unwrap();
//! assert_eq!(saved.result.unwrap().edits, 1);
//! // Later, or in another session of the game: the tree stays chopped.
//! app.world_mut().entity_mut(forest).insert(ScatterEdits::default());
//! app.world_mut().write_message(LoadWorld::from(&dir));
//! app.update();
//! let loaded = app.world_mut().resource_mut::<Messages<WorldLoaded>>().drain().last().unwrap();
//! assert_eq!(loaded.result.unwrap().edits, 1);
//! # std::fs::remove_dir_all(&dir).unwrap();
//! ```

mod error;
mod files;
mod plugin;

pub use error::{MapError, MapProblem, SaveError, SaveTextError, UnsavedLayer};
pub use files::{INDEX_FILE, PaintedMapEntry, PaintedMaps, SAVE_FORMAT, SavedEdits};
pub use plugin::{RwtSavePlugin, SaveSystems};

use crate::layers::{GroundMap, LayerDensity, ScatterLayer};
use bevy::prelude::*;
use std::fmt;
use std::path::{Path, PathBuf};

/// A class's density map, by name: the class `class` of the layer on `layer`, its density a
/// [`LayerDensity::Image`]. The name identifies the map in a save (its file name) and in a
/// HUD; the brush paints the maps it names ([`crate::brush::DensityBrush::targets`]).
#[derive(Clone, Debug, PartialEq, Reflect)]
#[reflect(Clone, Debug, PartialEq)]
pub struct NamedMap {
    /// The layer entity.
    pub layer: Entity,
    /// The class index in the layer.
    pub class: usize,
    /// The map's name.
    pub name: String,
}

impl NamedMap {
    /// The map of class `class` of `layer`, called `name`.
    pub fn new(layer: Entity, class: usize, name: impl Into<String>) -> Self {
        Self {
            layer,
            class,
            name: name.into(),
        }
    }

    /// The map, if the layer has the class and its density is an image map.
    pub(crate) fn ground_map(&self, layers: &Query<&ScatterLayer>) -> Result<GroundMap, MapError> {
        let density = layers
            .get(self.layer)
            .ok()
            .and_then(|l| l.classes.get(self.class))
            .map(|c| &c.density)
            .ok_or_else(|| MapProblem::NoLayer.at(&self.name))?;
        match density {
            LayerDensity::Image(map) => Ok(map.clone()),
            _ => Err(MapProblem::NotAnImage.at(&self.name)),
        }
    }
}

/// Saves the world to a folder: the edits of every named layer, the maps named here and
/// (with `layer_files`) their layers' files. Answered by [`WorldSaved`].
#[derive(Message, Clone, Debug, PartialEq, Reflect)]
#[reflect(Clone, Debug, PartialEq)]
pub struct SaveWorld {
    /// The folder (made if missing; a previous save there is replaced as a whole).
    pub dir: PathBuf,
    /// The density maps to save.
    pub maps: Vec<NamedMap>,
    /// Whether the layer file of each map's layer is written beside the maps (turn it off
    /// for layers a file cannot describe, e.g. classes made of sprites in code).
    pub layer_files: bool,
}

impl SaveWorld {
    /// Saves the edits to `dir` (no maps).
    pub fn to(dir: impl AsRef<Path>) -> Self {
        Self {
            dir: dir.as_ref().to_path_buf(),
            maps: Vec::new(),
            layer_files: true,
        }
    }

    /// Also saves these maps.
    pub fn with_maps(mut self, maps: impl IntoIterator<Item = NamedMap>) -> Self {
        self.maps.extend(maps);
        self
    }
}

/// Loads a folder written by [`SaveWorld`]: the edits of the layers named in it, and its
/// maps into the maps of the same names here. Every file is read and checked first: a
/// missing, corrupt or mismatched one is an error naming it, and then nothing changes.
/// Answered by [`WorldLoaded`].
#[derive(Message, Clone, Debug, PartialEq, Reflect)]
#[reflect(Clone, Debug, PartialEq)]
pub struct LoadWorld {
    /// The folder.
    pub dir: PathBuf,
    /// The maps to read into (by name; the save's other maps are left alone).
    pub maps: Vec<NamedMap>,
}

impl LoadWorld {
    /// Loads the edits from `dir` (no maps).
    pub fn from(dir: impl AsRef<Path>) -> Self {
        Self {
            dir: dir.as_ref().to_path_buf(),
            maps: Vec::new(),
        }
    }

    /// Also reads into these maps.
    pub fn with_maps(mut self, maps: impl IntoIterator<Item = NamedMap>) -> Self {
        self.maps.extend(maps);
        self
    }
}

/// What a [`SaveWorld`] came to.
#[derive(Message, Debug)]
pub struct WorldSaved {
    /// The folder.
    pub dir: PathBuf,
    /// What was saved, or why nothing was (or, [`SaveError::LayerNotSaved`], what was not).
    pub result: Result<SaveSummary, SaveError>,
}

/// What a [`LoadWorld`] came to.
#[derive(Message, Debug)]
pub struct WorldLoaded {
    /// The folder.
    pub dir: PathBuf,
    /// What was loaded, or why nothing was.
    pub result: Result<LoadSummary, SaveError>,
}

/// What a save wrote.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct SaveSummary {
    /// Density maps.
    pub maps: usize,
    /// Layer files.
    pub layer_files: usize,
    /// Edits, over all layers.
    pub edits: usize,
}

impl fmt::Display for SaveSummary {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        write!(
            f,
            "saved {} maps, {} layer files and {} edits",
            self.maps, self.layer_files, self.edits
        )
    }
}

/// What a load read into the world.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct LoadSummary {
    /// Density maps.
    pub maps: usize,
    /// Edits, over all layers.
    pub edits: usize,
}

impl fmt::Display for LoadSummary {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        write!(f, "loaded {} maps and {} edits", self.maps, self.edits)
    }
}
