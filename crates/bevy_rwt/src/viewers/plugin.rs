//! The viewers feature plugin.

use super::{Viewers, collect_viewers};
use crate::settings::{RwtSystems, configure_sets, in_schedule};
use bevy::ecs::schedule::InternedScheduleLabel;
use bevy::prelude::*;

/// Lays every [`super::RwtViewer`] on the ground each frame (part of [`crate::RwtPlugins`]).
pub struct RwtViewersPlugin {
    schedule: InternedScheduleLabel,
}

in_schedule!(RwtViewersPlugin);

impl Plugin for RwtViewersPlugin {
    fn build(&self, app: &mut App) {
        configure_sets(app, self.schedule);
        app.register_type::<super::RwtViewer>()
            .init_resource::<Viewers>()
            .add_systems(self.schedule, collect_viewers.in_set(RwtSystems::Viewers));
    }
}
