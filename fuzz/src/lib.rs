//! The checks behind the fuzz targets. The same files are compiled into the project's tests
//! (`#[path]` modules), which replay every input kept under `fuzz/regressions/`.

pub mod core_checks;
pub mod layer_checks;
