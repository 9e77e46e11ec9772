//! Files the examples write themselves where the asset server reads them (levels, glTF
//! assets): nothing is downloaded, and a file is written again only when it changed.

use std::path::PathBuf;

/// Writes `bytes` to `relative` under the asset folder (`$BEVY_ASSET_ROOT/assets`, else
/// the workspace's), atomically and only when the file holds something else; returns its
/// path.
pub fn write_asset(relative: &str, bytes: &[u8]) -> PathBuf {
    let root =
        std::env::var("BEVY_ASSET_ROOT").unwrap_or_else(|_| env!("CARGO_MANIFEST_DIR").into());
    let path = std::path::Path::new(&root).join("assets").join(relative);
    if std::fs::read(&path).ok().as_deref() != Some(bytes) {
        std::fs::create_dir_all(path.parent().expect("a folder")).expect("the asset's folder");
        bevy_rwt::rwt_core::files::write_atomic(&path, bytes).expect("the asset is written");
    }
    path
}

/// A leaf-card texture, 64 texels square: white, opaque inside five overlapping discs,
/// clear elsewhere (as a PNG).
pub fn leaf_mask_png() -> Vec<u8> {
    let size = 64;
    let discs = [(32.0, 32.0, 18.0), (16.0, 20.0, 12.0), (48.0, 20.0, 12.0)];
    let more = [(18.0, 46.0, 11.0), (46.0, 46.0, 11.0)];
    let image = image::RgbaImage::from_fn(size, size, |x, y| {
        let (x, y) = (x as f32 + 0.5, y as f32 + 0.5);
        let inside = discs
            .iter()
            .chain(&more)
            .any(|(cx, cy, r)| (x - cx).hypot(y - cy) <= *r);
        image::Rgba([255, 255, 255, if inside { 255 } else { 0 }])
    });
    let mut png = Vec::new();
    image
        .write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
        .expect("a PNG encodes in memory");
    png
}
