//! What the plugin reports about each layer: its assets, chunks and instances.

use crate::look::InstancedClassError;
use bevy::platform::collections::HashSet;
use bevy::prelude::*;
use rwt_core::streaming::ChunkCoord;

/// Whether the assets a layer reads (its layer file, density maps, heightmap) are there.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub enum AssetStatus {
    /// Every asset is loaded: the layer streams.
    #[default]
    Ready,
    /// Waiting for these assets (paths, or handles of assets made in code) to load.
    Waiting(Vec<String>),
    /// These assets failed to load (`asset: reason`): the layer shows nothing until they
    /// are fixed (a file watcher reloads them).
    Failed(Vec<String>),
}

/// The state of a layer, kept up to date by the plugin on every entity with a
/// [`super::ScatterLayer`] or a [`super::file::ScatterLayerSource`]: read it for a HUD, or
/// to tell a player why a layer is empty.
#[derive(Component, Clone, Debug, Default, PartialEq)]
pub struct ScatterLayerStatus {
    /// Its assets.
    pub assets: AssetStatus,
    /// Chunks loaded.
    pub loaded_chunks: HashSet<ChunkCoord>,
    /// Entity instances alive (spawned and not yet despawned).
    pub live_instances: usize,
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
    /// The last reload of the layer's file ([`super::file::ScatterLayerSource`]) that failed
    /// (`path: reason`): the layer keeps streaming the version loaded before, until a reload
    /// succeeds (then `None`).
    pub layer_file_error: Option<String>,
    /// Instanced classes that cannot be drawn (class index, reason): their chunks stream and
    /// are counted, but are not drawn until the cause is fixed.
    pub class_errors: Vec<(u16, InstancedClassError)>,
}
