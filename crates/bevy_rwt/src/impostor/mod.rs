//! Impostors: far instances of a class drawn as camera-facing cards (see
//! [`Impostor`](crate::look::Impostor)).
//!
//! Each class with an impostor has its atlas baked once, on the async compute pool, from the
//! look it shows at the impostor's distance (its far level of detail when that starts
//! nearer): [`bake`] rasterizes the mesh with its material from every view on the CPU.
//! [`ImpostorAtlases`] holds the atlases by what they were baked from; the instanced look
//! then draws each chunk's instances of the class as cards (one instanced draw per chunk,
//! culled per instance like any instanced class), and entity instances are only spawned
//! near enough to crossfade with them.

pub mod bake;

pub use bake::{BakeError, BakedImpostor, ImpostorFrames};

use crate::layers::{ScatterClass, ScatterLayer};
use crate::look::{ClassLook, Impostor};
use bevy::asset::RenderAssetUsages;
use bevy::mesh::{Indices, PrimitiveTopology};
use bevy::platform::collections::HashMap;
use bevy::prelude::*;
use bevy::tasks::futures::check_ready;
use bevy::tasks::{AsyncComputeTaskPool, Task};

/// What an atlas is baked from: a mesh, a material, the views.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct ImpostorKey {
    mesh: AssetId<Mesh>,
    material: AssetId<StandardMaterial>,
    views: (u32, u32, u32),
}

/// A baked atlas, ready to draw: the image, the card every instance draws, and where the
/// views lie.
#[derive(Clone, Debug)]
pub struct ImpostorAtlas {
    /// The atlas (see [`BakedImpostor::image`]).
    pub image: Handle<Image>,
    /// A quad as wide and tall as the views (centred across, at the views' height).
    pub card: Handle<Mesh>,
    /// Where the views lie.
    pub frames: ImpostorFrames,
    /// The material's perceptual roughness.
    pub roughness: f32,
}

/// An atlas on its way.
enum Baking {
    Running(Task<Result<BakedImpostor, BakeError>>, f32),
    Ready(ImpostorAtlas),
    Failed,
}

/// Every class's impostor atlas, by what it was baked from.
#[derive(Resource, Default)]
pub struct ImpostorAtlases {
    atlases: HashMap<ImpostorKey, Baking>,
    /// Bumped whenever an atlas becomes ready (layers showing impostors redraw their chunks).
    generation: u64,
}

impl ImpostorAtlases {
    /// The atlas of `class`, once baked.
    pub fn of(&self, class: &ScatterClass) -> Option<&ImpostorAtlas> {
        match self.atlases.get(&key_of(class)?)? {
            Baking::Ready(atlas) => Some(atlas),
            _ => None,
        }
    }

    /// How many atlases became ready so far.
    pub fn generation(&self) -> u64 {
        self.generation
    }
}

/// The mesh and material a class's impostor shows: its far level of detail's when that
/// starts before the impostor, its own otherwise (`None` for classes without an impostor,
/// or whose look is not a mesh).
fn baked_look(
    class: &ScatterClass,
) -> Option<(&Handle<Mesh>, &Handle<StandardMaterial>, &Impostor)> {
    let impostor = class.impostor.as_ref()?;
    let ClassLook::Mesh { mesh, material } = &class.look else {
        return None;
    };
    Some(match &class.lod {
        Some(lod) if lod.distance < impostor.distance => (&lod.mesh, &lod.material, impostor),
        _ => (mesh, material, impostor),
    })
}

fn key_of(class: &ScatterClass) -> Option<ImpostorKey> {
    let (mesh, material, impostor) = baked_look(class)?;
    Some(ImpostorKey {
        mesh: mesh.id(),
        material: material.id(),
        views: impostor.clamped(),
    })
}

/// Starts a bake for every class with an impostor whose look has loaded, and puts finished
/// atlases in place.
pub(crate) fn bake_impostors(
    layers: Query<&ScatterLayer>,
    mut atlases: ResMut<ImpostorAtlases>,
    meshes: Option<ResMut<Assets<Mesh>>>,
    materials: Option<Res<Assets<StandardMaterial>>>,
    images: Option<ResMut<Assets<Image>>>,
) {
    let (Some(mut meshes), Some(materials), Some(mut images)) = (meshes, materials, images) else {
        return;
    };
    for class in layers.iter().flat_map(|l| l.classes.iter()) {
        let (Some(key), Some((mesh, material, impostor))) = (key_of(class), baked_look(class))
        else {
            continue;
        };
        if atlases.atlases.contains_key(&key) {
            continue;
        }
        let (Some(mesh), Some(material)) = (meshes.get(mesh), materials.get(material)) else {
            continue;
        };
        let texture = match &material.base_color_texture {
            Some(handle) => match images.get(handle) {
                Some(image) => Some(image.clone()),
                None => continue,
            },
            None => None,
        };
        let task = start_bake(mesh.clone(), material, texture, *impostor);
        let roughness = material.perceptual_roughness;
        atlases
            .atlases
            .insert(key, Baking::Running(task, roughness));
    }
    let mut ready = 0;
    for (key, baking) in atlases.atlases.iter_mut() {
        let Baking::Running(task, roughness) = baking else {
            continue;
        };
        let Some(result) = check_ready(task) else {
            continue;
        };
        *baking = match result {
            Ok(baked) => {
                ready += 1;
                Baking::Ready(ImpostorAtlas {
                    card: meshes.add(card(&baked.frames)),
                    image: images.add(baked.image),
                    frames: baked.frames,
                    roughness: *roughness,
                })
            }
            Err(e) => {
                error!("impostor of mesh {:?} not baked: {e}", key.mesh);
                Baking::Failed
            }
        };
    }
    atlases.generation += ready;
}

/// A bake of `mesh` with `material` on the async compute pool.
fn start_bake(
    mesh: Mesh,
    material: &StandardMaterial,
    texture: Option<Image>,
    impostor: Impostor,
) -> Task<Result<BakedImpostor, BakeError>> {
    let base_color = material.base_color.to_linear();
    let alpha_cutoff = match material.alpha_mode {
        AlphaMode::Mask(cutoff) => Some(cutoff),
        _ => None,
    };
    AsyncComputeTaskPool::get().spawn(async move {
        let source = bake::BakeSource {
            mesh: &mesh,
            base_color,
            texture: texture.as_ref(),
            alpha_cutoff,
        };
        bake::bake(&source, &impostor)
    })
}

/// The card every instance draws: a quad of the views' size, x across and y up, standing
/// at the views' centre height, with UVs from its top left.
pub fn card(frames: &ImpostorFrames) -> Mesh {
    let (w, h, cy) = (frames.half.x, frames.half.y, frames.center.y);
    let positions = vec![
        [-w, cy + h, 0.0],
        [w, cy + h, 0.0],
        [w, cy - h, 0.0],
        [-w, cy - h, 0.0],
    ];
    Mesh::new(
        PrimitiveTopology::TriangleList,
        RenderAssetUsages::RENDER_WORLD | RenderAssetUsages::MAIN_WORLD,
    )
    .with_inserted_attribute(Mesh::ATTRIBUTE_POSITION, positions)
    .with_inserted_attribute(Mesh::ATTRIBUTE_NORMAL, vec![[0.0, 0.0, 1.0]; 4])
    .with_inserted_attribute(
        Mesh::ATTRIBUTE_UV_0,
        vec![[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]],
    )
    .with_inserted_indices(Indices::U16(vec![0, 2, 1, 0, 3, 2]))
}
