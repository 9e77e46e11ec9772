//! Streaming: viewers -> chunks -> queries on the async compute pool -> budgeted spawns.
//!
//! All decisions (which chunks, which instances change) come from
//! [`rwt_core::streaming`]; this module only moves data between Bevy and those functions.

mod plugin;
#[cfg(test)]
mod soak_tests;
#[cfg(test)]
mod tests;

pub use plugin::StreamingPlugin;

use crate::layer::{ClassLook, HeightFn, ScatterInstance, ScatterLayer, slope};
use crate::{ChunkLoaded, ChunkUnloaded, RwtSettings, RwtStats, RwtViewer, ViewCone};
use bevy::platform::collections::{HashMap, HashSet};
use bevy::prelude::*;
use bevy::tasks::{AsyncComputeTaskPool, Task, futures::check_ready};
use glam::DVec2;
use rwt_core::density::{Density, Exclude, Scale};
use rwt_core::query::{Point, PointId, Sampler};
use rwt_core::streaming::{ChunkCoord, ChunkSet, Viewer, diff_instances};
use rwt_core::tileset::TileSet;
use std::collections::VecDeque;
use std::sync::Arc;

/// The shipped tile set, parsed once for the app.
#[derive(Resource, Clone)]
pub struct RwtTileSet(pub Arc<TileSet>);

/// Ground positions and footprints of the viewers this frame.
#[derive(Resource, Default, Debug)]
pub struct Viewers(pub Vec<Viewer>);

type Densities = Vec<Arc<dyn Density + Send + Sync>>;

/// A chunk's generation task: its points, or nothing when the query was refused.
type ChunkTask = Task<Option<Vec<Point>>>;

#[derive(Default)]
struct ChunkState {
    instances: HashMap<PointId, Entity>,
    /// Points generated but not yet spawned (waiting for the spawn budget).
    queued: Vec<Point>,
    /// Whether the chunk is in the spawn order.
    in_order: bool,
    /// Level-of-detail band the content was generated for.
    lod: i64,
    task: Option<(ChunkTask, i64)>,
    /// Content must be regenerated (painted map changed, band changed while busy).
    stale: bool,
}

/// Per-layer streaming state, added with the layer.
#[derive(Component, Default)]
pub struct LayerState {
    sampler: Option<Arc<Sampler>>,
    densities: Option<Densities>,
    height: Option<HeightFn>,
    chunks: ChunkSet,
    states: HashMap<ChunkCoord, ChunkState>,
    /// Chunks with queued points, in the order they finished (unloaded ones are skipped).
    spawn_order: VecDeque<ChunkCoord>,
    despawn: VecDeque<Entity>,
}

impl LayerState {
    /// Live instances of the layer: those its chunks hold, plus those waiting in the
    /// despawn queue (still in the world until their turn comes).
    pub fn live(&self) -> usize {
        self.states
            .values()
            .map(|c| c.instances.len())
            .sum::<usize>()
            + self.despawn.len()
    }

    /// Chunks with a generation task in flight or waiting for one.
    pub fn pending(&self) -> usize {
        self.states
            .values()
            .filter(|c| c.task.is_some() || c.stale)
            .count()
    }

    /// Chunks with a generation task in flight.
    fn in_flight(&self) -> usize {
        self.states.values().filter(|c| c.task.is_some()).count()
    }

    /// Loaded chunks.
    pub fn loaded(&self) -> usize {
        self.chunks.loaded().len()
    }

    /// The loaded chunks themselves.
    pub fn loaded_chunks(&self) -> impl Iterator<Item = &rwt_core::streaming::ChunkCoord> + '_ {
        self.chunks.loaded().iter()
    }

    /// Instances waiting for the spawn budget.
    pub fn queued(&self) -> usize {
        self.states.values().map(|c| c.queued.len()).sum()
    }

    /// Despawns every instance the layer has placed or was about to remove.
    fn despawn_all(&self, commands: &mut Commands) {
        for e in self.entities().chain(self.despawn.iter().copied()) {
            commands.entity(e).try_despawn();
        }
    }

    /// Every instance entity of the layer.
    pub fn entities(&self) -> impl Iterator<Item = Entity> + '_ {
        self.states
            .values()
            .flat_map(|c| c.instances.values().copied())
    }
}

fn ground(t: &GlobalTransform) -> DVec2 {
    let p = t.translation();
    DVec2::new(p.x as f64, p.z as f64)
}

/// Half-angle of a viewer's ground wedge, or `None` for every direction.
fn half_angle(cone: ViewCone, projection: Option<&Projection>) -> Option<f32> {
    let half = match cone {
        ViewCone::All => return None,
        ViewCone::Fixed(h) => h,
        ViewCone::Camera { margin } => match projection {
            Some(Projection::Perspective(p)) => {
                ((p.fov * 0.5).tan() * p.aspect_ratio).atan() + margin
            }
            _ => return None,
        },
    };
    // Wider than a half-turn is every direction.
    (half < std::f32::consts::FRAC_PI_2 * 1.9).then_some(half)
}

/// Viewer positions and view wedges on the ground plane.
pub fn collect_viewers(
    mut viewers: ResMut<Viewers>,
    query: Query<(&GlobalTransform, &RwtViewer, Option<&Projection>)>,
    settings: Res<RwtSettings>,
) {
    viewers.0.clear();
    for (t, v, projection) in &query {
        let position = ground(t);
        let forward = t.forward();
        let flat = Vec2::new(forward.x, forward.z);
        // Looking mostly down, the view covers every direction.
        let footprint = match half_angle(v.cone, projection) {
            Some(half) if flat.length() > 0.3 => {
                let dir = flat.normalize();
                let reach = settings.footprint_reach as f32;
                let side = |a: f32| {
                    let (s, c) = a.sin_cos();
                    let d = Vec2::new(dir.x * c - dir.y * s, dir.x * s + dir.y * c) * reach;
                    DVec2::new(position.x + d.x as f64, position.y + d.y as f64)
                };
                if half >= std::f32::consts::FRAC_PI_2 {
                    // A wedge wider than a half-plane is not convex: approximate it by the
                    // half-plane ahead plus the near ring, which is loaded anyway.
                    vec![
                        side(-std::f32::consts::FRAC_PI_2),
                        side(0.0),
                        side(std::f32::consts::FRAC_PI_2),
                    ]
                } else {
                    // Counter-clockwise wedge: apex, then the two far corners.
                    vec![position, side(-half), side(half)]
                }
            }
            _ => Vec::new(),
        };
        viewers.0.push(Viewer {
            position,
            footprint,
        });
    }
}

/// The level-of-detail band of a chunk: the density fall-off is quantized so that moving a
/// little does not re-query, and so that every query of a band gives the same content.
fn lod_band(layer: &ScatterLayer, chunk: ChunkCoord, viewers: &[Viewer]) -> i64 {
    let Some((near, far)) = layer.falloff else {
        return 0;
    };
    let size = layer.streaming.chunk_size;
    let d = viewers
        .iter()
        .map(|v| chunk.distance(size, v.position))
        .fold(f64::INFINITY, f64::min);
    let step = ((far - near) / 8.0).max(1e-6);
    ((d - near).max(0.0) / step).floor().min(1e6) as i64
}

/// The density factor of a level-of-detail band: 1 up to `near`, falling linearly to 0 at
/// `far`, constant over a band so that every query of a band gives the same content and
/// approaching (a lower band, a higher factor) only adds points.
fn band_factor(layer: &ScatterLayer, band: i64) -> f64 {
    match layer.falloff {
        None => 1.0,
        Some((near, far)) => {
            let step = ((far - near) / 8.0).max(1e-6);
            (1.0 - band as f64 * step / (far - near).max(1e-6)).clamp(0.0, 1.0)
        }
    }
}

/// Starts a generation task for a chunk: the query, then the height and slope filters.
fn start_task(
    layer: &ScatterLayer,
    sampler: Arc<Sampler>,
    densities: Densities,
    height: HeightFn,
    chunk: ChunkCoord,
    band: i64,
) -> ChunkTask {
    let rect = chunk.rect(layer.streaming.chunk_size);
    let factor = band_factor(layer, band);
    let (range, max_slope) = (layer.height_range, layer.max_slope);
    AsyncComputeTaskPool::get().spawn(async move {
        let scaled: Vec<_> = densities.iter().map(|d| Scale(d.clone(), factor)).collect();
        let mut out = Vec::new();
        sampler
            .query_classes(rect, &scaled, |p| {
                let ground = Vec2::new(p.position.x as f32, p.position.y as f32);
                let in_range = range.is_none_or(|(lo, hi)| (lo..=hi).contains(&height(ground)));
                let flat_enough = max_slope.is_none_or(|m| slope(&height, ground, 0.25) <= m);
                if in_range && flat_enough {
                    out.push(p);
                }
            })
            .ok()
            .map(|_| out)
    })
}

/// Plans chunks for every layer and starts the generation tasks that are needed.
#[allow(clippy::too_many_arguments)]
pub fn plan_chunks(
    mut layers: Query<(Entity, &ScatterLayer, &mut LayerState)>,
    viewers: Res<Viewers>,
    images: Res<Assets<Image>>,
    tile_set: Res<RwtTileSet>,
    settings: Res<RwtSettings>,
    mut unloaded: MessageWriter<ChunkUnloaded>,
) {
    for (entity, layer, mut state) in &mut layers {
        let state = &mut *state;
        if state.sampler.is_none() {
            state.sampler = Some(Arc::new(
                Sampler::new(&tile_set.0, layer.seed).with_tile_size(layer.tile_size),
            ));
        }
        if state.densities.is_none() {
            let resolved: Option<Densities> = layer
                .classes
                .iter()
                .map(|c| c.density.resolve(&images))
                .collect();
            let exclusion = layer.exclusion.as_ref().map(|m| m.resolve(&images));
            match (resolved, exclusion) {
                // A painted map is still loading: try again next frame.
                (None, _) | (_, Some(None)) => continue,
                (Some(d), None) => state.densities = Some(d),
                (Some(d), Some(Some(mask))) => {
                    state.densities = Some(
                        d.into_iter()
                            .map(|inner| {
                                Arc::new(Exclude {
                                    inner,
                                    mask: mask.clone(),
                                    threshold: 0.5,
                                }) as Arc<dyn Density + Send + Sync>
                            })
                            .collect(),
                    )
                }
            }
        }
        if state.height.is_none() {
            match layer.height.resolve(&images) {
                Some(h) => state.height = Some(h),
                // A heightmap is still loading: try again next frame.
                None => continue,
            }
        }
        let changes = state.chunks.update(&layer.streaming, &viewers.0);
        for chunk in changes.unload {
            if let Some(c) = state.states.remove(&chunk) {
                state.despawn.extend(c.instances.values().copied());
            }
            // Its queued points go with it; its place in the spawn order is skipped later.
            unloaded.write(ChunkUnloaded {
                layer: entity,
                chunk,
            });
        }
        for chunk in changes.load {
            state.states.entry(chunk).or_default().stale = true;
        }
        // Level-of-detail bands move with the viewers.
        if layer.falloff.is_some() {
            for (chunk, c) in state.states.iter_mut() {
                if lod_band(layer, *chunk, &viewers.0) != c.lod {
                    c.stale = true;
                }
            }
        }
        let free = settings
            .max_tasks_in_flight
            .saturating_sub(state.in_flight());
        let sampler = state.sampler.clone().expect("sampler set above");
        let densities = state.densities.clone().expect("densities set above");
        let height = state.height.clone().expect("height set above");
        let mut order: Vec<(f64, ChunkCoord)> = state
            .states
            .iter()
            .filter(|(_, c)| c.stale && c.task.is_none())
            .map(|(ch, _)| {
                let d = viewers
                    .0
                    .iter()
                    .map(|v| ch.distance(layer.streaming.chunk_size, v.position))
                    .fold(f64::INFINITY, f64::min);
                (d, *ch)
            })
            .collect();
        order.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        // Nearest chunks first, as many as there are free task slots.
        for (_, chunk) in order.into_iter().take(free) {
            let band = lod_band(layer, chunk, &viewers.0);
            let c = state.states.get_mut(&chunk).expect("listed above");
            c.stale = false;
            c.task = Some((
                start_task(
                    layer,
                    sampler.clone(),
                    densities.clone(),
                    height.clone(),
                    chunk,
                    band,
                ),
                band,
            ));
        }
    }
}

/// Collects finished tasks and queues the instances that appear or disappear.
pub fn collect_results(
    mut layers: Query<(Entity, &mut LayerState)>,
    mut loaded: MessageWriter<ChunkLoaded>,
) {
    for (entity, mut state) in &mut layers {
        let state = &mut *state;
        let mut finished = Vec::new();
        for (chunk, c) in state.states.iter_mut() {
            let Some((task, band)) = c.task.as_mut() else {
                continue;
            };
            if let Some(result) = check_ready(task) {
                let band = *band;
                c.task = None;
                finished.push((*chunk, band, result));
            }
        }
        for (chunk, band, result) in finished {
            let Some(points) = result else { continue };
            let c = state.states.get_mut(&chunk).expect("finished chunks exist");
            c.lod = band;
            // Compare with what the chunk shows or is about to show.
            let shown: Vec<PointId> = c
                .instances
                .keys()
                .chain(c.queued.iter().map(|p| &p.id))
                .copied()
                .collect();
            let diff = diff_instances(shown.iter(), &points);
            if !diff.removed.is_empty() {
                let removed: HashSet<PointId> = diff.removed.iter().copied().collect();
                c.queued.retain(|p| !removed.contains(&p.id));
                for id in &diff.removed {
                    if let Some(e) = c.instances.remove(id) {
                        state.despawn.push_back(e);
                    }
                }
            }
            let count = points.len();
            c.queued.extend(diff.added);
            if !c.queued.is_empty() && !c.in_order {
                c.in_order = true;
                state.spawn_order.push_back(chunk);
            }
            loaded.write(ChunkLoaded {
                layer: entity,
                chunk,
                instances: count,
            });
        }
    }
}
/// Spawns and despawns queued instances within the per-frame budget.
pub fn apply_budget(
    mut commands: Commands,
    mut layers: Query<(Entity, &ScatterLayer, &mut LayerState)>,
    settings: Res<RwtSettings>,
) {
    let mut spawn_budget = settings.spawn_budget;
    let mut despawn_budget = settings.despawn_budget;
    for (entity, layer, mut state) in &mut layers {
        let state = &mut *state;
        while despawn_budget > 0 {
            let Some(e) = state.despawn.pop_front() else {
                break;
            };
            commands.entity(e).try_despawn();
            despawn_budget -= 1;
        }
        while spawn_budget > 0 {
            let Some(&chunk) = state.spawn_order.front() else {
                break;
            };
            let Some(height) = state.height.clone() else {
                break;
            };
            let Some(c) = state.states.get_mut(&chunk) else {
                // Unloaded while waiting.
                state.spawn_order.pop_front();
                continue;
            };
            while spawn_budget > 0 {
                let Some(p) = c.queued.pop() else { break };
                let class =
                    &layer.classes[(p.class as usize).min(layer.classes.len().saturating_sub(1))];
                let ground = Vec2::new(p.position.x as f32, p.position.y as f32);
                let scale =
                    class.scale * p.id.scale(layer.seed, class.scale_variation as f64) as f32;
                let transform = Transform::from_xyz(ground.x, height(ground), ground.y)
                    .with_rotation(Quat::from_rotation_y(p.id.rotation(layer.seed) as f32))
                    .with_scale(Vec3::splat(scale));
                let instance = ScatterInstance {
                    layer: entity,
                    id: p.id,
                    class: p.class,
                };
                // One bundle for the common case: an insert after the spawn would move
                // every instance to a second archetype.
                let e = match &class.look {
                    ClassLook::Mesh { mesh, material } => commands
                        .spawn((
                            instance,
                            Mesh3d(mesh.clone()),
                            MeshMaterial3d(material.clone()),
                            transform,
                        ))
                        .id(),
                    ClassLook::Custom(insert) => {
                        let mut custom = commands.spawn((instance, transform));
                        insert(&mut custom);
                        custom.id()
                    }
                };
                c.instances.insert(p.id, e);
                spawn_budget -= 1;
            }
            if c.queued.is_empty() {
                c.in_order = false;
                state.spawn_order.pop_front();
            }
        }
    }
}
/// Re-queries the chunks a repainted map covers; only changed instances are touched.
pub fn repaint(
    mut events: MessageReader<AssetEvent<Image>>,
    mut layers: Query<(&ScatterLayer, &mut LayerState)>,
) {
    let changed: Vec<AssetId<Image>> = events
        .read()
        .filter_map(|e| match e {
            AssetEvent::Modified { id } | AssetEvent::LoadedWithDependencies { id } => Some(*id),
            _ => None,
        })
        .collect();
    if changed.is_empty() {
        return;
    }
    for (layer, mut state) in &mut layers {
        let touched: Vec<(Vec2, Vec2)> = layer
            .densities()
            .filter_map(|d| match d {
                crate::layer::LayerDensity::Image {
                    image, min, size, ..
                } if changed.contains(&image.id()) => Some((*min, *size)),
                _ => None,
            })
            .collect();
        if touched.is_empty() {
            continue;
        }
        state.densities = None;
        let size = layer.streaming.chunk_size;
        for (chunk, c) in state.states.iter_mut() {
            let r = chunk.rect(size);
            let overlaps = touched.iter().any(|(min, s)| {
                r.max.x > min.x as f64
                    && r.min.x < (min.x + s.x) as f64
                    && r.max.y > min.y as f64
                    && r.min.y < (min.y + s.y) as f64
            });
            if overlaps {
                c.stale = true;
            }
        }
    }
}

/// Despawns every instance of a layer whose component is removed.
pub fn on_layer_removed(
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
pub fn on_layer_inserted(
    insert: On<Insert, ScatterLayer>,
    states: Query<&LayerState>,
    mut commands: Commands,
) {
    if let Ok(old) = states.get(insert.entity) {
        old.despawn_all(&mut commands);
    }
    commands.entity(insert.entity).insert(LayerState::default());
}

/// Updates [`RwtStats`].
pub fn update_stats(layers: Query<&LayerState>, mut stats: ResMut<RwtStats>) {
    stats.live_instances = layers.iter().map(LayerState::live).sum();
    stats.loaded_chunks = layers.iter().map(LayerState::loaded).sum();
    stats.pending_tasks = layers.iter().map(LayerState::pending).sum();
    stats.queued_spawns = layers.iter().map(LayerState::queued).sum();
}
