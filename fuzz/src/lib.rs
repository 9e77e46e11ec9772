//! The checks behind the core fuzz targets. The same file is compiled into rwt_core's tests
//! (a `#[path]` module), which replay every input kept under `fuzz/regressions/`.

pub mod core_checks;
