//! Bevy integration for rwt. The plugin itself arrives with its own issue; until then this
//! crate only re-exports the engine-agnostic core so downstream code can depend on one name.

pub use rwt_core;
