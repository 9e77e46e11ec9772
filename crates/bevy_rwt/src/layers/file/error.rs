//! What can be wrong with a layer file, or with describing a layer as one.

use bevy::prelude::*;

/// What is wrong with a layer file.
#[derive(Debug, thiserror::Error)]
pub enum LayerFileError {
    /// Not readable.
    #[error("cannot read layer file: {0}")]
    Io(#[from] std::io::Error),
    /// Not UTF-8 text.
    #[error("layer file is not UTF-8 text: {0}")]
    NotText(#[from] std::str::Utf8Error),
    /// Not valid RON for a layer (the error says where).
    #[error("invalid layer file: {0}")]
    Parse(#[from] ron::error::SpannedError),
    /// Valid RON with values out of range.
    #[error("invalid layer: {0}")]
    Invalid(#[from] InvalidLayer),
    /// The description could not be written as RON.
    #[error("cannot write layer file: {0}")]
    Write(#[from] ron::Error),
    /// A layer built in code uses something a layer file cannot name (see
    /// [`LayerDescription::describe`](super::LayerDescription::describe)).
    #[error("cannot describe the layer: {part}: {what}")]
    NotDescribable {
        /// Where in the layer.
        part: LayerPart,
        /// What has no file form.
        what: Undescribable,
    },
    /// The file names a mesh, material or height function
    /// [`NamedAssets`](super::NamedAssets) does not have.
    #[error("layer file names {kind} {name:?}, which is not registered in NamedAssets")]
    UnknownName {
        /// What kind of asset.
        kind: NamedKind,
        /// The name.
        name: String,
    },
    /// The file names a glTF asset, and this build has no glTF loader (the `gltf` feature).
    #[error("class {class} names a glTF asset: build bevy_rwt with its `gltf` feature")]
    NoGltf {
        /// The class's index.
        class: usize,
    },
    /// The file is larger than [`MAX_LAYER_FILE_BYTES`](super::MAX_LAYER_FILE_BYTES): not a
    /// layer description.
    #[error("layer file is larger than {limit} bytes")]
    TooLarge {
        /// The limit in bytes.
        limit: u64,
    },
}

/// A layer file's values out of range.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum InvalidLayer {
    /// A format this library does not read (a newer one).
    #[error("layer file format {found} is not supported (this library reads 1 to {supported})")]
    Format {
        /// The file's format.
        found: u32,
        /// The newest format read here.
        supported: u32,
    },
    /// No class.
    #[error("a layer needs at least one class")]
    NoClasses,
    /// A size or distance that must be positive and finite is not.
    #[error("{field} {value} must be positive")]
    NotPositive {
        /// The field (`tile_size`, `chunk_size`, `load_distance`, `unload_distance`).
        field: &'static str,
        /// Its value.
        value: f64,
    },
    /// The load distance reaches more chunks than streaming allows.
    #[error("load_distance {load_distance} spans more than {limit} chunks of {chunk_size}")]
    TooFar {
        /// The load distance.
        load_distance: f64,
        /// The chunk size.
        chunk_size: f64,
        /// The most chunks a load distance may span
        /// ([`MAX_REACH_CHUNKS`](rwt_core::streaming::MAX_REACH_CHUNKS)).
        limit: f64,
    },
    /// Chunks would unload before they load.
    #[error("unload_distance {unload_distance} is below load_distance {load_distance}")]
    UnloadBelowLoad {
        /// The load distance.
        load_distance: f64,
        /// The unload distance.
        unload_distance: f64,
    },
    /// Clump parameters out of range.
    #[error("clumps: {0}")]
    Clumps(rwt_core::clumps::ClumpError),
    /// A class's far-mesh distance is not positive and finite.
    #[error("class {class}: lod distance {distance} must be positive")]
    LodDistance {
        /// The class's index.
        class: usize,
        /// The distance.
        distance: f32,
    },
    /// A number out of its range.
    #[error("{field} {} must be {rule}", super::numbers::short(*value))]
    Number {
        /// The field, with its class where it has one (`class 1: mesh radius`).
        field: String,
        /// Its value.
        value: f64,
        /// What it must be.
        rule: String,
    },
    /// More classes than a layer may have.
    #[error("{classes} classes, more than {limit}")]
    TooManyClasses {
        /// Classes in the file.
        classes: usize,
        /// The limit ([`MAX_CLASSES`](super::MAX_CLASSES)).
        limit: usize,
    },
    /// A class has neither a mesh and a material nor an asset, or an asset beside a mesh, a
    /// material or a far `lod` (an asset's levels are in its file).
    #[error(
        "class {class}: a class has a mesh and a material, or an asset (without mesh, material or lod)"
    )]
    ClassLook {
        /// The class's index.
        class: usize,
    },
    /// A far material is not `Instanced()` exactly when its class is instanced.
    #[error("class {class}: a far material is Instanced() exactly when the class is instanced")]
    FarMaterial {
        /// The class's index.
        class: usize,
    },
}

/// A part of a layer, where it cannot be described.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LayerPart {
    /// The class of this index.
    Class(usize),
    /// The exclusion map.
    Exclusion,
    /// The ground's height.
    Ground,
}

impl std::fmt::Display for LayerPart {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Class(i) => write!(f, "class {i}"),
            Self::Exclusion => f.write_str("the exclusion"),
            Self::Ground => f.write_str("the ground"),
        }
    }
}

/// What of a layer built in code a layer file cannot name.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum Undescribable {
    /// A look made in code.
    #[error("a custom look (code) has no file form")]
    CustomLook,
    /// An asset class whose glTF file was not loaded from a path.
    #[error("an asset class's glTF file has no asset path")]
    AssetLook,
    /// A density made in code.
    #[error("a custom density (code) has no file form")]
    CustomDensity,
    /// A mesh with neither a name in `NamedAssets` nor an asset path.
    #[error("mesh {0:?} has no asset path and no name")]
    Mesh(AssetId<Mesh>),
    /// A material with neither a name in `NamedAssets` nor an asset path.
    #[error("material {0:?} has no asset path and no name")]
    Material(AssetId<StandardMaterial>),
    /// An image (density map, heightmap, texture) without a path.
    #[error("image {0:?} has no asset path")]
    Image(AssetId<Image>),
    /// A keep-out names another layer by entity, which a file cannot (a `Name` it can).
    #[error("a keep-out names another layer by entity, which a layer file cannot (use a Name)")]
    KeepOut,
    /// A ground made in code ([`HeightSource::Custom`](crate::HeightSource::Custom)).
    #[error("a custom ground (code) has no file form")]
    CustomGround,
    /// A height function without a name in `NamedAssets`.
    #[error("a height function without a name in NamedAssets")]
    HeightFunction,
    /// A promotion whose inserter has no name in `NamedAssets`.
    #[error("a promotion's inserter without a name in NamedAssets")]
    PromotionInserter,
}

/// The kinds of assets a layer file names through `NamedAssets`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum NamedKind {
    /// A mesh.
    Mesh,
    /// A material.
    Material,
    /// A height function.
    Height,
    /// What a promoted instance gets (an [`InstanceInserter`](crate::look::InstanceInserter)).
    Inserter,
}

impl std::fmt::Display for NamedKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Self::Mesh => "mesh",
            Self::Material => "material",
            Self::Height => "height",
            Self::Inserter => "inserter",
        })
    }
}
