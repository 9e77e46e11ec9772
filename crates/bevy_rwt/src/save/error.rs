//! Why a map could not be used, and why a save or a load failed.

use crate::layers::file::LayerFileError;
use bevy::prelude::*;
use bevy::render::render_resource::TextureFormat;
use std::path::PathBuf;

/// Why a named map's texels could not be read or written.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum MapProblem {
    /// The layer entity has no `ScatterLayer`, or no such class.
    #[error("no such layer or class")]
    NoLayer,
    /// The class's density is not a [`crate::LayerDensity::Image`].
    #[error("its density is not an image map")]
    NotAnImage,
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

impl MapProblem {
    /// Why `image`'s texels could not be used: not loaded, or not on the CPU.
    pub(crate) fn of(image: Option<&Image>) -> Self {
        image.map_or(Self::NotLoaded, |image| Self::NotOnCpu {
            format: image.texture_descriptor.format,
        })
    }

    /// The error for the map called `map`.
    pub(crate) fn at(self, map: &str) -> MapError {
        MapError {
            map: map.to_string(),
            problem: self,
        }
    }
}

/// A named map ([`super::NamedMap`]) that could not be painted, saved or loaded into.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("map {map}: {problem}")]
pub struct MapError {
    /// The map's name.
    pub map: String,
    /// Why.
    pub problem: MapProblem,
}

/// Why a [`super::SaveWorld`] or a [`super::LoadWorld`] failed. A failed save leaves the
/// previous one as it was; a failed load changes nothing.
#[derive(Debug, thiserror::Error)]
pub enum SaveError {
    /// A map could not be read (to save it) or written (to load into it).
    #[error(transparent)]
    Map(#[from] MapError),
    /// A file could not be read or written.
    #[error(transparent)]
    File(#[from] rwt_core::files::FileError),
    /// The index or a layer file of a save is not valid.
    #[error("{}: {error}", file.display())]
    Parse {
        /// The file.
        file: PathBuf,
        /// What is wrong with it (boxed: parser errors are large).
        error: Box<SaveTextError>,
    },
    /// The save is of a format this library does not read (a newer one).
    #[error("{}: save format {found} is not supported (this library reads 1 to {supported})", file.display())]
    Format {
        /// The index file.
        file: PathBuf,
        /// Its format.
        found: u32,
        /// The newest format read here.
        supported: u32,
    },
    /// A saved map is not an image of at most its map's size.
    #[error("{}: {error}", file.display())]
    Decode {
        /// The file.
        file: PathBuf,
        /// Why.
        error: rwt_core::density::ImageDensityError,
    },
    /// A saved map's size is not its map's.
    #[error("{}: {}x{} map, the world's is {}x{}", file.display(), found.0, found.1, expected.0, expected.1)]
    MapSize {
        /// The file.
        file: PathBuf,
        /// Its size.
        found: (u32, u32),
        /// The map's size in the world.
        expected: (u32, u32),
    },
    /// A map could not be encoded as PNG.
    #[error("map {map}: cannot encode it: {error}")]
    Encode {
        /// The map's name.
        map: String,
        /// The encoder's error.
        error: image::ImageError,
    },
    /// A saved edits file is damaged, cut short, or made for another point set.
    #[error("{}: {error}", file.display())]
    Edits {
        /// The file.
        file: PathBuf,
        /// Why.
        error: rwt_core::edits::EditsError,
    },
    /// Two layers have one name: their edits could not be told apart when loaded.
    #[error("two scatter layers are named {name:?}: names identify edits in a save")]
    DuplicateLayer {
        /// The name.
        name: String,
    },
    /// Two maps have one name: they could not be told apart when loaded.
    #[error("two maps are named {name:?}: names identify maps in a save")]
    DuplicateMap {
        /// The name.
        name: String,
    },
    /// The index names a file outside its folder.
    #[error("the index names {file:?}, outside its folder")]
    OutsideFolder {
        /// The name.
        file: String,
    },
    /// The maps and edits were saved, but these layers have no layer file: they use
    /// something a layer file cannot name (see [`crate::layers::file::NamedAssets`]).
    #[error("saved; no layer file for {}", join(layers))]
    LayerNotSaved {
        /// The layers, and why each has no file.
        layers: Vec<UnsavedLayer>,
    },
    /// No tile set to name the edits by: [`crate::RwtStreamingPlugin`] is not in the app.
    #[error("nothing streams: the app has no RwtStreamingPlugin")]
    NotStreaming,
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
