//! Layers back to layer files: [`LayerDescription::describe`].

use super::{
    AssetDescription, ClassDescription, DensityDescription, HeightDescription,
    InstancedShadingDescription, KeepOutDescription, LAYER_FORMAT, LayerDescription,
    LayerFileError, LayerPart, LodDescription, MapDescription, MaterialDescription,
    MeshDescription, NamedAssets, PromotionDescription, Undescribable,
};
use crate::layers::{HeightSource, LayerDensity, LayerRef, ScatterClass, ScatterLayer};
use crate::look::{ClassLook, MeshLod};
use bevy::prelude::*;

/// The fields of a class description that say how it looks.
struct LookFields {
    mesh: Option<MeshDescription>,
    material: Option<MaterialDescription>,
    lod: Option<LodDescription>,
    asset: Option<AssetDescription>,
}

/// How [`LayerDescription::describe`] names assets.
struct Namer<'a, I> {
    names: &'a NamedAssets,
    image: I,
}

impl LayerDescription {
    /// The layer file of `layer`: what [`LayerDescription::to_layer`] turns back into the
    /// same layer. Meshes, materials and height functions are written by their name in
    /// `names`, else by their asset path; images by `image_path` when it gives one (e.g.
    /// where a painted map was saved), else by their asset path; promotions' inserters by
    /// their name. A layer using what has none of these (a mesh made in code without a
    /// name, a custom density, look or ground, an unnamed inserter, a keep-out) is a
    /// [`LayerFileError::NotDescribable`] naming it: nothing is left out silently.
    pub fn describe(
        layer: &ScatterLayer,
        names: &NamedAssets,
        image_path: impl FnMut(&Handle<Image>) -> Option<String>,
    ) -> Result<Self, LayerFileError> {
        // Every field, so that a new one cannot be forgotten here.
        let ScatterLayer {
            classes,
            tile_size,
            seed,
            lattice,
            streaming,
            falloff,
            plane,
            height,
            surfaces,
            per_area,
            height_range,
            max_slope,
            exclusion,
            keep_out,
        } = layer;
        let mut namer = Namer {
            names,
            image: image_path,
        };
        let classes = classes
            .iter()
            .enumerate()
            .map(|(i, c)| namer.class(c).map_err(|e| not(LayerPart::Class(i), e)))
            .collect::<Result<_, _>>()?;
        let (height, ground) = namer
            .height(height)
            .map_err(|e| not(LayerPart::Ground, e))?;
        let keep_out = keep_out
            .iter()
            .map(|k| match &k.layer {
                LayerRef::Named(name) => Ok(KeepOutDescription {
                    layer: name.clone(),
                    radii: k.radii.clone(),
                }),
                LayerRef::Entity(_) => Err(not(LayerPart::Ground, Undescribable::KeepOut)),
            })
            .collect::<Result<_, _>>()?;
        let exclusion = match exclusion {
            Some(d) => Some(namer.density(d).map_err(|e| not(LayerPart::Exclusion, e))?),
            None => None,
        };
        Ok(Self {
            format: LAYER_FORMAT,
            classes,
            tile_size: *tile_size,
            seed: *seed,
            lattice: Some(*lattice),
            chunk_size: Some(streaming.chunk_size),
            load_distance: Some(streaming.load_distance),
            unload_distance: Some(streaming.unload_distance),
            near_distance: Some(streaming.near_distance),
            falloff: falloff.map(|f| (f.near, f.far)),
            falloff_floor: falloff.map_or(0.0, |f| f.floor),
            plane: *plane,
            height,
            ground,
            surfaces: *surfaces,
            per_area: *per_area,
            height_range: *height_range,
            max_slope: *max_slope,
            exclusion,
            keep_out,
        })
    }
}

fn not(part: LayerPart, what: Undescribable) -> LayerFileError {
    LayerFileError::NotDescribable { part, what }
}

fn asset_path<A: Asset>(handle: &Handle<A>) -> Option<String> {
    handle.path().map(|p| p.to_string())
}

impl<I: FnMut(&Handle<Image>) -> Option<String>> Namer<'_, I> {
    fn class(&mut self, c: &ScatterClass) -> Result<ClassDescription, Undescribable> {
        // Every field, so that a new one cannot be forgotten here.
        let ScatterClass {
            density,
            look,
            scale,
            scale_variation,
            lod,
            pick_bounds,
            promotion,
            stance,
            impostor,
        } = c;
        let LookFields {
            mesh,
            material,
            lod,
            asset,
        } = self.look(look, lod.as_ref())?;
        let promotion = match promotion {
            Some(p) => Some(PromotionDescription {
                distance: p.distance,
                insert: self
                    .names
                    .inserter_name(&p.insert)
                    .ok_or(Undescribable::PromotionInserter)?,
            }),
            None => None,
        };
        Ok(ClassDescription {
            density: self.density(density)?,
            mesh,
            material,
            asset,
            scale: *scale,
            scale_variation: *scale_variation,
            lod,
            stance: *stance,
            pick_bounds: *pick_bounds,
            promotion,
            impostor: *impostor,
        })
    }

    /// A class's look and its far level of detail.
    fn look(
        &mut self,
        look: &ClassLook,
        lod: Option<&MeshLod>,
    ) -> Result<LookFields, Undescribable> {
        let (mesh, material) = match look {
            ClassLook::Mesh { mesh, material } => (self.mesh(mesh)?, self.material(material)?),
            ClassLook::Instanced(look) => {
                let mut material = InstancedShadingDescription::from(&look.material);
                if let Some(texture) = &look.material.texture {
                    material.texture = Some(self.image(texture)?);
                }
                (
                    self.mesh(&look.mesh)?,
                    MaterialDescription::Instanced(material),
                )
            }
            ClassLook::Custom(_) => return Err(Undescribable::CustomLook),
            #[cfg(feature = "gltf")]
            ClassLook::Asset(look) => {
                let file = asset_path(&look.gltf).ok_or(Undescribable::AssetLook)?;
                return Ok(LookFields {
                    mesh: None,
                    material: None,
                    lod: None,
                    asset: Some(AssetDescription::of(look, &file)),
                });
            }
        };
        let far = match look {
            ClassLook::Instanced(look) => look.far.as_ref(),
            _ => None,
        };
        let lod = match (lod, far) {
            (_, Some(far)) => Some(LodDescription {
                mesh: self.mesh(&far.mesh)?,
                material: MaterialDescription::Instanced(InstancedShadingDescription::default()),
                distance: far.distance,
                crossfade: None,
            }),
            (Some(lod), None) => Some(LodDescription {
                mesh: self.mesh(&lod.mesh)?,
                material: self.material(&lod.material)?,
                distance: lod.distance,
                crossfade: Some(lod.crossfade),
            }),
            (None, None) => None,
        };
        Ok(LookFields {
            mesh: Some(mesh),
            material: Some(material),
            lod,
            asset: None,
        })
    }

    fn mesh(&self, mesh: &Handle<Mesh>) -> Result<MeshDescription, Undescribable> {
        if let Some(name) = self.names.mesh_name(mesh) {
            return Ok(MeshDescription::Named(name));
        }
        asset_path(mesh)
            .map(MeshDescription::Path)
            .ok_or(Undescribable::Mesh(mesh.id()))
    }

    fn material(
        &self,
        material: &Handle<StandardMaterial>,
    ) -> Result<MaterialDescription, Undescribable> {
        if let Some(name) = self.names.material_name(material) {
            return Ok(MaterialDescription::Named(name));
        }
        asset_path(material)
            .map(MaterialDescription::Path)
            .ok_or(Undescribable::Material(material.id()))
    }

    fn image(&mut self, image: &Handle<Image>) -> Result<String, Undescribable> {
        (self.image)(image)
            .or_else(|| asset_path(image))
            .ok_or(Undescribable::Image(image.id()))
    }

    fn density(&mut self, d: &LayerDensity) -> Result<DensityDescription, Undescribable> {
        Ok(match d {
            LayerDensity::Constant(v) => DensityDescription::Constant(*v),
            LayerDensity::Noise(n) => DensityDescription::Noise(n.params()),
            LayerDensity::Clumps(c) => DensityDescription::Clumps(c.params()),
            LayerDensity::Image(map) => {
                DensityDescription::Image(MapDescription::of(map, self.image(&map.image)?))
            }
            LayerDensity::Custom(_) => {
                return Err(Undescribable::CustomDensity);
            }
        })
    }

    /// The flat height and the ground description.
    fn height(
        &mut self,
        h: &HeightSource,
    ) -> Result<(f32, Option<HeightDescription>), Undescribable> {
        Ok(match h {
            HeightSource::Constant(h) => (*h, None),
            HeightSource::Function(_) => {
                let name = self
                    .names
                    .height_name(h)
                    .ok_or(Undescribable::HeightFunction)?;
                (0.0, Some(HeightDescription::Named(name)))
            }
            HeightSource::Image(map) => {
                let ground = MapDescription::of(map, self.image(&map.image)?);
                (0.0, Some(HeightDescription::Image(ground)))
            }
            HeightSource::Surfaces => (0.0, Some(HeightDescription::Surfaces)),
            HeightSource::Custom(_) => return Err(Undescribable::CustomGround),
        })
    }
}
