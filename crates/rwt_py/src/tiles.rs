//! The tile set a call uses: the embedded one (prepared once per process) or a file.

use crate::errors::tileset_error;
use pyo3::PyResult;
use rwt_core::query::Sampler;
use rwt_core::tileset::TileSet;
use std::path::Path;
use std::sync::OnceLock;

/// The embedded tile set, parsed once.
pub fn embedded() -> &'static TileSet {
    static SET: OnceLock<TileSet> = OnceLock::new();
    SET.get_or_init(TileSet::embedded)
}

/// A sampler for `seed` over the tile set at `path`, or over the embedded set (whose
/// prepared tiles are shared by every call).
pub fn sampler(path: Option<&Path>, seed: u64) -> PyResult<Sampler> {
    static EMBEDDED: OnceLock<Sampler> = OnceLock::new();
    Ok(match path {
        None => EMBEDDED
            .get_or_init(|| Sampler::new(embedded(), 0))
            .clone()
            .with_seed(seed),
        Some(path) => Sampler::new(&load(path)?, seed),
    })
}

/// Reads a tile set file (built by `rwt tileset build`).
pub fn load(path: &Path) -> PyResult<TileSet> {
    TileSet::read_file(path).map_err(|e| tileset_error(path, e))
}
