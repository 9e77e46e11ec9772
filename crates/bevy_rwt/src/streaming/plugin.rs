//! The streaming feature plugin.

use super::collect::collect_results;
use super::edit::apply_edits;
use super::footprint::{KnownFootprints, track_footprints};
use super::plan::plan_chunks;
use super::repaint::{PaintedRegions, repaint};
use super::spawn::apply_budget;
use super::*;
use crate::edits::EditInstance;
use crate::settings::RwtSystems;
use bevy::ecs::schedule::InternedScheduleLabel;

/// Streams layers around viewers (part of [`crate::RwtPlugin`]).
pub struct RwtStreamingPlugin {
    /// Schedule of the systems.
    pub schedule: InternedScheduleLabel,
    /// The tile set the layers sample.
    pub tile_set: Arc<TileSet>,
}

impl Plugin for RwtStreamingPlugin {
    fn build(&self, app: &mut App) {
        app.insert_resource(RwtTileSet::new(self.tile_set.clone()))
            .init_resource::<PaintedRegions>()
            .init_resource::<KnownFootprints>()
            .add_message::<ChunkLoaded>()
            .add_message::<ChunkUnloaded>()
            .add_message::<DensityMapPainted>()
            .add_message::<EditInstance>()
            .add_observer(on_layer_inserted)
            .add_observer(on_layer_removed)
            .add_systems(
                self.schedule,
                (
                    (repaint, apply_edits, track_footprints, plan_chunks)
                        .chain()
                        .in_set(RwtSystems::Plan),
                    collect_results.in_set(RwtSystems::Collect),
                    apply_budget.in_set(RwtSystems::Apply),
                    update_status.in_set(RwtSystems::Stats),
                ),
            );
    }
}
