//! The check behind the `layer_file` fuzz target. The same file is compiled into bevy_rwt's
//! tests (a `#[path]` module), which replay every input kept under
//! `fuzz/regressions/layer_file/`.

pub mod layer_checks;
