//! Impostors: far instances of a class drawn as camera-facing cards (see
//! [`crate::look::Impostor`]).
//!
//! Each class with an impostor has its atlas baked once, on the async compute pool, from the
//! look it shows at the impostor's distance (its far level of detail when that starts
//! nearer): [`bake`] rasterizes the mesh with its material (or an instanced class's
//! shading) from every view on the CPU.
//! [`ImpostorAtlases`] holds the atlases by what they were baked from; the instanced look
//! then draws each chunk's instances of the class as cards (one instanced draw per chunk,
//! culled per instance like any instanced class), and entity instances are only spawned
//! near enough to crossfade with them.

#[cfg(feature = "gltf")]
mod asset;
mod atlas;
pub mod bake;
mod frames;

pub use bake::{BakeError, BakedImpostor, ImpostorFrames};

use crate::layers::{ScatterClass, ScatterLayer};
use crate::look::{ClassLook, Impostor, InstancedShading};
use bevy::asset::RenderAssetUsages;
use bevy::mesh::{Indices, PrimitiveTopology};
use bevy::platform::collections::HashMap;
use bevy::prelude::*;
use bevy::tasks::futures::check_ready;
use bevy::tasks::{AsyncComputeTaskPool, Task};

/// What an atlas is baked from: a mesh, its material or shading, the views.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct ImpostorKey {
    mesh: AssetId<Mesh>,
    look: LookKey,
    views: (u32, u32, u32),
}

/// A class's material, or its instanced shading (by what the bake reads of it).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
enum LookKey {
    Material(AssetId<StandardMaterial>),
    Shading {
        colors: [u32; 8],
        tip_from: u32,
        alpha_cutoff: u32,
        texture: Option<AssetId<Image>>,
    },
    /// An asset class's look: its file and (hashed) root.
    #[cfg(feature = "gltf")]
    Asset {
        gltf: AssetId<bevy::gltf::Gltf>,
        root: u64,
    },
}

/// What a class's impostor is baked from besides its mesh.
enum BakedLook<'a> {
    Material(&'a Handle<StandardMaterial>),
    Shading(&'a InstancedShading),
}

impl BakedLook<'_> {
    fn key(&self) -> LookKey {
        match self {
            BakedLook::Material(m) => LookKey::Material(m.id()),
            BakedLook::Shading(s) => {
                let (base, tip) = (s.base_color.to_linear(), s.tip_color.to_linear());
                let mut colors = [0; 8];
                for (k, c) in base
                    .to_f32_array()
                    .into_iter()
                    .chain(tip.to_f32_array())
                    .enumerate()
                {
                    colors[k] = c.to_bits();
                }
                LookKey::Shading {
                    colors,
                    tip_from: s.tip_from.to_bits(),
                    alpha_cutoff: s.alpha_cutoff.to_bits(),
                    texture: s.texture.as_ref().map(Handle::id),
                }
            }
        }
    }
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
        self.ready(&key_of(class)?)
    }

    /// The atlas baked from `key`, once ready.
    fn ready(&self, key: &ImpostorKey) -> Option<&ImpostorAtlas> {
        match self.atlases.get(key)? {
            Baking::Ready(atlas) => Some(atlas),
            _ => None,
        }
    }

    /// Starts baking `source` with `impostor`'s views as the atlas of `key`.
    fn start(&mut self, key: ImpostorKey, source: OwnedSource, impostor: Impostor) {
        let roughness = source.roughness;
        let task = start_bake(source, impostor);
        self.atlases.insert(key, Baking::Running(task, roughness));
    }

    /// How many atlases became ready so far.
    pub fn generation(&self) -> u64 {
        self.generation
    }
}

/// The mesh and material a class's impostor shows: its far level of detail's when that
/// starts before the impostor, its own otherwise (`None` for classes without an impostor,
/// or whose look is a game's own).
fn baked_look(class: &ScatterClass) -> Option<(&Handle<Mesh>, BakedLook<'_>, &Impostor)> {
    let impostor = class.impostor.as_ref()?;
    Some(match (&class.look, &class.lod) {
        (ClassLook::Mesh { .. }, Some(lod)) if lod.distance < impostor.distance => {
            (&lod.mesh, BakedLook::Material(&lod.material), impostor)
        }
        (ClassLook::Mesh { mesh, material }, _) => (mesh, BakedLook::Material(material), impostor),
        (ClassLook::Instanced(look), _) => {
            let mesh = match &look.far {
                Some(far) if far.distance < impostor.distance => &far.mesh,
                _ => &look.mesh,
            };
            (mesh, BakedLook::Shading(&look.material), impostor)
        }
        (ClassLook::Custom(_), _) => return None,
        #[cfg(feature = "gltf")]
        (ClassLook::Asset(_), _) => return None,
    })
}

fn key_of(class: &ScatterClass) -> Option<ImpostorKey> {
    let (mesh, look, impostor) = baked_look(class)?;
    Some(key(mesh, &look, impostor))
}

/// What an atlas of `mesh` with `look` and `impostor`'s views is baked from.
fn key(mesh: &Handle<Mesh>, look: &BakedLook, impostor: &Impostor) -> ImpostorKey {
    ImpostorKey {
        mesh: mesh.id(),
        look: look.key(),
        views: impostor.clamped(),
    }
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
        let Some((mesh, look, impostor)) = baked_look(class) else {
            continue;
        };
        let key = key(mesh, &look, impostor);
        if atlases.atlases.contains_key(&key) {
            continue;
        }
        let Some(mesh) = meshes.get(mesh) else {
            continue;
        };
        let Some(source) = OwnedSource::of(mesh, &look, &materials, &images) else {
            continue;
        };
        atlases.start(key, source, *impostor);
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

/// What a bake task takes with it: the parts (one, or an asset's primitives), the
/// roughness the cards are lit with.
struct OwnedSource {
    parts: Vec<OwnedPart>,
    roughness: f32,
}

/// A mesh and its look, owned by a bake task.
struct OwnedPart {
    mesh: Mesh,
    color: bake::BakeColor,
    vertex_colors: bool,
    lean: f32,
    texture: Option<Image>,
    alpha_cutoff: Option<f32>,
}

/// A texture's image: `Some(None)` without one, `None` while it loads.
fn loaded_texture(handle: Option<&Handle<Image>>, images: &Assets<Image>) -> Option<Option<Image>> {
    match handle {
        Some(h) => images.get(h).map(|i| Some(i.clone())),
        None => Some(None),
    }
}

impl OwnedSource {
    /// The bake's source for `mesh` with `look`, once its material and texture loaded.
    fn of(
        mesh: &Mesh,
        look: &BakedLook,
        materials: &Assets<StandardMaterial>,
        images: &Assets<Image>,
    ) -> Option<Self> {
        let (part, roughness) = match look {
            BakedLook::Material(handle) => {
                let material = materials.get(*handle)?;
                let part = OwnedPart {
                    mesh: mesh.clone(),
                    color: bake::BakeColor::Plain(material.base_color.to_linear()),
                    vertex_colors: true,
                    lean: 0.0,
                    texture: loaded_texture(material.base_color_texture.as_ref(), images)?,
                    alpha_cutoff: match material.alpha_mode {
                        AlphaMode::Mask(cutoff) => Some(cutoff),
                        _ => None,
                    },
                };
                (part, material.perceptual_roughness)
            }
            BakedLook::Shading(shading) => {
                let part = OwnedPart {
                    mesh: mesh.clone(),
                    color: bake::BakeColor::Gradient {
                        base: shading.base_color.to_linear(),
                        tip: shading.tip_color.to_linear(),
                        tip_from: shading.tip_from,
                    },
                    vertex_colors: false,
                    lean: INSTANCED_LEAN,
                    texture: loaded_texture(shading.texture.as_ref(), images)?,
                    alpha_cutoff: shading.texture.as_ref().map(|_| shading.alpha_cutoff),
                };
                (part, shading.roughness)
            }
        };
        Some(Self {
            parts: vec![part],
            roughness,
        })
    }
}

/// How far the instanced shading leans its normals towards the sky (`instanced.wgsl`).
const INSTANCED_LEAN: f32 = 0.45;

/// A bake of `source` on the async compute pool.
fn start_bake(source: OwnedSource, impostor: Impostor) -> Task<Result<BakedImpostor, BakeError>> {
    AsyncComputeTaskPool::get().spawn(async move {
        let parts: Vec<bake::BakeSource> = source
            .parts
            .iter()
            .map(|p| bake::BakeSource {
                mesh: &p.mesh,
                color: p.color,
                vertex_colors: p.vertex_colors,
                lean: p.lean,
                texture: p.texture.as_ref(),
                alpha_cutoff: p.alpha_cutoff,
            })
            .collect();
        bake::bake_parts(&parts, &impostor)
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
