//! Bevy images over the ground: densities and heightmaps.

use bevy::prelude::*;
use glam::DVec2;
use rwt_core::density::Placement;
use rwt_core::density::{ImageDensity, MAX_IMAGE_PIXELS};

/// Whether a map has more pixels than a density or heightmap is made from.
pub(crate) fn too_large(image: &Image) -> bool {
    image.width() as u64 * image.height() as u64 > MAX_IMAGE_PIXELS
}

/// An image over a ground rectangle, times a scale: the one form of every image the plugin
/// reads (a class's or an exclusion's painted density map, a heightmap, the brush's
/// canvas). The image's luminance times alpha (0..1, bilinear; a transparent texel is
/// empty) covers `min..min + size` on the layer's plane (x, z on the ground of a 3-D world,
/// x, y on a 2-D plane), its top row along the far edge (max z, or max y); a value of 1 is
/// `scale` (instances per square unit for a density, the height for a heightmap).
#[derive(Clone, Debug, PartialEq, Reflect)]
#[reflect(Clone, Debug, PartialEq)]
pub struct GroundMap {
    /// The image.
    pub image: Handle<Image>,
    /// Ground position of the image's bottom-left corner.
    pub min: Vec2,
    /// Ground size of the image.
    pub size: Vec2,
    /// What a white texel means.
    pub scale: f64,
}

impl GroundMap {
    /// Where its values lie, for `rwt_core`.
    pub fn placement(&self) -> Placement {
        Placement {
            min: DVec2::new(self.min.x as f64, self.min.y as f64),
            size: DVec2::new(self.size.x as f64, self.size.y as f64),
            scale: self.scale,
        }
    }

    /// The ground rectangle it covers, when it is finite and not inverted.
    pub fn rect(&self) -> Option<rwt_core::Rect> {
        let at = self.placement();
        rwt_core::Rect::new(at.min, at.min + at.size).ok()
    }

    /// Its density, from its image in `images`; `None` while the image is not loaded, or
    /// when it cannot be read (see [`from_bevy_image`]).
    pub fn density(&self, images: &Assets<Image>) -> Option<ImageDensity> {
        from_bevy_image(images.get(&self.image)?, self.placement())
    }
}

/// The luminance times alpha of a Bevy image (row 0 at the top, as Bevy stores it; a
/// transparent texel is empty) placed `at` (its top row along the max-y edge). `None` for
/// images whose pixels cannot be read on the CPU (compressed formats, GPU-only images) and
/// for images of more than [`MAX_IMAGE_PIXELS`] pixels (a density takes about 16 bytes a
/// pixel).
pub fn from_bevy_image(image: &Image, at: Placement) -> Option<ImageDensity> {
    let (w, h) = (image.width(), image.height());
    if too_large(image) {
        return None;
    }
    let values = luminance_fast(image).or_else(|| {
        let mut values = Vec::with_capacity((w * h) as usize);
        for y in 0..h {
            for x in 0..w {
                values.push(texel_luminance(image, x, y)?);
            }
        }
        Some(values)
    })?;
    ImageDensity::from_values(w, h, &values, at).ok()
}

/// The value a layer reads from texel `(x, y)`: its linear luminance times its alpha, so a
/// transparent texel is an empty one (Bevy reads one-channel formats as an opaque grey, so
/// their value is the channel's); `None` for unreadable texels.
pub(crate) fn texel_luminance(image: &Image, x: u32, y: u32) -> Option<f32> {
    let c = image.get_color_at(x, y).ok()?.to_linear();
    Some((0.2126 * c.red + 0.7152 * c.green + 0.0722 * c.blue) * c.alpha)
}

/// Writes a grey of value `v` (linear) to a texel.
pub(crate) fn set_texel_luminance(image: &mut Image, x: u32, y: u32, v: f32) -> bool {
    image.set_color_at(x, y, Color::linear_rgb(v, v, v)).is_ok()
}

/// Linear luminance times alpha straight from the bytes of the common 8-bit formats (painted
/// maps are re-read on every stroke, so this path matters); `None` for other formats.
fn luminance_fast(image: &Image) -> Option<Vec<f32>> {
    use bevy::render::render_resource::TextureFormat as F;
    let data = image.data.as_ref()?;
    let pixels = (image.width() * image.height()) as usize;
    let srgb: [f32; 256] = std::array::from_fn(|i| {
        let c = i as f32 / 255.0;
        if c <= 0.04045 {
            c / 12.92
        } else {
            ((c + 0.055) / 1.055).powf(2.4)
        }
    });
    let linear: [f32; 256] = std::array::from_fn(|i| i as f32 / 255.0);
    let (channels, table) = match image.texture_descriptor.format {
        F::Rgba8Unorm => (4, &linear),
        F::Rgba8UnormSrgb => (4, &srgb),
        F::R8Unorm => (1, &linear),
        _ => return None,
    };
    if data.len() < pixels * channels {
        return None;
    }
    Some(
        data.chunks_exact(channels)
            .take(pixels)
            .map(|p| {
                if channels == 1 {
                    table[p[0] as usize]
                } else {
                    (0.2126 * table[p[0] as usize]
                        + 0.7152 * table[p[1] as usize]
                        + 0.0722 * table[p[2] as usize])
                        * linear[p[3] as usize]
                }
            })
            .collect(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use bevy::render::render_resource::{Extent3d, TextureDimension, TextureFormat};

    #[test]
    fn fast_path_matches_the_generic_one() {
        for format in [TextureFormat::Rgba8Unorm, TextureFormat::Rgba8UnormSrgb] {
            let mut img = Image::new_fill(
                Extent3d {
                    width: 8,
                    height: 8,
                    depth_or_array_layers: 1,
                },
                TextureDimension::D2,
                &[10, 120, 240, 200],
                format,
                Default::default(),
            );
            img.set_color_at(3, 5, Color::srgb(0.9, 0.1, 0.4)).unwrap();
            img.set_color_at(4, 5, Color::srgba(1.0, 1.0, 1.0, 0.0))
                .unwrap();
            let fast = luminance_fast(&img).unwrap();
            for y in 0..8 {
                for x in 0..8 {
                    let slow = texel_luminance(&img, x, y).unwrap();
                    assert!(
                        (fast[(y * 8 + x) as usize] - slow).abs() < 1e-3,
                        "{format:?} {x} {y}"
                    );
                }
            }
            // A transparent white texel is empty.
            assert_eq!(fast[5 * 8 + 4], 0.0);
            assert_eq!(texel_luminance(&img, 4, 5), Some(0.0));
        }
    }
}
