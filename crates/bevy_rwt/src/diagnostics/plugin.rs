//! The diagnostics feature plugin.

use super::{FrameStart, RwtStats, paths, publish, start_timer, update_stats};
use crate::settings::{RwtSystems, configure_sets, in_schedule};
use bevy::diagnostic::{Diagnostic, RegisterDiagnostic};
use bevy::ecs::schedule::InternedScheduleLabel;
use bevy::platform::time::Instant;
use bevy::prelude::*;

/// Keeps [`RwtStats`] and the `rwt/` diagnostics (part of [`crate::RwtPlugins`]).
pub struct RwtDiagnosticsPlugin {
    schedule: InternedScheduleLabel,
}

in_schedule!(RwtDiagnosticsPlugin);

impl Plugin for RwtDiagnosticsPlugin {
    fn build(&self, app: &mut App) {
        configure_sets(app, self.schedule);
        app.register_type::<RwtStats>()
            .init_resource::<RwtStats>()
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
