//! The viewers feature plugin.

use super::{Viewers, collect_viewers};
use crate::settings::RwtSystems;
use bevy::ecs::schedule::InternedScheduleLabel;
use bevy::prelude::*;

/// Lays every [`super::RwtViewer`] on the ground each frame (part of [`crate::RwtPlugin`]).
pub struct RwtViewersPlugin {
    /// Schedule of the systems.
    pub schedule: InternedScheduleLabel,
}

impl Plugin for RwtViewersPlugin {
    fn build(&self, app: &mut App) {
        app.init_resource::<Viewers>()
            .add_systems(self.schedule, collect_viewers.in_set(RwtSystems::Viewers));
    }
}
