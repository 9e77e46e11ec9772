//! The streaming feature plugin.

use super::collect::collect_results;
use super::edit::apply_edits;
use super::footprint::{KnownFootprints, track_footprints};
use super::keep_out::track_keep_out;
use super::plan::plan_chunks;
use super::repaint::{PaintedRegions, repaint};
use super::spawn::apply_budget;
use super::surfaces::{SurfaceMeshes, track_surfaces};
use super::*;
use crate::edits::{ConfirmedEdit, EditAuthority, EditInstance, EditOutcome, ScatterEdits};
use crate::footprints::Footprint;
use crate::instancing::InstancedMeshes;
use crate::layers::ScatterEntity;
use crate::settings::{RwtSystems, configure_sets};
use crate::viewers::Viewers;
use bevy::ecs::schedule::{InternedScheduleLabel, ScheduleLabel};

/// Streams layers around viewers (part of [`crate::RwtPlugins`]). Without
/// [`crate::viewers::RwtViewersPlugin`] nothing streams; without
/// [`crate::layers::RwtLayersPlugin`] layers made in code stream, layer files do not load.
pub struct RwtStreamingPlugin {
    schedule: InternedScheduleLabel,
    tile_set: Option<Arc<TileSet>>,
}

impl RwtStreamingPlugin {
    /// The part, its systems in `schedule`, sampling the shipped tile set.
    pub fn new(schedule: impl ScheduleLabel) -> Self {
        Self {
            schedule: schedule.intern(),
            tile_set: None,
        }
    }

    /// Samples this tile set instead of the shipped one.
    pub fn with_tile_set(mut self, set: Arc<TileSet>) -> Self {
        self.tile_set = Some(set);
        self
    }
}

impl Default for RwtStreamingPlugin {
    fn default() -> Self {
        Self::new(Update)
    }
}

impl Plugin for RwtStreamingPlugin {
    fn build(&self, app: &mut App) {
        configure_sets(app, self.schedule);
        let tile_set = self
            .tile_set
            .clone()
            .unwrap_or_else(|| Arc::new(TileSet::embedded()));
        app.register_type::<ScatterEntity>()
            .register_type::<ScatterEdits>()
            .register_type::<Footprint>()
            .register_type::<crate::KeepOut>()
            .register_type::<crate::ground::ScatterSurface>()
            .register_type::<ChunkLoaded>()
            .register_type::<ChunkUnloaded>()
            .register_type::<DensityMapPainted>()
            .register_type::<EditInstance>()
            .insert_resource(RwtTileSet::new(tile_set))
            .init_resource::<Viewers>()
            .init_resource::<InstancedMeshes>()
            .init_resource::<PaintedRegions>()
            .init_resource::<KnownFootprints>()
            .init_resource::<SurfaceMeshes>()
            .add_message::<ChunkLoaded>()
            .add_message::<ChunkUnloaded>()
            .add_message::<DensityMapPainted>()
            .add_message::<EditInstance>()
            .add_message::<EditOutcome>()
            .add_message::<ConfirmedEdit>()
            .init_resource::<EditAuthority>()
            .register_type::<EditAuthority>()
            .add_observer(on_layer_inserted)
            .add_observer(on_layer_removed)
            .add_systems(
                self.schedule,
                (
                    (
                        restart_changed_layers,
                        repaint,
                        apply_edits,
                        track_footprints,
                        track_surfaces,
                        track_keep_out,
                        plan_chunks,
                    )
                        .chain()
                        .in_set(RwtSystems::Plan),
                    collect_results.in_set(RwtSystems::Collect),
                    apply_budget.in_set(RwtSystems::Apply),
                    update_status.in_set(RwtSystems::Stats),
                ),
            );
    }

    fn finish(&self, app: &mut App) {
        crate::layers::init_image_assets(app);
    }
}
