//! Bevy images as densities.

use bevy::prelude::*;
use glam::DVec2;
use rwt_core::density::ImageDensity;

/// The luminance of a Bevy image (row 0 at the top, as Bevy stores it) over the ground
/// rectangle `min..min + size` (x, z), times `scale`. `None` for images whose pixels cannot be
/// read on the CPU (compressed formats, GPU-only images).
pub fn from_bevy_image(image: &Image, min: Vec2, size: Vec2, scale: f64) -> Option<ImageDensity> {
    let (w, h) = (image.width(), image.height());
    let mut values = Vec::with_capacity((w * h) as usize);
    for y in 0..h {
        for x in 0..w {
            let c = image.get_color_at(x, y).ok()?.to_linear();
            values.push(0.2126 * c.red + 0.7152 * c.green + 0.0722 * c.blue);
        }
    }
    // rwt's y axis is the ground's z: the image's top row lies along the max-z edge.
    ImageDensity::from_values(
        w,
        h,
        &values,
        DVec2::new(min.x as f64, min.y as f64),
        DVec2::new(size.x as f64, size.y as f64),
        scale,
    )
    .ok()
}
