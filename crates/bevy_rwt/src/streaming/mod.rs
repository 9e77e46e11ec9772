//! Streaming: viewers -> chunks -> queries on the async compute pool -> budgeted spawns.
//!
//! Every decision (which chunks, which level of detail, which instances change) comes from
//! [`rwt_core::streaming`]; this module moves data between Bevy and those functions:
//! - `resolve`: a layer's densities and height source as thread-safe snapshots, re-made
//!   only for the maps that change;
//! - `plan`: chunks to load and unload, generation tasks for the nearest stale chunks;
//! - `collect`: finished tasks handed to the look that shows them: points of entity
//!   classes to the entity look (`entities`), instance buffers to [`crate::instancing`];
//! - `spawn`: each look's queue spent within the per-frame budgets;
//! - `repaint`: painted maps mark the chunks they cover stale.

mod collect;
mod discs;
mod edit;
mod footprint;
mod generate;
mod keep_out;
mod plan;
mod plugin;
mod repaint;
mod resolve;
mod spawn;
mod surfaces;

pub(crate) use footprint::KnownFootprints;
pub(crate) use generate::{Changes, Generator};
pub use plugin::RwtStreamingPlugin;

use crate::edits::EditSet;
use crate::edits::EditStamp;
use crate::entities::EntityQueue;
use crate::instancing::{InstancedClasses, InstancedQueue, PackedClass};
use crate::layers::{ScatterLayer, ScatterLayerStatus};
use bevy::platform::collections::HashMap;
use bevy::prelude::*;
use bevy::tasks::Task;
use rwt_core::query::{Point, QueryError, Rect, Sampler};
use rwt_core::streaming::{ChunkCoord, ChunkSet};
use rwt_core::tileset::TileSet;
use std::sync::Arc;

/// A chunk's instances were generated (or regenerated) and queued for spawning.
#[derive(Message, Clone, Copy, Debug, PartialEq, Reflect)]
#[reflect(Clone, Debug, PartialEq)]
pub struct ChunkLoaded {
    /// The layer entity.
    pub layer: Entity,
    /// The chunk.
    pub chunk: ChunkCoord,
    /// Instances the chunk holds now.
    pub instances: usize,
}

/// A chunk left every viewer's unload distance; its instances are being despawned.
#[derive(Message, Clone, Copy, Debug, PartialEq, Reflect)]
#[reflect(Clone, Debug, PartialEq)]
pub struct ChunkUnloaded {
    /// The layer entity.
    pub layer: Entity,
    /// The chunk.
    pub chunk: ChunkCoord,
}

/// Tells the plugin which part of a density map a brush changed (ground coordinates of the
/// layers that read it). When the map's `Modified` event arrives, only chunks overlapping
/// the painted regions re-scatter; without this message, every chunk the map covers does.
#[derive(Message, Clone, Copy, Debug, PartialEq, Reflect)]
#[reflect(Clone, Debug, PartialEq)]
pub struct DensityMapPainted {
    /// The map.
    pub image: AssetId<Image>,
    /// The ground region whose density changed.
    pub region: Rect,
}

/// The tile set every layer samples (the shipped one unless the plugin was given another):
/// a resource, read-only outside the plugin. Its [`RwtTileSet::fingerprint`] names it in
/// saved edits and in what networked peers compare.
#[derive(Resource, Clone)]
pub struct RwtTileSet {
    pub(crate) set: Arc<TileSet>,
    /// [`TileSet::fingerprint`], which saved edits name their tile set by.
    fingerprint: u64,
}

impl RwtTileSet {
    pub(crate) fn new(set: Arc<TileSet>) -> Self {
        Self {
            fingerprint: set.fingerprint(),
            set,
        }
    }

    /// The tile set.
    pub fn tile_set(&self) -> &TileSet {
        &self.set
    }

    /// [`TileSet::fingerprint`] of the tile set.
    pub fn fingerprint(&self) -> u64 {
        self.fingerprint
    }

    /// What the point identities of `layer` refer to (in saves).
    pub fn stamp(&self, layer: &ScatterLayer) -> EditStamp {
        EditStamp {
            seed: layer.seed,
            lattice: layer.lattice,
            tile_set: self.fingerprint,
        }
    }
}

/// What a chunk's generation task hands back: the points of entity classes, the buffers
/// of instanced ones (packed in the task), and the chunk's edits it applied.
struct ChunkContent {
    points: Vec<Point>,
    packed: Vec<PackedClass>,
    edits: Option<Arc<EditSet>>,
}

/// A chunk's generation task: its content, or why the query was refused (over the chunk
/// point budget).
type ChunkTask = Task<Result<ChunkContent, QueryError>>;

#[derive(Default)]
struct ChunkState {
    /// Level-of-detail band the content was generated for.
    lod: i64,
    task: Option<(ChunkTask, i64)>,
    /// Content must be regenerated (painted map changed, band changed while busy).
    stale: bool,
    /// The last query was refused (over the chunk point budget): the chunk shows what it
    /// showed before, or nothing.
    refused: bool,
    /// Whether a generation finished since the chunk loaded (at level of detail `lod`).
    shown: bool,
    /// The ground under the chunk changed: the next generation also moves the entities it
    /// keeps onto the new ground.
    reground: bool,
    /// Whether the task in flight was started for a changed ground.
    task_regrounds: bool,
}

/// A layer's points as shown: see [`LayerState::shown`].
pub(crate) struct ShownLayer {
    pub generator: Generator,
    pub chunks: Vec<ShownChunk>,
}

/// A chunk that shows points.
pub(crate) struct ShownChunk {
    pub chunk: ChunkCoord,
    /// Level-of-detail factor of what it shows.
    pub factor: f64,
    pub edits: Option<Arc<EditSet>>,
}

/// Per-layer streaming state, added with the layer.
#[derive(Component, Default)]
pub(crate) struct LayerState {
    sampler: Option<Arc<Sampler>>,
    /// The layer's instanced classes (made with the sampler).
    instanced_classes: Option<InstancedClasses>,
    sources: resolve::Resolved,
    chunks: ChunkSet,
    states: HashMap<ChunkCoord, ChunkState>,
    /// What the entity look shows and is about to show.
    entities: EntityQueue,
    /// What the instanced look draws and is about to draw.
    instanced: InstancedQueue,
    /// The layer's edits by the chunk that holds each point, shared with generation tasks
    /// (a changed chunk's set is copied on write, so a task's set tells whether its
    /// result is out of date).
    chunk_edits: HashMap<ChunkCoord, Arc<EditSet>>,
    /// Whether `chunk_edits` was made from the layer's [`crate::edits::ScatterEdits`].
    edits_indexed: bool,
    /// Whether a refused query was logged (once per layer).
    refusal_logged: bool,
    /// The layers that clear this one, as its tasks generate with them; `None` while one
    /// of them is not ready.
    keep_out: Option<Arc<[generate::Clearing]>>,
}

impl LayerState {
    /// The layer's ground as its chunks are generated on (`None` until resolved, e.g.
    /// while a heightmap loads): where the brush paints.
    pub(crate) fn ground(&self) -> Option<&crate::ground::SharedGround> {
        self.sources.ground()
    }

    /// How the layer's chunks are generated (`None` until its sampler and sources are
    /// made).
    fn generator(&self, layer: &ScatterLayer) -> Option<Generator> {
        Some(Generator::new(
            layer,
            self.sampler.clone()?,
            &self.sources.ready()?,
            self.keep_out_for(layer)?,
        ))
    }

    /// The layers that clear this one, as its tasks generate with them; `None` while one
    /// of the layers it names is not ready.
    fn keep_out_for(&self, layer: &ScatterLayer) -> Option<Arc<[generate::Clearing]>> {
        match &self.keep_out {
            Some(k) => Some(k.clone()),
            None => layer.keep_out.is_empty().then(|| Arc::from([])),
        }
    }

    /// The layer's sampler, made on first use.
    fn sampler(&mut self, layer: &ScatterLayer, tile_set: &TileSet, budget: usize) -> Arc<Sampler> {
        self.sampler
            .get_or_insert_with(|| {
                let sampler = Sampler::new(tile_set, layer.seed)
                    .with_lattice(layer.lattice)
                    .with_budget(budget);
                Arc::new(sampler.with_tile_size(layer.tile_size))
            })
            .clone()
    }

    /// Chunks with a generation task in flight or waiting for one.
    fn pending(&self) -> usize {
        self.states
            .values()
            .filter(|c| c.task.is_some() || c.stale)
            .count()
    }

    /// Chunks with a generation task in flight.
    fn in_flight(&self) -> usize {
        self.states.values().filter(|c| c.task.is_some()).count()
    }

    /// Despawns every instance the layer has placed or was about to remove.
    fn despawn_all(&self, commands: &mut Commands) {
        self.entities.despawn_all(commands);
        self.instanced.despawn_all(commands);
    }

    /// Forgets a chunk that left every viewer's unload distance: each look takes its
    /// instances away.
    fn unload(&mut self, chunk: ChunkCoord) {
        self.states.remove(&chunk);
        self.entities.unload(chunk);
        self.instanced.unload(chunk);
    }

    /// What picking needs to make a layer's shown points again: how they are generated,
    /// and each shown chunk with its level-of-detail factor and edits (`None` until the
    /// layer's sources are made).
    pub(crate) fn shown(&self, layer: &ScatterLayer) -> Option<ShownLayer> {
        let generator = self.generator(layer)?;
        let chunks = self
            .states
            .iter()
            .filter(|(_, c)| c.shown)
            .map(|(chunk, c)| ShownChunk {
                chunk: *chunk,
                factor: layer.falloff.map_or(1.0, |f| f.factor(c.lod)),
                edits: self.chunk_edits.get(chunk).cloned(),
            })
            .collect();
        Some(ShownLayer { generator, chunks })
    }

    /// Marks `chunk` for regeneration, if loaded.
    fn mark_chunk_stale(&mut self, chunk: ChunkCoord) {
        if let Some(c) = self.states.get_mut(&chunk) {
            c.stale = true;
        }
    }

    /// Marks every chunk overlapping `region`, where the ground changed, for regeneration
    /// on the new ground.
    fn mark_regrounded(&mut self, size: f64, region: &Rect) {
        for (chunk, c) in self.states.iter_mut() {
            if chunk.rect(size).overlaps(region) {
                c.stale = true;
                c.reground = true;
            }
        }
    }

    /// Marks every chunk for regeneration.
    fn mark_all_stale(&mut self) {
        for c in self.states.values_mut() {
            c.stale = true;
        }
    }

    /// Marks every chunk overlapping `region` for regeneration.
    fn mark_stale(&mut self, size: f64, region: &Rect) {
        for (chunk, c) in self.states.iter_mut() {
            if chunk.rect(size).overlaps(region) {
                c.stale = true;
            }
        }
    }
}

/// Despawns every instance of a layer whose component is removed.
fn on_layer_removed(
    remove: On<Remove, ScatterLayer>,
    states: Query<&LayerState>,
    mut commands: Commands,
) {
    if let Ok(state) = states.get(remove.entity) {
        state.despawn_all(&mut commands);
    }
    // The entity may be being despawned: removing then is a silent no-op.
    if let Ok(mut e) = commands.get_entity(remove.entity) {
        e.try_remove::<LayerState>();
    }
}

/// Gives every new or replaced layer a fresh streaming state: a replaced layer (new settings,
/// a reloaded description) despawns what the old one placed and streams anew.
fn on_layer_inserted(
    insert: On<Insert, ScatterLayer>,
    states: Query<&LayerState>,
    mut statuses: Query<&mut ScatterLayerStatus>,
    mut commands: Commands,
) {
    let status = statuses.get_mut(insert.entity).ok();
    restart(
        insert.entity,
        states.get(insert.entity).ok(),
        status,
        &mut commands,
    );
}

/// Streams a layer changed in place (through reflection, an inspector, or a
/// `Mut<ScatterLayer>`) anew, as a replaced one: its settings take effect at once.
fn restart_changed_layers(
    layers: Query<(Entity, Ref<ScatterLayer>, Option<&LayerState>)>,
    mut statuses: Query<&mut ScatterLayerStatus>,
    mut commands: Commands,
) {
    for (entity, layer, old) in &layers {
        if layer.is_changed() && !layer.is_added() {
            restart(entity, old, statuses.get_mut(entity).ok(), &mut commands);
        }
    }
}

/// Despawns what a layer placed and gives it a fresh streaming state.
fn restart(
    entity: Entity,
    old: Option<&LayerState>,
    status: Option<impl std::ops::DerefMut<Target = ScatterLayerStatus>>,
    commands: &mut Commands,
) {
    if let Some(old) = old {
        old.despawn_all(commands);
    }
    if let Some(mut status) = status {
        status.loaded_chunks.clear();
    }
    commands.entity(entity).insert(LayerState::default());
}

/// Copies each layer's counts into its [`ScatterLayerStatus`] (its loaded chunks are
/// copied by planning, when they change). Meshes of surfaces being indexed count as
/// pending tasks of the layers on surfaces.
fn update_status(
    mut layers: Query<(&ScatterLayer, &LayerState, &mut ScatterLayerStatus)>,
    surfaces: Res<surfaces::SurfaceMeshes>,
) {
    for (layer, state, mut status) in &mut layers {
        let status = status.bypass_change_detection();
        status.live_entities = state.entities.live();
        status.live_instanced = state.instanced.live();
        status.promoted_instances = state.instanced.promoted();
        let indexing = match layer.height {
            crate::layers::HeightSource::Surfaces => surfaces.building(),
            _ => 0,
        };
        status.pending_tasks = state.pending() + indexing;
        status.queued_spawns = state.entities.queued() + state.instanced.queued();
        status.refused_chunks = state.states.values().filter(|c| c.refused).count();
    }
}
