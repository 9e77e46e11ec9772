//! `RWT_COST=1` (with a scripted session, `RWT_SCREENSHOT`): once the script has settled in
//! its view, times the frame drawn by the direct path (`InstanceCulling::PerChunk`: chunks
//! drawn whole, no occlusion), then culled per instance on the GPU with occlusion (the
//! camera's `OcclusionCulling`, as open_world runs), prints one line each and the ratios:
//!
//! `open-world-cost: view=V cull=whole live=N main_ms=X/Y render_world_ms=X/Y frame_ms=X/Y`
//! `open-world-cost: view=V cull=occlusion live=N main_ms=X/Y render_world_ms=X/Y frame_ms=X/Y`
//! `open-world-cost: ratio occlusion/whole frame_ms=R render_world_ms=R`
//!
//! (median/p95 of 30 frames after 15 to warm up; `rwt_examples::frame_clock` says what each
//! time covers). The screenshot is taken after, of the culled frame.

use crate::script::ScriptSystems;
use bevy::prelude::*;
use bevy::render::occlusion_culling::OcclusionCulling;
use bevy_rwt::prelude::*;
use rwt_examples::frame_clock::{FrameClock, FrameClockPlugin, FrameTimes};
use rwt_examples::prelude::*;

/// Frames run after each change of setting, before timing.
const WARM_UP: u32 = 15;
/// Frames timed per setting.
const TIMED: usize = 30;

/// The settings timed, in order: name, culling, whether the camera occludes.
const SETTINGS: [(&str, InstanceCulling, bool); 2] = [
    ("whole", InstanceCulling::PerChunk, false),
    ("occlusion", InstanceCulling::PerInstance, true),
];

/// Whether the environment asks for the timing (`RWT_COST` set, not `0`).
pub fn requested() -> bool {
    std::env::var("RWT_COST").is_ok_and(|v| v != "0")
}

/// Times the settings when [`requested`] (the app disables pipelined rendering then).
pub struct CostPlugin;

impl Plugin for CostPlugin {
    fn build(&self, app: &mut App) {
        if !requested() {
            return;
        }
        app.add_plugins(FrameClockPlugin)
            .init_resource::<Cost>()
            .add_systems(
                Update,
                time_settings
                    .after(ScriptSystems)
                    .run_if(|s: Res<Smoke>| s.active()),
            );
    }
}

/// Where the timing is: waiting for the script, timing a setting (frames since it was
/// applied), or done; and the times so far.
#[derive(Resource, Default)]
struct Cost {
    timing: Option<(usize, u32)>,
    done: bool,
    times: Vec<FrameTimes>,
}

/// Starts once nothing holds the script's screenshot and streaming has settled; holds the
/// screenshot until every setting is timed.
#[allow(clippy::too_many_arguments)]
fn time_settings(
    mut cost: ResMut<Cost>,
    clock: Res<FrameClock>,
    mut report: ResMut<SmokeReport>,
    stats: Res<RwtStats>,
    live: Res<LiveInstances>,
    cameras: Query<Entity, With<FlyCamera>>,
    mut commands: Commands,
) {
    if cost.done {
        return;
    }
    let Some((setting, frames)) = cost.timing else {
        if !report.hold && stats.pending_tasks == 0 {
            apply(0, &cameras, &mut commands);
            cost.timing = Some((0, 0));
        }
        report.hold = true;
        return;
    };
    report.hold = true;
    let frames = frames + 1;
    cost.timing = Some((setting, frames));
    clock.record(frames > WARM_UP);
    if clock.recorded() < TIMED {
        return;
    }
    let times = clock.take();
    println!(
        "open-world-cost: view={} cull={} live={} {times}",
        std::env::var("RWT_VIEW").unwrap_or_else(|_| "eye".into()),
        SETTINGS[setting].0,
        live.0 + live.1
    );
    cost.times.push(times);
    if setting + 1 < SETTINGS.len() {
        apply(setting + 1, &cameras, &mut commands);
        cost.timing = Some((setting + 1, 0));
        return;
    }
    if let [whole, culled] = cost.times[..] {
        println!(
            "open-world-cost: ratio occlusion/whole frame_ms={:.2} render_world_ms={:.2}",
            culled.frame.median / whole.frame.median,
            culled.render_world.median / whole.render_world.median
        );
    }
    cost.done = true;
    report.hold = false;
}

/// Sets the culling of setting `i` and gives the camera occlusion or takes it away.
fn apply(i: usize, cameras: &Query<Entity, With<FlyCamera>>, commands: &mut Commands) {
    let (_, culling, occludes) = SETTINGS[i];
    commands.insert_resource(culling);
    for camera in cameras {
        if occludes {
            commands.entity(camera).insert(OcclusionCulling);
        } else {
            commands.entity(camera).remove::<OcclusionCulling>();
        }
    }
}
