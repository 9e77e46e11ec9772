//! The gizmos feature plugin.

use super::{RwtGizmos, draw};
use bevy::prelude::*;

/// Draws chunk and tile bounds with gizmos in `PostUpdate`. Part of [`crate::RwtPlugins`],
/// disabled there: enable it for debugging; it needs Bevy's gizmo plugin (part of
/// `DefaultPlugins`).
pub struct RwtGizmosPlugin;

impl Plugin for RwtGizmosPlugin {
    fn build(&self, app: &mut App) {
        app.register_type::<RwtGizmos>()
            .init_resource::<RwtGizmos>()
            .add_systems(PostUpdate, draw);
    }
}
