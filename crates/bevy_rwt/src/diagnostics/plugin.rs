//! The diagnostics feature plugin.

use super::{FrameStart, RwtStats, paths, publish, start_timer, update_stats};
use crate::settings::RwtSystems;
use bevy::diagnostic::{Diagnostic, RegisterDiagnostic};
use bevy::ecs::schedule::InternedScheduleLabel;
use bevy::prelude::*;
use std::time::Instant;

/// Keeps [`RwtStats`] and the `rwt/` diagnostics (part of [`crate::RwtPlugin`]).
pub struct RwtDiagnosticsPlugin {
    /// Schedule of the systems.
    pub schedule: InternedScheduleLabel,
}

impl Plugin for RwtDiagnosticsPlugin {
    fn build(&self, app: &mut App) {
        app.init_resource::<RwtStats>()
            .insert_resource(FrameStart(Instant::now()))
            .add_systems(self.schedule, start_timer.before(RwtSystems::Viewers))
            .add_systems(
                self.schedule,
                (update_stats, publish).chain().after(RwtSystems::Stats),
            );
        for path in paths::ALL {
            app.register_diagnostic(Diagnostic::new(path));
        }
    }
}
