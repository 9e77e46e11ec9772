//! The plugin's headless integration tests, one module per feature, in one test binary
//! (one link of Bevy instead of one per file). `soak.rs` and `fuzz_regressions.rs` stay
//! binaries of their own: the soak measures the process's memory.

mod common;

#[cfg(feature = "gltf")]
mod assets;
#[cfg(feature = "brush")]
mod brush;
mod edits;
mod footprints;
mod gizmos;
mod ground;
mod impostors;
mod instanced;
mod keep_out;
mod layer_files;
mod painting;
mod picking;
#[cfg(feature = "brush")]
mod plugins;
mod promotion;
#[cfg(feature = "brush")]
mod reflection;
mod save;
mod streaming;
