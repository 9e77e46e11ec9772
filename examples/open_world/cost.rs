//! `RWT_COST=1` (with a scripted session, `RWT_SCREENSHOT`): once the script has settled in
//! its view, times the frame drawn by the direct path (`InstanceCulling::PerChunk`: chunks
//! drawn whole, no occlusion), culled per instance on the GPU with occlusion (the camera's
//! `OcclusionCulling`, as open_world runs), and drawn whole by a camera that keeps Bevy's
//! occlusion for its own meshes, prints one line each and the ratios:
//!
//! `open-world-cost: view=V cull=whole live=N main_ms=X/Y render_world_ms=X/Y frame_ms=X/Y`
//! `open-world-cost: view=V cull=occlusion live=N main_ms=X/Y render_world_ms=X/Y frame_ms=X/Y`
//! `open-world-cost: view=V cull=whole_occluding live=N main_ms=X/Y render_world_ms=X/Y frame_ms=X/Y`
//! `open-world-cost: ratio occlusion/whole frame_ms=R render_world_ms=R rounds=R1,R2,..`
//! `open-world-cost: ratio occlusion/whole_occluding frame_ms=R render_world_ms=R`
//!
//! The last ratio is what rwt's culling itself costs and saves where a game's camera
//! occludes anyway: the render world's difference from `whole` is Bevy's occlusion plus
//! rwt's culling, from `whole_occluding` rwt's culling alone.
//!
//! The settings take turns, [`ROUNDS`] times [`TIMED`] frames each after a few to warm up,
//! so that a slow minute of the machine weighs on all alike: each line is the median/p95 of
//! a setting's frames over every round (`rwt_examples::frame_clock` says what each time
//! covers), the ratios those medians', and `rounds` each round's frame ratio of the first
//! two. The screenshot is taken after, of the culled frame.

use crate::script::ScriptSystems;
use bevy::prelude::*;
use bevy::render::occlusion_culling::OcclusionCulling;
use bevy_rwt::prelude::*;
use rwt_examples::frame_clock::{FrameClock, FrameClockPlugin, FrameTimes};
use rwt_examples::prelude::*;

/// Frames run after the first change of setting, before timing (pipelines compile).
const FIRST_WARM_UP: u32 = 15;
/// Frames run after each later change of setting, before timing.
const WARM_UP: u32 = 4;
/// Frames timed per setting and round.
const TIMED: usize = 8;
/// Turns each setting takes.
const ROUNDS: usize = 4;

/// The settings timed, in turn: name, culling, whether the camera occludes.
const SETTINGS: [(&str, InstanceCulling, bool); 3] = [
    ("whole", InstanceCulling::PerChunk, false),
    ("occlusion", InstanceCulling::PerInstance, true),
    ("whole_occluding", InstanceCulling::PerChunk, true),
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

/// Where the timing is: waiting for the script, timing turn `turn` (setting `turn %
/// SETTINGS.len()`) with the frames since it was applied, or done; and the frames so far.
#[derive(Resource, Default)]
struct Cost {
    timing: Option<(usize, u32)>,
    done: bool,
    /// Per setting, its timed frames over every round.
    frames: [Vec<[f64; 3]>; SETTINGS.len()],
    /// Per round, the culled frame's median over the frame drawn whole's.
    rounds: Vec<f64>,
}

/// Starts once nothing holds the script's screenshot and streaming has settled; holds the
/// screenshot until every setting is timed.
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
    let Some((turn, frames)) = cost.timing else {
        if !report.hold && stats.pending_tasks == 0 {
            apply(0, &cameras, &mut commands);
            cost.timing = Some((0, 0));
        }
        report.hold = true;
        return;
    };
    report.hold = true;
    let frames = frames + 1;
    cost.timing = Some((turn, frames));
    let warm_up = if turn < SETTINGS.len() {
        FIRST_WARM_UP
    } else {
        WARM_UP
    };
    clock.record(frames > warm_up);
    if clock.recorded() < TIMED {
        return;
    }
    let setting = turn % SETTINGS.len();
    let timed = clock.take_frames();
    if setting == 1 {
        let whole = FrameTimes::of(&cost.frames[0][cost.frames[0].len() - TIMED..]);
        cost.rounds
            .push(FrameTimes::of(&timed).frame.median / whole.frame.median);
    }
    cost.frames[setting].extend(timed);
    if turn + 1 < ROUNDS * SETTINGS.len() {
        apply((turn + 1) % SETTINGS.len(), &cameras, &mut commands);
        cost.timing = Some((turn + 1, 0));
        return;
    }
    report_times(&cost, live.0 + live.1);
    cost.done = true;
    report.hold = false;
}

/// Prints the result lines.
fn report_times(cost: &Cost, live: usize) {
    let view = std::env::var("RWT_VIEW").unwrap_or_else(|_| "eye".into());
    let times = cost.frames.each_ref().map(|f| FrameTimes::of(f));
    for ((name, ..), times) in SETTINGS.iter().zip(&times) {
        println!("open-world-cost: view={view} cull={name} live={live} {times}");
    }
    let [whole, culled, whole_occluding] = &times;
    let rounds: Vec<String> = cost.rounds.iter().map(|r| format!("{r:.2}")).collect();
    println!(
        "open-world-cost: ratio occlusion/whole frame_ms={:.2} render_world_ms={:.2} rounds={}",
        culled.frame.median / whole.frame.median,
        culled.render_world.median / whole.render_world.median,
        rounds.join(",")
    );
    println!(
        "open-world-cost: ratio occlusion/whole_occluding frame_ms={:.2} render_world_ms={:.2}",
        culled.frame.median / whole_occluding.frame.median,
        culled.render_world.median / whole_occluding.render_world.median,
    );
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
