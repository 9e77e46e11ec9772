//! The meshes marked [`ScatterSurface`] as the ground of the layers on surfaces: gathered on
//! the main thread, indexed on the async compute pool, handed to each layer as one
//! [`SurfaceGround`]. A marked mesh that appears, moves, changes or goes re-scatters only
//! the chunks under its old and new ground rectangles.

use super::LayerState;
use crate::ground::{MeshGroundError, MeshTriangles, ScatterSurface, SurfaceGround, SurfaceMesh};
use crate::layers::{HeightSource, ScatterLayer};
use crate::look::GroundPlane;
use bevy::ecs::message::MessageCursor;
use bevy::ecs::system::SystemParam;
use bevy::math::Affine3A;
use bevy::platform::collections::{HashMap, HashSet};
use bevy::prelude::*;
use bevy::tasks::{AsyncComputeTaskPool, Task, block_on, futures_lite::future};
use rwt_core::query::Rect;
use std::sync::Arc;

/// What a marked mesh's ground was made from: when any of it changes, it is made again.
#[derive(Clone, Debug, PartialEq)]
struct Source {
    mesh: AssetId<Mesh>,
    transform: Affine3A,
    marker: ScatterSurface,
}

/// One marked mesh on one plane.
type Key = (Entity, GroundPlane);

type BuildTask = Task<Result<SurfaceMesh, MeshGroundError>>;

/// Every marked mesh's ground, built or being built.
#[derive(Resource, Default)]
pub(crate) struct SurfaceMeshes {
    built: HashMap<Key, (Source, Arc<SurfaceMesh>)>,
    building: HashMap<Key, (Source, BuildTask)>,
    /// Meshes that cannot be ground, with what they were (logged once each).
    failed: HashMap<Key, Source>,
}

/// Ground rectangles whose surfaces changed this frame, per plane.
type Changed = Vec<(GroundPlane, Rect)>;

/// What tracking the marked meshes reads.
#[derive(SystemParam)]
pub(super) struct MarkedMeshes<'w, 's> {
    marked: Query<'w, 's, (Entity, &'static ScatterSurface)>,
    children: Query<'w, 's, &'static Children>,
    parents: Query<'w, 's, &'static ChildOf>,
    meshes: Query<'w, 's, (&'static Mesh3d, &'static GlobalTransform)>,
    assets: Option<Res<'w, Assets<Mesh>>>,
    events: Option<Res<'w, Messages<AssetEvent<Mesh>>>>,
}

impl MarkedMeshes<'_, '_> {
    /// Every marked mesh entity with what its ground is made from (the marker nearest
    /// above it, its own first).
    fn sources(&self) -> HashMap<Entity, Source> {
        let mut out = HashMap::new();
        for (root, _) in &self.marked {
            let below = std::iter::once(root).chain(self.children.iter_descendants(root));
            for e in below {
                if out.contains_key(&e) {
                    continue;
                }
                let (Ok((mesh, at)), Some(marker)) = (self.meshes.get(e), self.marker_of(e)) else {
                    continue;
                };
                let source = Source {
                    mesh: mesh.id(),
                    transform: at.affine(),
                    marker: marker.clone(),
                };
                out.insert(e, source);
            }
        }
        out
    }

    /// The marker of `e` or of its nearest marked ancestor.
    fn marker_of(&self, e: Entity) -> Option<&ScatterSurface> {
        let mut at = e;
        loop {
            if let Ok((_, marker)) = self.marked.get(at) {
                return Some(marker);
            }
            at = self.parents.get(at).ok()?.parent();
        }
    }
}

/// Gathers the marked meshes, starts building the ground of new or changed ones, collects
/// finished builds, and hands each layer on surfaces its ground, marking the chunks under
/// what changed stale.
pub(super) fn track_surfaces(
    marked: MarkedMeshes,
    mut cursor: Local<MessageCursor<AssetEvent<Mesh>>>,
    mut layers: Query<(Entity, &ScatterLayer, &mut LayerState)>,
    mut registry: ResMut<SurfaceMeshes>,
) {
    let planes: HashSet<GroundPlane> = layers
        .iter()
        .filter(|(_, l, _)| matches!(l.height, HeightSource::Surfaces))
        .map(|(_, l, _)| l.plane)
        .collect();
    let modified: HashSet<AssetId<Mesh>> = match &marked.events {
        Some(events) => cursor
            .read(events)
            .filter_map(|e| match e {
                AssetEvent::Modified { id } => Some(*id),
                _ => None,
            })
            .collect(),
        None => HashSet::new(),
    };
    if planes.is_empty() && registry.built.is_empty() && registry.building.is_empty() {
        return;
    }
    let sources = marked.sources();
    let mut changed = Changed::new();
    registry.forget_gone(&sources, &planes, &mut changed);
    registry.start_builds(&sources, &planes, &modified, marked.assets.as_deref());
    registry.collect_builds(&mut changed);
    for (entity, layer, mut state) in &mut layers {
        if !matches!(layer.height, HeightSource::Surfaces) {
            continue;
        }
        let fresh = state.ground().is_none();
        if (fresh && registry.building.is_empty()) || !changed.is_empty() {
            let ground = registry.ground_for(entity, layer.plane);
            state.sources.set_surfaces(layer, Arc::new(ground));
        }
        let size = layer.streaming.chunk_size;
        for (_, rect) in changed.iter().filter(|(p, _)| *p == layer.plane) {
            state.mark_regrounded(size, rect);
        }
    }
}

/// A mesh's ground rectangle as a query rectangle.
fn rect_of(mesh: &SurfaceMesh) -> Option<Rect> {
    let (lo, hi) = mesh.ground_rect();
    Rect::new(lo.as_dvec2(), hi.as_dvec2()).ok()
}

impl SurfaceMeshes {
    /// Meshes whose ground is being built.
    pub fn building(&self) -> usize {
        self.building.len()
    }

    /// Forgets the ground of meshes no longer marked (or on no plane a layer uses).
    fn forget_gone(
        &mut self,
        sources: &HashMap<Entity, Source>,
        planes: &HashSet<GroundPlane>,
        changed: &mut Changed,
    ) {
        let keep = |(e, plane): &Key| sources.contains_key(e) && planes.contains(plane);
        let gone: Vec<Key> = self.built.keys().filter(|k| !keep(k)).copied().collect();
        for key in gone {
            if let Some((_, mesh)) = self.built.remove(&key) {
                changed.extend(rect_of(&mesh).map(|r| (key.1, r)));
            }
        }
        self.building.retain(|k, _| keep(k));
        self.failed.retain(|k, _| keep(k));
    }

    /// Starts building the ground of every marked mesh that has none for what it is now.
    fn start_builds(
        &mut self,
        sources: &HashMap<Entity, Source>,
        planes: &HashSet<GroundPlane>,
        modified: &HashSet<AssetId<Mesh>>,
        assets: Option<&Assets<Mesh>>,
    ) {
        for (&entity, source) in sources {
            for &plane in planes {
                let key = (entity, plane);
                let current = |s: &Source| s == source && !modified.contains(&s.mesh);
                let done = self.built.get(&key).is_some_and(|(s, _)| current(s))
                    || self.building.get(&key).is_some_and(|(s, _)| current(s))
                    || self.failed.get(&key).is_some_and(current);
                let Some(mesh) = assets.and_then(|a| a.get(source.mesh)).filter(|_| !done) else {
                    continue;
                };
                let triangles = MeshTriangles::of(mesh);
                let at = GlobalTransform::from(source.transform);
                let task = AsyncComputeTaskPool::get()
                    .spawn(async move { triangles?.place(&at, plane, Some(entity)) });
                self.building.insert(key, (source.clone(), task));
            }
        }
    }

    /// Takes the builds that finished: their old and new rectangles changed.
    fn collect_builds(&mut self, changed: &mut Changed) {
        let finished: Vec<_> = self
            .building
            .extract_if(|_, (_, task)| task.is_finished())
            .collect();
        for (key, (source, task)) in finished {
            // A finished task is ready at its first poll.
            let Some(result) = block_on(future::poll_once(task)) else {
                continue;
            };
            if let Some((_, old)) = self.built.remove(&key) {
                changed.extend(rect_of(&old).map(|r| (key.1, r)));
            }
            match result {
                Ok(mesh) => {
                    changed.extend(rect_of(&mesh).map(|r| (key.1, r)));
                    self.built.insert(key, (source, Arc::new(mesh)));
                }
                Err(why) => {
                    error!("entity {}: its mesh cannot be scatter ground: {why}", key.0);
                    self.failed.insert(key, source);
                }
            }
        }
    }

    /// The ground of a layer on `plane`: every built mesh, in entity order, with whether
    /// the layer grows on it.
    fn ground_for(&self, layer: Entity, plane: GroundPlane) -> SurfaceGround {
        let mut meshes: Vec<(Entity, Arc<SurfaceMesh>, bool)> = self
            .built
            .iter()
            .filter(|((_, p), _)| *p == plane)
            .map(|((e, _), (source, mesh))| (*e, mesh.clone(), source.marker.grows(layer)))
            .collect();
        meshes.sort_by_key(|(e, ..)| *e);
        SurfaceGround::new(meshes.into_iter().map(|(_, m, g)| (m, g)).collect())
    }
}
