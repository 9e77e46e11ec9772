//! What the plugin reports about each layer: its assets, chunks and instances.

use crate::look::InstancedClassError;
use bevy::asset::{AssetLoadError, AssetPath, UntypedAssetId};
use bevy::platform::collections::HashSet;
use bevy::prelude::*;
use bevy::render::render_resource::TextureFormat;
use rwt_core::streaming::ChunkCoord;
use std::fmt;
use std::sync::Arc;

/// Whether the assets a layer reads (its layer file, density maps, heightmap) are there.
#[derive(Clone, Debug, Default, PartialEq, Reflect)]
#[reflect(Clone, Debug, Default, PartialEq)]
pub enum AssetStatus {
    /// Every asset is loaded: the layer streams.
    #[default]
    Ready,
    /// Waiting for these assets to load.
    Waiting(Vec<LayerAsset>),
    /// These assets cannot be used: the layer shows nothing until they are fixed (a file
    /// watcher reloads them).
    Failed(Vec<AssetFailure>),
}

/// An asset a layer reads: its path, or only its id for an asset made in code.
#[derive(Clone, Debug, PartialEq, Eq, Reflect)]
#[reflect(Clone, Debug, PartialEq)]
pub struct LayerAsset {
    /// The asset.
    pub id: UntypedAssetId,
    /// Where it loads from, when it does.
    pub path: Option<AssetPath<'static>>,
}

impl LayerAsset {
    /// The asset of `handle`.
    pub fn of<A: Asset>(handle: &Handle<A>) -> Self {
        Self {
            id: handle.id().untyped(),
            path: handle.path().cloned(),
        }
    }
}

impl fmt::Display for LayerAsset {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match &self.path {
            Some(path) => write!(f, "{path}"),
            None => write!(f, "{:?}", self.id),
        }
    }
}

/// An asset a layer reads that cannot be used, and why.
#[derive(Clone, Debug, PartialEq, thiserror::Error, Reflect)]
#[reflect(Clone, Debug, PartialEq)]
#[error("{asset}: {why}")]
pub struct AssetFailure {
    /// The asset.
    pub asset: LayerAsset,
    /// Why.
    pub why: AssetProblem,
}

/// Why an asset a layer reads cannot be used.
#[derive(Clone, Debug, PartialEq, thiserror::Error, Reflect)]
#[reflect(Clone, Debug, PartialEq)]
pub enum AssetProblem {
    /// The asset server could not load it.
    #[error("{0}")]
    Load(LoadFailure),
    /// A map image of more pixels than a density may read.
    #[error(
        "{width}x{height} pixels, over the limit of {limit} for a map (rwt_core::density::MAX_IMAGE_PIXELS)"
    )]
    TooLarge {
        /// Its width.
        width: u32,
        /// Its height.
        height: u32,
        /// The limit in pixels.
        limit: u64,
    },
    /// A map image whose pixels cannot be read on the CPU (a compressed format, or kept on
    /// the GPU only).
    #[error("pixels not readable on the CPU (format {format:?})")]
    NotOnCpu {
        /// Its format.
        format: TextureFormat,
    },
}

/// The asset server's error for one failed load. Two are equal when they are the same
/// failure (a reload that fails again is a new one). An opaque value to reflection.
#[derive(Clone, Debug, thiserror::Error, Reflect)]
#[reflect(opaque, Clone, Debug, PartialEq)]
#[error(transparent)]
pub struct LoadFailure(pub Arc<AssetLoadError>);

impl PartialEq for LoadFailure {
    fn eq(&self, other: &Self) -> bool {
        Arc::ptr_eq(&self.0, &other.0)
    }
}

/// The state of a layer, kept up to date by the plugin on every entity with a
/// [`super::ScatterLayer`] or a [`super::file::ScatterLayerSource`]: read it for a HUD, or
/// to tell a player why a layer is empty.
#[derive(Component, Clone, Debug, Default, PartialEq, Reflect)]
#[reflect(Component, Clone, Debug, Default, PartialEq)]
pub struct ScatterLayerStatus {
    /// Its assets.
    pub assets: AssetStatus,
    /// Chunks loaded.
    pub loaded_chunks: HashSet<ChunkCoord>,
    /// Instances of entity classes alive (spawned and not yet despawned): one entity each.
    pub live_entities: usize,
    /// Instances of instanced classes alive (in chunk buffers, no entity each, or
    /// promoted to entities near a viewer).
    pub live_instanced: usize,
    /// Instances of instanced classes promoted to entities (see [`super::Promotion`]).
    pub promoted_instances: usize,
    /// Chunks being generated or waiting to be.
    pub pending_tasks: usize,
    /// Instances waiting for the spawn budget (or, for instanced classes, the upload budget).
    pub queued_spawns: usize,
    /// Loaded chunks not generated because their query would exceed
    /// [`crate::RwtSettings::chunk_point_budget`] (lower the density, or raise the budget).
    pub refused_chunks: usize,
    /// The last reload of the layer's file ([`super::file::ScatterLayerSource`]) that
    /// failed: the layer keeps streaming the version loaded before, until a reload succeeds
    /// (then `None`).
    pub layer_file_error: Option<AssetFailure>,
    /// Instanced classes that cannot be drawn (class index, reason): their chunks stream and
    /// are counted, but are not drawn until the cause is fixed.
    pub class_errors: Vec<(u16, InstancedClassError)>,
}
