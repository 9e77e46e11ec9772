//! The entity look: one entity per instance (a shared mesh and material, or a game's own
//! components), spawned and despawned within per-frame budgets, chunk by chunk in the order
//! the chunks finished generating. Streaming hands this look each chunk's points; which
//! entities appear, stay or go is decided here, by point identity: existing instances never
//! move.

use crate::ground::GroundRule;
use crate::layers::{ScatterEntity, ScatterLayer};
use crate::look::ClassLook;
use bevy::camera::visibility::VisibilityRange;
use bevy::platform::collections::{HashMap, HashSet};
use bevy::prelude::*;
use rwt_core::query::{Point, PointId};
use rwt_core::streaming::{ChunkCoord, Viewer, diff_instances};
use std::collections::VecDeque;

/// A chunk's entity instances.
#[derive(Default)]
struct EntityChunk {
    /// Spawned instances by identity, with their class.
    spawned: HashMap<PointId, (Entity, u16)>,
    /// Points generated but not yet spawned (waiting for the spawn budget).
    queued: Vec<Point>,
    /// Whether the chunk is in the spawn order.
    in_order: bool,
    /// The points of classes drawn far as impostors, spawned only while the chunk is near.
    impostors: Vec<Point>,
    /// Whether the chunk is near enough for its impostor classes' entities.
    near: bool,
}

/// Which classes of a layer are drawn far as impostors, and within what ground distance of
/// a viewer a chunk spawns their entities: where a camera may see the meshes, up to the end
/// of their crossfade with the impostors.
pub(crate) struct ImpostorReach {
    classes: Vec<bool>,
    reach: f64,
}

impl ImpostorReach {
    /// A chunk near once stays so until this factor past the reach.
    const HYSTERESIS: f64 = 1.1;

    /// The reach of `layer`'s impostor classes (`None` when it has none).
    pub fn of(layer: &ScatterLayer) -> Option<Self> {
        let bands = layer.classes.iter().map(|c| c.impostor.map(|i| i.band().1));
        let reach = bands.clone().flatten().fold(f32::NAN, f32::max);
        (!reach.is_nan()).then(|| Self {
            classes: bands.map(|b| b.is_some()).collect(),
            reach: reach as f64,
        })
    }

    /// Whether entities of `class` are held back in far chunks.
    fn holds(&self, class: u16) -> bool {
        self.classes.get(class as usize).copied().unwrap_or(false)
    }

    /// Whether a chunk `distance` from the nearest viewer is near, given whether it was.
    fn near(&self, distance: f64, was: bool) -> bool {
        distance <= self.reach * if was { Self::HYSTERESIS } else { 1.0 }
    }
}

/// A layer's entity instances: what each chunk shows and is about to show, the order in
/// which chunks spawn, and the instances waiting to be despawned.
#[derive(Default)]
pub(crate) struct EntityQueue {
    chunks: HashMap<ChunkCoord, EntityChunk>,
    /// Chunks with queued points, in the order they finished (unloaded ones are skipped).
    spawn_order: VecDeque<ChunkCoord>,
    despawn: VecDeque<Entity>,
}

/// What spawning a layer's instances needs.
pub(crate) struct Spawner<'a> {
    /// The layer entity.
    pub entity: Entity,
    pub layer: &'a ScatterLayer,
    /// The ground the layer's chunks are generated on.
    pub ground: &'a GroundRule,
}

impl EntityQueue {
    /// Shows `points` in `chunk`: vanished or re-classed instances go to the despawn queue,
    /// new points wait for the spawn budget; the others stay as they are.
    pub fn show(
        &mut self,
        chunk: ChunkCoord,
        mut points: Vec<Point>,
        reach: Option<&ImpostorReach>,
    ) {
        let c = self.chunks.entry(chunk).or_default();
        if let Some(reach) = reach {
            c.impostors = points
                .iter()
                .filter(|p| reach.holds(p.class))
                .copied()
                .collect();
            if !c.near {
                points.retain(|p| !reach.holds(p.class));
            }
        }
        // Compare with what the chunk shows or is about to show.
        let spawned = c.spawned.iter().map(|(id, (_, class))| (*id, *class));
        let queued = c.queued.iter().map(|p| (p.id, p.class));
        let diff = diff_instances(spawned.chain(queued), &points);
        if !diff.removed.is_empty() {
            let removed: HashSet<PointId> = diff.removed.iter().copied().collect();
            c.queued.retain(|p| !removed.contains(&p.id));
            for id in &diff.removed {
                if let Some((e, _)) = c.spawned.remove(id) {
                    self.despawn.push_back(e);
                }
            }
        }
        c.queued.extend(diff.added);
        if !c.queued.is_empty() && !c.in_order {
            c.in_order = true;
            self.spawn_order.push_back(chunk);
        }
    }

    /// Spawns the impostor classes' entities of chunks that came within `reach` of a
    /// viewer, and despawns those of chunks that left it.
    pub fn follow_viewers(&mut self, reach: &ImpostorReach, size: f64, viewers: &[Viewer]) {
        for (chunk, c) in self.chunks.iter_mut() {
            let near = reach.near(chunk.viewer_distance(size, viewers), c.near);
            if near == c.near {
                continue;
            }
            c.near = near;
            if near {
                let shown = |p: &&Point| !c.spawned.contains_key(&p.id);
                let points: Vec<Point> = c.impostors.iter().filter(shown).copied().collect();
                c.queued.extend(points);
                if !c.queued.is_empty() && !c.in_order {
                    c.in_order = true;
                    self.spawn_order.push_back(*chunk);
                }
            } else {
                c.queued.retain(|p| !reach.holds(p.class));
                let despawn = &mut self.despawn;
                c.spawned.retain(|_, (e, class)| {
                    let held = reach.holds(*class);
                    if held {
                        despawn.push_back(*e);
                    }
                    !held
                });
            }
        }
    }

    /// Puts the instances of `chunk` that `points` keep (same identity and class) where
    /// they stand now: the ground under them changed.
    pub fn replace_kept(
        &self,
        commands: &mut Commands,
        spawner: &Spawner,
        chunk: ChunkCoord,
        points: &[Point],
    ) {
        let Some(c) = self.chunks.get(&chunk) else {
            return;
        };
        for p in points {
            if let Some((e, class)) = c.spawned.get(&p.id)
                && *class == p.class
            {
                let at = spawner.layer.place(p, spawner.ground);
                commands.entity(*e).try_insert(at);
            }
        }
    }

    /// Forgets a chunk that unloaded: its instances go to the despawn queue, its queued
    /// points with it (its place in the spawn order is skipped later).
    pub fn unload(&mut self, chunk: ChunkCoord) {
        if let Some(c) = self.chunks.remove(&chunk) {
            self.despawn.extend(c.spawned.values().map(|(e, _)| *e));
        }
    }

    /// Takes point `id` of `chunk` away now, whatever the budget (an edit removed it);
    /// returns whether this look showed it or was about to.
    pub fn remove_now(&mut self, commands: &mut Commands, chunk: ChunkCoord, id: &PointId) -> bool {
        let Some(c) = self.chunks.get_mut(&chunk) else {
            return false;
        };
        c.impostors.retain(|p| p.id != *id);
        if let Some((e, _)) = c.spawned.remove(id) {
            commands.entity(e).try_despawn();
            return true;
        }
        let queued = c.queued.len();
        c.queued.retain(|p| p.id != *id);
        c.queued.len() != queued
    }

    /// Spawns `p` now (an edit gave it another entity class) in place of the instance of
    /// its point, which is despawned; returns whether this look showed the point or was
    /// about to (otherwise nothing changes).
    pub fn reclass_now(
        &mut self,
        commands: &mut Commands,
        spawner: &Spawner,
        chunk: ChunkCoord,
        p: &Point,
    ) -> bool {
        if !self.remove_now(commands, chunk, &p.id) {
            return false;
        }
        let c = self.chunks.entry(chunk).or_default();
        if ImpostorReach::of(spawner.layer).is_some_and(|r| r.holds(p.class)) {
            c.impostors.push(*p);
            if !c.near {
                return true;
            }
        }
        let e = spawn_instance(commands, spawner, p);
        c.spawned.insert(p.id, (e, p.class));
        true
    }

    /// Instances alive: those the chunks hold, plus those waiting in the despawn queue
    /// (still in the world until their turn comes).
    pub fn live(&self) -> usize {
        self.chunks.values().map(|c| c.spawned.len()).sum::<usize>() + self.despawn.len()
    }

    /// Points waiting for the spawn budget.
    pub fn queued(&self) -> usize {
        self.chunks.values().map(|c| c.queued.len()).sum()
    }

    /// Despawns every instance placed or about to be removed.
    pub fn despawn_all(&self, commands: &mut Commands) {
        let placed = self.chunks.values().flat_map(|c| c.spawned.values());
        for e in placed.map(|(e, _)| *e).chain(self.despawn.iter().copied()) {
            commands.entity(e).try_despawn();
        }
    }

    /// Despawns queued instances, oldest first, while the budget lasts.
    pub fn despawn_queued(&mut self, commands: &mut Commands, budget: &mut usize) {
        while *budget > 0 {
            let Some(e) = self.despawn.pop_front() else {
                break;
            };
            commands.entity(e).try_despawn();
            *budget -= 1;
        }
    }

    /// Spawns queued points chunk by chunk, in the order their chunks finished, while the
    /// budget lasts.
    pub fn spawn_queued(&mut self, commands: &mut Commands, spawner: &Spawner, budget: &mut usize) {
        while *budget > 0 {
            let Some(&chunk) = self.spawn_order.front() else {
                break;
            };
            let Some(c) = self.chunks.get_mut(&chunk) else {
                // Unloaded while waiting.
                self.spawn_order.pop_front();
                continue;
            };
            while *budget > 0 {
                let Some(p) = c.queued.pop() else { break };
                let e = spawn_instance(commands, spawner, &p);
                c.spawned.insert(p.id, (e, p.class));
                *budget -= 1;
            }
            if c.queued.is_empty() {
                c.in_order = false;
                self.spawn_order.pop_front();
            }
        }
    }
}

/// Spawns one instance: the class's look placed on the ground by [`ScatterLayer::place`].
fn spawn_instance(commands: &mut Commands, spawner: &Spawner, p: &Point) -> Entity {
    let layer = spawner.layer;
    let class = &layer.classes[(p.class as usize).min(layer.classes.len().saturating_sub(1))];
    let transform = layer.place(p, spawner.ground);
    let instance = ScatterEntity {
        layer: spawner.entity,
        id: p.id,
        class: p.class,
    };
    // One bundle for the common case: an insert after the spawn would move every instance
    // to a second archetype.
    // Drawn as an impostor from its band on: the mesh fades out over it (a far level of
    // detail that would start later is never seen).
    let band = class.impostor.map(|i| i.band());
    let lod = class
        .lod
        .as_ref()
        .filter(|l| class.impostor.is_none_or(|i| l.distance < i.distance));
    match (&class.look, lod) {
        (ClassLook::Mesh { mesh, material }, None) => {
            let look = (
                instance,
                Mesh3d(mesh.clone()),
                MeshMaterial3d(material.clone()),
                transform,
            );
            match band {
                Some((start, end)) => commands.spawn((
                    look,
                    VisibilityRange {
                        start_margin: 0.0..0.0,
                        end_margin: start..end,
                        use_aabb: false,
                    },
                )),
                None => commands.spawn(look),
            }
            .id()
        }
        (ClassLook::Mesh { mesh, material }, Some(lod)) => {
            let (near, far) = lod.ranges(band);
            commands
                .spawn((
                    instance,
                    Mesh3d(mesh.clone()),
                    MeshMaterial3d(material.clone()),
                    transform,
                    near,
                    children![(
                        Mesh3d(lod.mesh.clone()),
                        MeshMaterial3d(lod.material.clone()),
                        far,
                    )],
                ))
                .id()
        }
        (ClassLook::Custom(insert), _) => {
            let mut custom = commands.spawn((instance, transform));
            insert(&mut custom);
            custom.id()
        }
        // Packed in the generation task instead; never queued for spawning.
        (ClassLook::Instanced(_), _) => commands.spawn((instance, transform)).id(),
        #[cfg(feature = "gltf")]
        (ClassLook::Asset(_), _) => commands.spawn((instance, transform)).id(),
    }
}
