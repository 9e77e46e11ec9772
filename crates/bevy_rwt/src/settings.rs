//! What every feature plugin shares: the budgets and the system sets.

use bevy::ecs::schedule::InternedScheduleLabel;
use bevy::prelude::*;

/// Budgets of the streaming systems.
#[derive(Resource, Clone, Debug, Reflect)]
#[reflect(Resource, Clone, Debug, Default)]
pub struct RwtSettings {
    /// Most instances spawned per frame (all layers).
    pub spawn_budget: usize,
    /// Most instances despawned per frame (all layers).
    pub despawn_budget: usize,
    /// Most instances of instanced classes handed to their chunk entities per frame (all
    /// layers; at least one chunk per frame whatever its size).
    pub upload_budget: usize,
    /// Keep each instanced chunk's point identities beside its buffer
    /// ([`crate::instancing::InstanceBuffer::ids`]): for tests and tools, 24 bytes per instance.
    pub keep_instance_ids: bool,
    /// Most chunk generation tasks in flight per layer.
    pub max_tasks_in_flight: usize,
    /// Most points one chunk's query may produce (its entities, or its instance buffers at
    /// 24 bytes each), estimated before it runs: a chunk over it is not generated, is
    /// counted in [`crate::ScatterLayerStatus::refused_chunks`], and the layer logs why once.
    pub chunk_point_budget: usize,
    /// Length of the view wedge drawn from a viewer on the ground.
    pub footprint_reach: f64,
}

impl Default for RwtSettings {
    fn default() -> Self {
        Self {
            spawn_budget: 5_000,
            despawn_budget: 10_000,
            upload_budget: 1_000_000,
            keep_instance_ids: false,
            max_tasks_in_flight: 8,
            chunk_point_budget: 4_000_000,
            footprint_reach: 1.0e4,
        }
    }
}

/// The plugin's system sets, in order; each feature plugin adds its systems to one.
#[derive(SystemSet, Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum RwtSystems {
    /// Viewers to ground positions; layer files to layers.
    Viewers,
    /// Chunk planning and task start.
    Plan,
    /// Finished tasks to spawn and despawn queues.
    Collect,
    /// Budgeted spawning and despawning.
    Apply,
    /// Each layer's [`crate::ScatterLayerStatus`] (the plugin-wide [`crate::RwtStats`] are
    /// summed right after).
    Stats,
}

/// Orders the [`RwtSystems`] sets in `schedule` and gives the app default settings when it
/// has none: every part of [`crate::RwtPlugins`] calls it, so that each works alone.
pub(crate) fn configure_sets(app: &mut App, schedule: InternedScheduleLabel) {
    app.register_type::<RwtSettings>()
        .init_resource::<RwtSettings>()
        .configure_sets(
            schedule,
            (
                RwtSystems::Viewers,
                RwtSystems::Plan,
                RwtSystems::Collect,
                RwtSystems::Apply,
                RwtSystems::Stats,
            )
                .chain(),
        );
}

/// `new(schedule)` and `Default` (in `Update`) for a part of [`crate::RwtPlugins`] whose
/// only setting is the schedule of its systems.
macro_rules! in_schedule {
    ($part:ident) => {
        impl $part {
            /// The part, its systems in `schedule`.
            pub fn new(schedule: impl bevy::ecs::schedule::ScheduleLabel) -> Self {
                Self {
                    schedule: bevy::ecs::schedule::ScheduleLabel::intern(&schedule),
                }
            }
        }

        impl Default for $part {
            fn default() -> Self {
                Self::new(bevy::prelude::Update)
            }
        }
    };
}
pub(crate) use in_schedule;
