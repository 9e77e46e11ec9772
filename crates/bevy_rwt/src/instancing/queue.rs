//! The instanced look's side of streaming: each chunk's instance buffers (packed in its
//! generation task) wait for the upload budget, then go to one [`InstancedChunk`] entity per
//! (chunk, class), spawned when new, updated in place, despawned when empty or unloaded.
//! Instances of a promoted class near a viewer are held by entities instead
//! ([`super::promote`]); the chunk's buffer draws the others.

use super::chunk::{ImpostorDraw, InstanceBuffer, InstancedChunk};
use super::mesh::InstancedMeshes;
use super::pack::{self, PackedClass};
use crate::impostor::{ImpostorAtlas, ImpostorAtlases};
use crate::layers::ScatterClass;
use crate::layers::ScatterLayer;
use crate::look::ClassLook;
use crate::look::{InstancedLook, InstancedShading, InstancedShadows};
use bevy::camera::primitives::Aabb;
use bevy::platform::collections::HashMap;
use bevy::prelude::*;
use rwt_core::query::PointId;
use rwt_core::streaming::ChunkCoord;
use std::collections::VecDeque;
use std::sync::Arc;

/// A chunk's instances of one class.
pub(super) struct ClassBuffer {
    /// The entities drawing the instances that are not promoted: one per part of the
    /// class's look (one for an instanced class, one per primitive of an asset's level);
    /// none when no instance is left, or the class is drawn as entities.
    pub parts: Vec<Entity>,
    /// The entity drawing them as impostors, for a class with an impostor once its atlas is
    /// baked.
    pub impostor: Option<Entity>,
    /// The instances as generated, promoted ones included.
    pub whole: Arc<InstanceBuffer>,
    /// Promoted instances and the entities that hold them.
    pub promoted: HashMap<PointId, Entity>,
}

/// A chunk's instanced classes.
#[derive(Default)]
pub(super) struct ChunkBuffers {
    pub classes: HashMap<u16, ClassBuffer>,
    /// Buffers generated but not yet handed over.
    waiting: Vec<PackedClass>,
    /// Whether the chunk is in the upload order.
    in_order: bool,
}

/// A layer's instanced chunks: what each chunk draws and is about to draw.
#[derive(Default)]
pub(crate) struct InstancedQueue {
    pub(super) chunks: HashMap<ChunkCoord, ChunkBuffers>,
    /// Chunks with buffers to hand over, in the order they finished.
    upload_order: VecDeque<ChunkCoord>,
    /// Entities of unloaded chunks (chunk entities, promoted instances): despawned at once,
    /// whatever the budget.
    retired: Vec<Entity>,
    /// [`Upload::generation`] when impostor and asset chunks were last drawn.
    generation_seen: (u64, u64),
}

impl ClassBuffer {
    /// Every entity it holds.
    fn entities(&self) -> impl Iterator<Item = Entity> + '_ {
        self.parts
            .iter()
            .copied()
            .chain(self.impostor)
            .chain(self.promoted.values().copied())
    }
}

impl InstancedQueue {
    /// Shows `packed` in `chunk` once the upload budget lets it (replacing what is waiting).
    pub fn show(&mut self, chunk: ChunkCoord, packed: Vec<PackedClass>) {
        if packed.is_empty() {
            return;
        }
        let c = self.chunks.entry(chunk).or_default();
        c.waiting = packed;
        if !c.in_order {
            c.in_order = true;
            self.upload_order.push_back(chunk);
        }
    }

    /// Forgets a chunk that unloaded: its entities are retired.
    pub fn unload(&mut self, chunk: ChunkCoord) {
        if let Some(c) = self.chunks.remove(&chunk) {
            let entities = c.classes.values().flat_map(ClassBuffer::entities);
            self.retired.extend(entities);
        }
    }

    /// Takes a promoted instance of `chunk` away now (an edit removed it); returns whether
    /// one was there. Instances in buffers are left to the chunk's regeneration.
    pub fn remove_now(&mut self, commands: &mut Commands, chunk: ChunkCoord, id: &PointId) -> bool {
        let Some(c) = self.chunks.get_mut(&chunk) else {
            return false;
        };
        for class in c.classes.values_mut() {
            if let Some(e) = class.promoted.remove(id) {
                commands.entity(e).try_despawn();
                class.whole = Arc::new(without(&class.whole, |i| i == id));
                return true;
            }
        }
        false
    }

    /// Instances of the layer's instanced classes (promoted ones included).
    pub fn live(&self) -> usize {
        let per_chunk = |c: &ChunkBuffers| -> usize {
            c.classes.values().map(|b| b.whole.instances.len()).sum()
        };
        self.chunks.values().map(per_chunk).sum()
    }

    /// Promoted instances.
    pub fn promoted(&self) -> usize {
        let per_chunk =
            |c: &ChunkBuffers| -> usize { c.classes.values().map(|b| b.promoted.len()).sum() };
        self.chunks.values().map(per_chunk).sum()
    }

    /// Instances waiting for the upload budget.
    pub fn queued(&self) -> usize {
        let waiting = |c: &ChunkBuffers| -> usize {
            c.waiting.iter().map(|p| p.buffer.instances.len()).sum()
        };
        self.chunks.values().map(waiting).sum()
    }

    /// Despawns every entity: chunk entities, promoted instances, retired ones.
    pub fn despawn_all(&self, commands: &mut Commands) {
        let held = self.chunks.values().flat_map(|c| c.classes.values());
        let held = held.flat_map(ClassBuffer::entities);
        for e in held.chain(self.retired.iter().copied()) {
            commands.entity(e).try_despawn();
        }
    }

    /// Despawns the entities of unloaded chunks.
    pub fn despawn_retired(&mut self, commands: &mut Commands) {
        for e in self.retired.drain(..) {
            commands.entity(e).try_despawn();
        }
    }
}

/// `buffer` without the instances whose identity `drop` says (identities are kept for the
/// classes this is used on).
pub(super) fn without(buffer: &InstanceBuffer, drop: impl Fn(&PointId) -> bool) -> InstanceBuffer {
    let (instances, ids): (Vec<_>, Vec<_>) = buffer
        .instances
        .iter()
        .zip(&buffer.ids)
        .filter(|(_, id)| !drop(id))
        .map(|(g, id)| (*g, *id))
        .unzip();
    InstanceBuffer {
        bounds: pack::bounds(&instances),
        instances,
        ids,
    }
}

/// The per-frame hand-over of instance buffers to chunk entities, shared by all layers.
pub(crate) struct Upload<'a> {
    /// Instances that may still be handed over this frame.
    budget: usize,
    meshes: Option<&'a Assets<Mesh>>,
    /// Mesh bounds, checked once per mesh.
    checked: &'a mut InstancedMeshes,
    /// Whether no chunk was handed over yet this frame (one always is).
    first: bool,
    /// The impostor atlases baked so far.
    impostors: Option<&'a ImpostorAtlases>,
    /// The asset classes' looks resolved so far.
    #[cfg(feature = "gltf")]
    assets: Option<&'a super::assets::ResolvedAssets>,
}

/// A layer's chunk: where buffers of its classes go.
#[derive(Clone, Copy)]
pub(super) struct Target<'a> {
    pub entity: Entity,
    pub layer: &'a ScatterLayer,
    pub chunk: ChunkCoord,
}

/// What a frame's hand-over reads: the meshes and their checks, the baked impostor
/// atlases, the resolved assets.
#[derive(bevy::ecs::system::SystemParam)]
pub(crate) struct UploadSources<'w> {
    meshes: Option<Res<'w, Assets<Mesh>>>,
    checked: ResMut<'w, InstancedMeshes>,
    impostors: Option<Res<'w, ImpostorAtlases>>,
    #[cfg(feature = "gltf")]
    assets: Option<Res<'w, super::assets::ResolvedAssets>>,
}

impl UploadSources<'_> {
    /// A frame's hand-over of up to `budget` instances (at least one chunk).
    pub fn upload(&mut self, budget: usize) -> Upload<'_> {
        Upload {
            budget,
            meshes: self.meshes.as_deref(),
            checked: &mut self.checked,
            first: true,
            impostors: self.impostors.as_deref(),
            #[cfg(feature = "gltf")]
            assets: self.assets.as_deref(),
        }
    }
}

impl<'a> Upload<'a> {
    /// What the chunks of classes drawn from baked or loaded assets were last drawn with:
    /// impostor atlases' and resolved assets' generations.
    fn generation(&self) -> (u64, u64) {
        let impostors = self.impostors.map_or(0, ImpostorAtlases::generation);
        #[cfg(feature = "gltf")]
        let assets = self.assets.map_or(0, |a| a.generation());
        #[cfg(not(feature = "gltf"))]
        let assets = 0;
        (impostors, assets)
    }

    /// Draws again the impostor and asset classes of every chunk when atlases were baked or
    /// assets resolved since the queue last looked (chunks handed over before drew nothing).
    pub fn refresh_classes(
        &mut self,
        commands: &mut Commands,
        entity: Entity,
        layer: &ScatterLayer,
        queue: &mut InstancedQueue,
    ) {
        let generation = self.generation();
        let seen = std::mem::replace(&mut queue.generation_seen, generation);
        if seen == generation {
            return;
        }
        let assets_changed = seen.1 != generation.1;
        for (chunk, c) in queue.chunks.iter_mut() {
            let target = Target {
                entity,
                layer,
                chunk: *chunk,
            };
            for (class, buffer) in c.classes.iter_mut() {
                let Some(c) = layer.classes.get(*class as usize) else {
                    continue;
                };
                let asset = c.look.is_asset();
                if asset && assets_changed {
                    // Promoted instances show the asset as it was: promoted again as it is.
                    for (_, e) in buffer.promoted.drain() {
                        commands.entity(e).try_despawn();
                    }
                }
                if asset || c.impostor.is_some() {
                    self.redraw(commands, target, *class, buffer);
                }
            }
        }
    }

    /// Whether instances of `class` may be promoted: its look is ready to draw them (an
    /// asset class once its file is resolved).
    pub(super) fn promotes(&self, layer: &ScatterLayer, class: u16) -> bool {
        match layer.classes.get(class as usize).map(|c| &c.look) {
            #[cfg(feature = "gltf")]
            Some(ClassLook::Asset(look)) => self.assets.and_then(|a| a.ready(look)).is_some(),
            Some(_) => true,
            None => false,
        }
    }

    /// Hands a layer's waiting buffers over, chunk by chunk in the order they finished.
    pub fn chunks(
        &mut self,
        commands: &mut Commands,
        entity: Entity,
        layer: &ScatterLayer,
        queue: &mut InstancedQueue,
    ) {
        while let Some(&chunk) = queue.upload_order.front() {
            let Some(c) = queue.chunks.get_mut(&chunk) else {
                // Unloaded while waiting.
                queue.upload_order.pop_front();
                continue;
            };
            let count: usize = c.waiting.iter().map(|p| p.buffer.instances.len()).sum();
            if count > self.budget && !self.first {
                break;
            }
            self.budget = self.budget.saturating_sub(count);
            self.first = false;
            queue.upload_order.pop_front();
            c.in_order = false;
            let target = Target {
                entity,
                layer,
                chunk,
            };
            for packed in std::mem::take(&mut c.waiting) {
                let slot = c.classes.remove(&packed.class);
                if let Some(class) = self.hand_over(commands, target, slot, packed) {
                    c.classes.insert(class.0, class.1);
                }
            }
        }
    }

    /// Puts one class's new buffer in place: promoted instances still in it stay promoted,
    /// the others go; the rest is drawn by the class's chunk entity.
    fn hand_over(
        &mut self,
        commands: &mut Commands,
        target: Target,
        slot: Option<ClassBuffer>,
        packed: PackedClass,
    ) -> Option<(u16, ClassBuffer)> {
        let (parts, impostor, mut promoted) = slot
            .map_or((Vec::new(), None, HashMap::new()), |s| {
                (s.parts, s.impostor, s.promoted)
            });
        // Promoted instances that are no longer in the buffer go (only promoted classes
        // have any).
        if !promoted.is_empty() {
            let kept: std::collections::HashSet<&PointId> = packed.buffer.ids.iter().collect();
            promoted.retain(|id, e| {
                let keep = kept.contains(id);
                if !keep {
                    commands.entity(*e).try_despawn();
                }
                keep
            });
        }
        let mut class = ClassBuffer {
            parts,
            impostor,
            whole: packed.buffer,
            promoted,
        };
        self.redraw(commands, target, packed.class, &mut class);
        (!class.whole.instances.is_empty()).then_some((packed.class, class))
    }

    /// Draws the class's instances that are not promoted with its chunk entity (spawned,
    /// updated, or despawned when none is left).
    pub(super) fn redraw(
        &mut self,
        commands: &mut Commands,
        target: Target,
        class: u16,
        buffer: &mut ClassBuffer,
    ) {
        let drawn = if buffer.promoted.is_empty() {
            buffer.whole.clone()
        } else {
            Arc::new(without(&buffer.whole, |id| {
                buffer.promoted.contains_key(id)
            }))
        };
        let (parts, impostor) = match drawn.instances.is_empty() {
            true => (Vec::new(), None),
            false => (
                self.parts(target, class, drawn.clone()),
                self.impostor_component(target, class, drawn),
            ),
        };
        place_all(commands, target, &mut buffer.parts, parts);
        place(commands, target, &mut buffer.impostor, impostor);
    }

    /// The component drawing `buffer` of a class of the target's layer as impostors, with
    /// its bounds (`None` when the class has none, or its atlas is not baked yet).
    fn impostor_component(
        &mut self,
        target: Target,
        class: u16,
        buffer: Arc<InstanceBuffer>,
    ) -> Option<(InstancedChunk, Aabb)> {
        let c = target.layer.classes.get(class as usize)?;
        let atlas = self.atlas(c)?;
        let component = impostor_chunk(target, class, c, atlas, buffer);
        let aabb = component.aabb(self.checked.bounds(&atlas.card, self.meshes));
        Some((component, aabb))
    }

    /// The impostor atlas of a class, once baked (an asset class's once resolved).
    fn atlas(&self, c: &ScatterClass) -> Option<&'a ImpostorAtlas> {
        let atlases = self.impostors?;
        match &c.look {
            #[cfg(feature = "gltf")]
            ClassLook::Asset(look) => {
                atlases.of_asset(look, self.assets?.ready(look)?, c.impostor.as_ref()?)
            }
            _ => atlases.of(c),
        }
    }

    /// The components drawing `buffer` of a class of the target's layer, with their bounds:
    /// one for an instanced class, one per primitive for an asset class once resolved, none
    /// for other classes.
    pub(super) fn parts(
        &mut self,
        target: Target,
        class: u16,
        buffer: Arc<InstanceBuffer>,
    ) -> Vec<(InstancedChunk, Aabb)> {
        let Some(c) = target.layer.classes.get(class as usize) else {
            return Vec::new();
        };
        match &c.look {
            ClassLook::Instanced(look) => vec![self.instanced(target, class, look, buffer)],
            #[cfg(feature = "gltf")]
            ClassLook::Asset(look) => match self.assets.and_then(|a| a.ready(look)) {
                Some(asset) => {
                    // Where its impostors are drawn, the last level fades out into them.
                    let impostor = c.impostor.filter(|_| self.atlas(c).is_some());
                    asset_parts(target, class, (look, asset, impostor), buffer)
                }
                None => Vec::new(),
            },
            _ => Vec::new(),
        }
    }

    /// The collider a promoted instance of `class` gets from its asset (`None`: not an
    /// asset class, not resolved yet, or a class that asks for none).
    #[cfg(feature = "gltf")]
    pub(super) fn asset_collider(
        &self,
        target: Target,
        class: u16,
    ) -> Option<crate::look::asset::AssetCollider> {
        let c = target.layer.classes.get(class as usize)?;
        let ClassLook::Asset(look) = &c.look else {
            return None;
        };
        let asset = self.assets?.ready(look).filter(|_| look.collider)?;
        Some(asset.collider())
    }

    /// The component drawing `buffer` of an instanced class, with its bounds.
    fn instanced(
        &mut self,
        target: Target,
        class: u16,
        look: &InstancedLook,
        buffer: Arc<InstanceBuffer>,
    ) -> (InstancedChunk, Aabb) {
        let layer = target.layer;
        let c = &layer.classes[class as usize];
        // Where its impostors are drawn, the meshes fade out as they fade in.
        let fade_out = c
            .impostor
            .filter(|_| self.atlas(c).is_some())
            .map(|i| i.band());
        let mesh_bounds = self.checked.bounds(&look.mesh, self.meshes);
        let meshes = (look.mesh.clone(), look.far.clone());
        let far_per_instance = self.checked.far_as_tall(&meshes, self.meshes);
        let component = InstancedChunk {
            layer: target.entity,
            chunk: target.chunk,
            class,
            mesh: look.mesh.clone(),
            meshes,
            far_per_instance,
            material: look.material.clone(),
            mesh_top: mesh_bounds.1.y.max(1e-3),
            max_scale: c.scale * (1.0 + c.scale_variation.abs()),
            falloff: layer_falloff(layer),
            buffer,
            impostor: None,
            fade_out,
            fade_in: None,
            surface: None,
        };
        let aabb = component.aabb(self.checked.class_bounds(&component.meshes, self.meshes));
        (component, aabb)
    }
}

/// The components drawing `buffer` of an asset class: one per primitive of each level,
/// each level fading in where the one before hands over and out where the next takes over
/// (the last where its `impostor` takes over, if it has one drawn), each part bounded by
/// the whole asset (its top is the wind's and the fade's height).
#[cfg(feature = "gltf")]
fn asset_parts(
    target: Target,
    class: u16,
    (look, asset, impostor): (
        &crate::look::asset::AssetLook,
        &crate::look::asset::ResolvedAsset,
        Option<crate::look::Impostor>,
    ),
    buffer: Arc<InstanceBuffer>,
) -> Vec<(InstancedChunk, Aabb)> {
    let c = &target.layer.classes[class as usize];
    let switches = look
        .lods
        .switches(asset.levels.len(), asset.bounds, &asset.coverage);
    let last = asset.levels.len() - 1;
    let band = |level: usize| match switches.get(level) {
        Some(d) => Some(look.lods.band(*d)),
        None if level == last => impostor.map(|i| i.band()),
        None => None,
    };
    let parts = asset.levels.iter().enumerate().flat_map(|(level, parts)| {
        let fades = (level.checked_sub(1).and_then(band), band(level));
        parts.iter().map(move |part| (part, fades))
    });
    parts
        .map(|(part, (fade_in, fade_out))| {
            let component = InstancedChunk {
                layer: target.entity,
                chunk: target.chunk,
                class,
                mesh: part.mesh.clone(),
                meshes: (part.mesh.clone(), None),
                far_per_instance: false,
                material: look.shading(&part.surface),
                surface: Some(part.surface.clone()),
                mesh_top: asset.bounds.1.y.max(1e-3),
                max_scale: c.scale * (1.0 + c.scale_variation.abs()),
                falloff: layer_falloff(target.layer),
                buffer: buffer.clone(),
                impostor: None,
                fade_out,
                fade_in,
            };
            let aabb = component.aabb(asset.bounds);
            (component, aabb)
        })
        .collect()
}

/// The layer's level-of-detail fall-off as chunk components carry it.
fn layer_falloff(layer: &ScatterLayer) -> Option<(f32, f32, f32)> {
    layer
        .falloff
        .map(|f| (f.near as f32, f.far as f32, f.floor as f32))
}

/// The chunk drawing the class's instances in `buffer` as impostors of `atlas`: lit cards,
/// still in the wind, casting no shadow, varied in colour as the class's meshes are.
fn impostor_chunk(
    target: Target,
    class: u16,
    c: &ScatterClass,
    atlas: &ImpostorAtlas,
    buffer: Arc<InstanceBuffer>,
) -> InstancedChunk {
    let frames = atlas.frames;
    let color_variation = match &c.look {
        ClassLook::Instanced(look) => look.material.color_variation,
        #[cfg(feature = "gltf")]
        ClassLook::Asset(look) => look.color_variation,
        _ => 0.0,
    };
    let material = InstancedShading {
        base_color: Color::WHITE,
        tip_color: Color::WHITE,
        color_variation,
        roughness: atlas.roughness,
        wind_response: 0.0,
        tip_from: 0.0,
        shadows: InstancedShadows::Off,
        texture: Some(atlas.image.clone()),
        bend_response: 0.0,
        thinning: None,
        ..default()
    };
    let band = c.impostor.map_or((0.0, 0.0), |i| i.band());
    InstancedChunk {
        layer: target.entity,
        chunk: target.chunk,
        class,
        mesh: atlas.card.clone(),
        meshes: (atlas.card.clone(), None),
        far_per_instance: false,
        material,
        mesh_top: (frames.center.y + frames.half.y).max(1e-3),
        max_scale: c.scale * (1.0 + c.scale_variation.abs()),
        falloff: layer_falloff(target.layer),
        buffer,
        impostor: Some(ImpostorDraw { frames, band }),
        surface: None,
        fade_in: None,
        fade_out: None,
    }
}

/// Puts each of `components` on a chunk entity of `slots` (spawned where there are more
/// components than entities, despawned where there are fewer).
fn place_all(
    commands: &mut Commands,
    target: Target,
    slots: &mut Vec<Entity>,
    components: Vec<(InstancedChunk, Aabb)>,
) {
    let mut old = std::mem::take(slots).into_iter();
    for component in components {
        let mut slot = old.next();
        place(commands, target, &mut slot, Some(component));
        slots.extend(slot);
    }
    for e in old {
        commands.entity(e).try_despawn();
    }
}

/// Puts `component` on the chunk entity in `slot`: spawned at the chunk's corner, updated,
/// or despawned when there is none.
fn place(
    commands: &mut Commands,
    target: Target,
    slot: &mut Option<Entity>,
    component: Option<(InstancedChunk, Aabb)>,
) {
    match (component, *slot) {
        (Some(bundle), Some(e)) => {
            commands.entity(e).insert(bundle);
        }
        (Some(bundle), None) => {
            let corner = target.chunk.rect(target.layer.streaming.chunk_size).min();
            let transform = Transform::from_xyz(corner.x as f32, 0.0, corner.y as f32);
            *slot = Some(commands.spawn((bundle, transform)).id());
        }
        (None, Some(e)) => {
            commands.entity(e).try_despawn();
            *slot = None;
        }
        (None, None) => {}
    }
}
