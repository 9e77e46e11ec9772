//! Planning: which chunks each layer loads and unloads, which need regenerating, and the
//! generation tasks for the nearest of them.

use super::footprint::KnownFootprints;
use super::resolve::Sources;
use super::{ChunkContent, ChunkTask, ChunkUnloaded, LayerState, RwtTileSet};
use crate::edits::EditSet;
use crate::footprints::GroundFootprint;
use crate::instancing::InstancedClasses;
use crate::layers::{AssetStatus, ScatterLayer, ScatterLayerStatus, report_assets, slope};
use crate::settings::RwtSettings;
use crate::viewers::Viewers;
use bevy::prelude::*;
use bevy::tasks::AsyncComputeTaskPool;
use rwt_core::density::Scale;
use rwt_core::query::Sampler;
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
        let free = inputs
            .settings
            .max_tasks_in_flight
            .saturating_sub(state.in_flight());
        let job = Job {
            entity,
            footprints: &inputs.footprints,
            layer,
            sampler: &sampler,
            sources: &sources,
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
    sampler: &'a Arc<Sampler>,
    sources: &'a Sources,
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
        let c = state.states.get_mut(&chunk).expect("listed above");
        c.stale = false;
        c.task = Some((start_task(job, chunk, band, changes), band));
    }
}

/// What a game changed in a chunk: its per-instance edits and the footprints over it.
struct Changes {
    edits: Option<Arc<EditSet>>,
    footprints: Vec<GroundFootprint>,
}

/// Starts a generation task for a chunk: the query at the band's density, the height and
/// slope filters, the chunk's edits and footprints, then the packing of instanced classes.
fn start_task(job: &Job, chunk: ChunkCoord, band: i64, changes: Changes) -> ChunkTask {
    let layer = job.layer;
    let (sampler, sources) = (job.sampler.clone(), job.sources);
    let instanced = job.instanced.clone();
    let rect = chunk.rect(layer.streaming.chunk_size);
    let factor = layer.falloff.map_or(1.0, |f| f.factor(band));
    let (range, max_slope) = (layer.height_range, layer.max_slope);
    let densities = sources.densities.clone();
    let height = sources.height.clone();
    let classes = layer.classes.len();
    AsyncComputeTaskPool::get().spawn(async move {
        let scaled: Vec<_> = densities.iter().map(|d| Scale(d.clone(), factor)).collect();
        let mut out = Vec::new();
        sampler.query_classes(rect, &scaled, |p| {
            let ground = Vec2::new(p.position.x as f32, p.position.y as f32);
            let in_range = range.is_none_or(|(lo, hi)| (lo..=hi).contains(&height(ground)));
            let flat_enough = max_slope.is_none_or(|m| slope(&height, ground, 0.25) <= m);
            if in_range && flat_enough {
                out.push(p);
            }
        })?;
        let Changes { edits, footprints } = changes;
        if let Some(edits) = &edits {
            edits.apply(&mut out, classes);
        }
        if !footprints.is_empty() {
            out.retain(|p| !footprints.iter().any(|f| f.clears(p.position, p.class)));
        }
        let packed = instanced.pack(&mut out, rect.min(), &height, &scaled, factor);
        Ok(ChunkContent {
            points: out,
            packed,
            edits,
        })
    })
}
