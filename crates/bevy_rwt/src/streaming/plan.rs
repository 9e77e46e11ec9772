//! Planning: which chunks each layer loads and unloads, which need regenerating, and the
//! generation tasks for the nearest of them.

use super::footprint::KnownFootprints;
use super::generate::{Changes, Generator};
use super::{ChunkContent, ChunkTask, ChunkUnloaded, LayerState, RwtTileSet};
use crate::instancing::InstancedClasses;
use crate::layers::{AssetStatus, ScatterLayer, ScatterLayerStatus, report_assets};
use crate::settings::RwtSettings;
use crate::viewers::Viewers;
use bevy::prelude::*;
use bevy::tasks::AsyncComputeTaskPool;
use rwt_core::streaming::{ChunkCoord, Viewer, nearest_first};
use std::sync::Arc;

/// The resources planning reads.
#[derive(bevy::ecs::system::SystemParam)]
pub(super) struct PlanInputs<'w> {
    viewers: Res<'w, Viewers>,
    images: Res<'w, Assets<Image>>,
    server: Option<Res<'w, AssetServer>>,
    tile_set: Res<'w, RwtTileSet>,
    settings: Res<'w, RwtSettings>,
    footprints: Res<'w, KnownFootprints>,
}

/// Plans chunks for every layer whose assets are there and starts the generation tasks
/// that are needed; layers still waiting for assets report why.
pub(super) fn plan_chunks(
    mut layers: Query<(
        Entity,
        &ScatterLayer,
        &mut LayerState,
        &mut ScatterLayerStatus,
    )>,
    inputs: PlanInputs,
    mut unloaded: MessageWriter<ChunkUnloaded>,
) {
    for (entity, layer, mut state, mut status) in &mut layers {
        let state = &mut *state;
        let sources = match state
            .sources
            .sources(layer, &inputs.images, inputs.server.as_deref())
        {
            Ok(sources) => sources,
            Err(missing) => {
                report_assets(entity, &mut status, missing);
                continue;
            }
        };
        report_assets(entity, &mut status, AssetStatus::Ready);
        let budget = inputs.settings.chunk_point_budget;
        let sampler = state.sampler(layer, &inputs.tile_set.set, budget);
        let keep_ids = inputs.settings.keep_instance_ids;
        let instanced = state
            .instanced_classes
            .get_or_insert_with(|| InstancedClasses::new(entity, layer, keep_ids))
            .clone();
        let viewers = inputs.viewers.on(layer.plane);
        if update_chunks(entity, layer, state, viewers, &mut unloaded) {
            status.loaded_chunks = state.chunks.loaded().iter().copied().collect();
        }
        mark_band_changes(layer, state, viewers);
        // A layer that other layers clear waits until they are ready.
        let keep_out = state.keep_out_for(layer);
        let free = match keep_out {
            Some(_) => inputs
                .settings
                .max_tasks_in_flight
                .saturating_sub(state.in_flight()),
            None => 0,
        };
        let keep_out = keep_out.unwrap_or_else(|| Arc::from([]));
        let job = Job {
            entity,
            footprints: &inputs.footprints,
            layer,
            generator: Generator::new(layer, sampler, &sources, keep_out),
            instanced: &instanced,
        };
        start_tasks(&job, state, viewers, free);
    }
}

/// Loads and unloads chunks for the viewers: unloaded chunks queue their instances for
/// despawning, loaded ones wait for generation. Returns whether any chunk changed.
fn update_chunks(
    entity: Entity,
    layer: &ScatterLayer,
    state: &mut LayerState,
    viewers: &[Viewer],
    unloaded: &mut MessageWriter<ChunkUnloaded>,
) -> bool {
    let changes = state.chunks.update(&layer.streaming, viewers);
    let changed = !(changes.load.is_empty() && changes.unload.is_empty());
    for chunk in changes.unload {
        state.unload(chunk);
        unloaded.write(ChunkUnloaded {
            layer: entity,
            chunk,
        });
    }
    for chunk in changes.load {
        state.states.entry(chunk).or_default().stale = true;
    }
    changed
}

/// Chunks whose level-of-detail band moved with the viewers need regenerating.
fn mark_band_changes(layer: &ScatterLayer, state: &mut LayerState, viewers: &[Viewer]) {
    let Some(falloff) = layer.falloff else {
        return;
    };
    let size = layer.streaming.chunk_size;
    for (chunk, c) in state.states.iter_mut() {
        if falloff.chunk_band(*chunk, size, viewers) != c.lod {
            c.stale = true;
        }
    }
}

/// What every generation task of a layer shares.
struct Job<'a> {
    /// The layer entity.
    entity: Entity,
    footprints: &'a KnownFootprints,
    layer: &'a ScatterLayer,
    generator: Generator,
    instanced: &'a InstancedClasses,
}

/// Starts generation tasks for up to `free` stale chunks without one, nearest first.
fn start_tasks(job: &Job, state: &mut LayerState, viewers: &[Viewer], free: usize) {
    let layer = job.layer;
    let size = layer.streaming.chunk_size;
    let stale = state
        .states
        .iter()
        .filter(|(_, c)| c.stale && c.task.is_none())
        .map(|(chunk, _)| *chunk);
    for chunk in nearest_first(stale, size, viewers).into_iter().take(free) {
        let band = layer
            .falloff
            .map_or(0, |f| f.chunk_band(chunk, size, viewers));
        let changes = Changes {
            edits: state.chunk_edits.get(&chunk).cloned(),
            footprints: job
                .footprints
                .clearing(job.entity, layer.plane, &chunk.rect(size)),
        };
        let Some(c) = state.states.get_mut(&chunk) else {
            continue;
        };
        c.stale = false;
        c.task_regrounds = std::mem::take(&mut c.reground);
        c.task = Some((start_task(job, chunk, band, changes), band));
    }
}

/// Starts a generation task for a chunk: its points (see [`Generator::points`]), then the
/// packing of instanced classes.
fn start_task(job: &Job, chunk: ChunkCoord, band: i64, changes: Changes) -> ChunkTask {
    let layer = job.layer;
    let generator = job.generator.clone();
    let instanced = job.instanced.clone();
    let rect = chunk.rect(layer.streaming.chunk_size);
    let factor = layer.falloff.map_or(1.0, |f| f.factor(band));
    AsyncComputeTaskPool::get().spawn(async move {
        let scaled = generator.scaled(factor, None);
        let (mut out, stands) = generator.points_and_stands(rect, &scaled, &changes)?;
        let ground = (&generator.ground, &stands);
        let packed = instanced.pack(&mut out, rect.min(), ground, &scaled, factor);
        Ok(ChunkContent {
            points: out,
            packed,
            edits: changes.edits,
        })
    })
}
