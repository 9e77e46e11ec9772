//! The surface of an asset's primitive as the instanced renderer draws it: glTF's
//! metallic-roughness material (base colour, normal map, metallic and roughness, emissive,
//! occlusion, alpha cut-out, double-sided), lit by Bevy's PBR lighting. Whatever else a
//! material asks for is refused with a [`SurfaceError`] rather than drawn wrong.

use bevy::prelude::*;

/// How a surface treats its base colour's alpha.
#[derive(Clone, Copy, Debug, Default, PartialEq, Reflect)]
#[reflect(Clone, Debug, Default, PartialEq)]
pub enum SurfaceAlpha {
    /// Alpha is ignored: the surface is whole.
    #[default]
    Opaque,
    /// Fragments whose alpha is below the cut-off are cut out, in every pass (leaf cards).
    Mask(f32),
}

/// One primitive's material, drawn instanced: glTF's core material, its textures read at
/// the mesh's first UV coordinates; the mesh's vertex colours, when it has them, multiply
/// the base colour.
#[derive(Clone, Debug, PartialEq, Reflect)]
#[reflect(Clone, Debug, Default, PartialEq)]
pub struct InstancedSurface {
    /// Base colour factor (its alpha is the cut-out's with [`SurfaceAlpha::Mask`]).
    pub base_color: Color,
    /// Base colour texture (sRGB), multiplied by the factor.
    pub base_color_texture: Option<Handle<Image>>,
    /// Tangent-space normal map (needs the mesh's tangents).
    pub normal_map: Option<Handle<Image>>,
    /// Metallic factor, 0..1.
    pub metallic: f32,
    /// Perceptual roughness factor, 0..1.
    pub perceptual_roughness: f32,
    /// Roughness in green, metallic in blue, multiplied by the factors.
    pub metallic_roughness_texture: Option<Handle<Image>>,
    /// Specular intensity of non-metals, 0..1 (0.5 is 4 % reflectance).
    pub reflectance: f32,
    /// Light emitted (linear).
    pub emissive: LinearRgba,
    /// Emissive texture, multiplied by `emissive`.
    pub emissive_texture: Option<Handle<Image>>,
    /// Ambient occlusion in red.
    pub occlusion_texture: Option<Handle<Image>>,
    /// How alpha is read.
    pub alpha: SurfaceAlpha,
    /// Whether both sides are drawn (the back's normal turned round).
    pub double_sided: bool,
}

impl Default for InstancedSurface {
    fn default() -> Self {
        Self {
            base_color: Color::WHITE,
            base_color_texture: None,
            normal_map: None,
            metallic: 0.0,
            perceptual_roughness: 0.5,
            metallic_roughness_texture: None,
            reflectance: 0.5,
            emissive: LinearRgba::BLACK,
            emissive_texture: None,
            occlusion_texture: None,
            alpha: SurfaceAlpha::Opaque,
            double_sided: false,
        }
    }
}

impl InstancedSurface {
    /// Whether any texture is read (the mesh then needs UVs).
    pub fn textured(&self) -> bool {
        self.textures().iter().any(Option::is_some)
    }

    /// The textures, in binding order: base colour, normal map, metallic-roughness,
    /// emissive, occlusion.
    pub fn textures(&self) -> [Option<&Handle<Image>>; 5] {
        [
            self.base_color_texture.as_ref(),
            self.normal_map.as_ref(),
            self.metallic_roughness_texture.as_ref(),
            self.emissive_texture.as_ref(),
            self.occlusion_texture.as_ref(),
        ]
    }

    /// The alpha below which fragments are cut out (below every alpha when opaque).
    pub fn alpha_cutoff(&self) -> f32 {
        match self.alpha {
            SurfaceAlpha::Opaque => -1.0,
            SurfaceAlpha::Mask(cutoff) => cutoff,
        }
    }
}

/// Why a material cannot be drawn instanced. The class is refused with it (logged, its
/// instances not drawn) rather than drawn wrong.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum SurfaceError {
    /// Blended alpha needs sorting back to front, which chunks of instances are not.
    #[error("alpha mode {0} is not drawn instanced (only Opaque and Mask are)")]
    AlphaMode(String),
    /// A texture read at other UV coordinates than the first.
    #[error("the {0} texture reads UV channel 1; instanced surfaces read UV channel 0")]
    SecondUvChannel(&'static str),
    /// A texture transform (`KHR_texture_transform`).
    #[error("the material transforms its UV coordinates; instanced surfaces do not")]
    UvTransform,
    /// A material extension the instanced surface does not draw.
    #[error("the material uses {0}, which instanced surfaces do not draw")]
    Extension(&'static str),
}

#[cfg(feature = "gltf")]
mod from_gltf {
    use super::{InstancedSurface, SurfaceAlpha, SurfaceError};
    use bevy::gltf::GltfMaterial;
    use bevy::math::Affine2;
    use bevy::mesh::UvChannel;
    use bevy::prelude::*;

    impl TryFrom<&GltfMaterial> for InstancedSurface {
        type Error = SurfaceError;

        fn try_from(m: &GltfMaterial) -> Result<Self, SurfaceError> {
            let alpha = match m.alpha_mode {
                AlphaMode::Opaque => SurfaceAlpha::Opaque,
                AlphaMode::Mask(cutoff) => SurfaceAlpha::Mask(cutoff),
                other => return Err(SurfaceError::AlphaMode(format!("{other:?}"))),
            };
            for (name, channel) in [
                ("base colour", &m.base_color_channel),
                ("normal", &m.normal_map_channel),
                ("metallic-roughness", &m.metallic_roughness_channel),
                ("emissive", &m.emissive_channel),
                ("occlusion", &m.occlusion_channel),
            ] {
                if *channel != UvChannel::Uv0 {
                    return Err(SurfaceError::SecondUvChannel(name));
                }
            }
            if m.uv_transform != Affine2::IDENTITY {
                return Err(SurfaceError::UvTransform);
            }
            for (name, used) in [
                ("transmission", m.specular_transmission > 0.0),
                ("clearcoat", m.clearcoat > 0.0),
                ("anisotropy", m.anisotropy_strength > 0.0),
                ("unlit shading", m.unlit),
            ] {
                if used {
                    return Err(SurfaceError::Extension(name));
                }
            }
            Ok(Self {
                base_color: m.base_color,
                base_color_texture: m.base_color_texture.clone(),
                normal_map: m.normal_map_texture.clone(),
                metallic: m.metallic,
                perceptual_roughness: m.perceptual_roughness,
                metallic_roughness_texture: m.metallic_roughness_texture.clone(),
                reflectance: m.reflectance,
                emissive: m.emissive,
                emissive_texture: m.emissive_texture.clone(),
                occlusion_texture: m.occlusion_texture.clone(),
                alpha,
                double_sided: m.double_sided,
            })
        }
    }

    #[cfg(test)]
    mod tests {
        use super::*;

        #[test]
        fn glb_materials_become_surfaces_or_typed_errors() {
            let leaves = GltfMaterial {
                base_color: Color::srgb(0.2, 0.5, 0.1),
                alpha_mode: AlphaMode::Mask(0.4),
                double_sided: true,
                metallic: 0.25,
                ..default()
            };
            let s = InstancedSurface::try_from(&leaves).unwrap();
            assert_eq!(s.alpha, SurfaceAlpha::Mask(0.4));
            assert_eq!(s.alpha_cutoff(), 0.4);
            assert!(s.double_sided && !s.textured());
            assert_eq!((s.metallic, s.base_color), (0.25, leaves.base_color));

            let glass = GltfMaterial {
                alpha_mode: AlphaMode::Blend,
                ..default()
            };
            assert_eq!(
                InstancedSurface::try_from(&glass),
                Err(SurfaceError::AlphaMode("Blend".into()))
            );
            let second_uv = GltfMaterial {
                occlusion_channel: UvChannel::Uv1,
                ..default()
            };
            assert_eq!(
                InstancedSurface::try_from(&second_uv),
                Err(SurfaceError::SecondUvChannel("occlusion"))
            );
            let coat = GltfMaterial {
                clearcoat: 1.0,
                ..default()
            };
            assert_eq!(
                InstancedSurface::try_from(&coat),
                Err(SurfaceError::Extension("clearcoat"))
            );
            let opaque = InstancedSurface::try_from(&GltfMaterial::default()).unwrap();
            assert!(opaque.alpha_cutoff() < 0.0 && !opaque.double_sided);
        }
    }
}
