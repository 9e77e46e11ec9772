//! The gizmos feature plugin.

use super::{RwtGizmos, draw};
use bevy::prelude::*;

/// Draws chunk and tile bounds with gizmos. Not part of [`crate::RwtPlugin`]: add it for
/// debugging; it needs Bevy's gizmo plugin (part of `DefaultPlugins`).
pub struct RwtGizmosPlugin;

impl Plugin for RwtGizmosPlugin {
    fn build(&self, app: &mut App) {
        app.init_resource::<RwtGizmos>()
            .add_systems(PostUpdate, draw);
    }
}
