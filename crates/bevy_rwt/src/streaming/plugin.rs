//! The streaming sub-plugin.

use super::*;
use crate::RwtSystems;
use bevy::ecs::schedule::InternedScheduleLabel;

/// Streams layers around viewers (added by [`crate::RwtPlugin`]).
pub struct StreamingPlugin {
    /// Schedule of the systems.
    pub schedule: InternedScheduleLabel,
}

impl Plugin for StreamingPlugin {
    fn build(&self, app: &mut App) {
        let set = Arc::new(TileSet::embedded());
        app.insert_resource(RwtTileSet(set))
            .init_resource::<Viewers>()
            .add_observer(on_layer_inserted)
            .add_observer(on_layer_removed)
            .add_systems(
                self.schedule,
                (
                    (crate::layer_asset::apply_layer_assets, collect_viewers)
                        .in_set(RwtSystems::Viewers),
                    (repaint, plan_chunks).chain().in_set(RwtSystems::Plan),
                    collect_results.in_set(RwtSystems::Collect),
                    apply_budget.in_set(RwtSystems::Apply),
                    update_stats.in_set(RwtSystems::Stats),
                ),
            );
    }

    fn finish(&self, app: &mut App) {
        // Painted maps are `Image` assets; headless apps without the image plugin still get
        // the asset type (registering it twice would duplicate its systems).
        if !app.world().contains_resource::<Assets<Image>>() {
            app.init_asset::<Image>();
        }
        app.init_asset::<crate::layer_asset::ScatterLayerAsset>()
            .register_asset_loader(crate::layer_asset::ScatterLayerLoader);
    }
}
