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
