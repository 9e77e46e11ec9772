//! Cost of turning a painted 1024^2 Bevy image into a density: every repaint of a map pays
//! it (`cargo bench -p bevy_rwt --bench image_convert`).
use bevy::prelude::*;
use bevy::render::render_resource::{Extent3d, TextureDimension, TextureFormat};
fn main() {
    let img = Image::new_fill(
        Extent3d {
            width: 1024,
            height: 1024,
            depth_or_array_layers: 1,
        },
        TextureDimension::D2,
        &[100, 150, 200, 255],
        TextureFormat::Rgba8UnormSrgb,
        Default::default(),
    );
    let t = std::time::Instant::now();
    let at = bevy_rwt::rwt_core::density::Placement {
        min: glam::DVec2::ZERO,
        size: glam::DVec2::splat(100.0),
        scale: 1.0,
    };
    let d = bevy_rwt::layers::from_bevy_image(&img, at).unwrap();
    println!(
        "1024^2 conversion: {:.1} ms ({:?})",
        t.elapsed().as_secs_f64() * 1e3,
        d.dimensions()
    );
}
