//! Occlusion in culling per instance, checked in a real renderer (`scripts/smoke.sh` runs
//! it under Xvfb and lavapipe): `cargo run --example gpu_occlusion`.
//!
//! A field of grass around a hill, no wind, a camera with Bevy's `DepthPrepass` and
//! `OcclusionCulling`, and a low sun behind it with `OcclusionCulling` too (its cascade
//! culls the casters its depth hides: the hill hides part of the field from it). The camera
//! waits low behind the hill, where the hill hides the field beyond it, then rises in one
//! frame to look over it: that frame's early phase still tests against the depth seen from
//! below, which hid the field, so everything it now shows, down to the blades whose tips
//! peek over the crest, must be kept by the late phase.
//!
//! The rising frame is taken twice: with chunks drawn whole
//! ([`InstanceCulling::PerChunk`], no occlusion), then culled per instance with occlusion,
//! and [`CullingCheck`] reads back that frame's counts. While chunks are drawn whole, Bevy's
//! pipeline statistics (`RenderDiagnosticsPlugin`; lavapipe has them) count the vertices
//! the camera's late prepass shades: a chunk drawn whole was all drawn by the early
//! prepass, so none. It prints `rwt-occlusion: draws D occluding O instances N kept G (gpu)
//! C (frustum) late L, cascade draws S occluded H, pixel difference P, pixels differing X,
//! late prepass vertices V (drawn whole)` and exits with an error unless the two frames
//! match (`MOST_DIFFERENCE`, `MOST_PIXELS`), occlusion dropped instances, the late phase
//! kept some, the sun's cascade occluded some, no draw kept more than the frustum alone
//! keeps, and the late prepass shaded no vertex of chunks drawn whole. Screenshots go to
//! `RWT_OCCLUSION_DIR` (default `target/occlusion`).

use bevy::app::AppExit;
use bevy::core_pipeline::prepass::DepthPrepass;
use bevy::diagnostic::{DiagnosticPath, DiagnosticsStore};
use bevy::prelude::*;
use bevy::render::diagnostic::RenderDiagnosticsPlugin;
use bevy::render::occlusion_culling::OcclusionCulling;
use bevy_rwt::prelude::*;
use bevy_rwt::testing::{CullingCheck, CullingReport};
use rwt_examples::frame_check::{
    COMPARED_MSAA, Captures, culling_check_app, mean_difference, out_of_patience, output_dir,
    passed, pixels_differing, spawn_shadow_sun,
};
use rwt_examples::grass_field;

/// Most mean difference between the two frames (0..255 a channel).
const MOST_DIFFERENCE: f64 = 0.05;
/// Most pixels that may differ by more than [`BY`] in some channel: none. The frames have no
/// multisampling, so a blade dropped while in view is whole pixels off (a blade one pixel
/// wide at the field's far edge, which levels 5 and up of the pyramid hid, showed so).
const MOST_PIXELS: usize = 0;
/// What a channel may differ by in a pixel that matches.
const BY: u8 = 24;
/// Frames each step waits once streaming has settled (pipelines compile on the CPU).
const WAIT: u32 = 12;
/// Most frames the check may take.
const PATIENCE: u32 = 600;

/// Towards a sun 18 degrees up behind the camera's rest (the camera looks along +x).
const BEHIND_SUN: Vec3 = Vec3::new(-1.0, 0.33, 0.2);

/// The camera's rest: low behind the hill, which hides the field beyond it.
fn low() -> Transform {
    Transform::from_xyz(-30.0, 1.2, 0.0).looking_at(Vec3::new(30.0, 1.2, 0.0), Vec3::Y)
}

/// The camera risen to look over the hill.
fn high() -> Transform {
    Transform::from_xyz(-30.0, 15.0, 0.0).looking_at(Vec3::new(20.0, 0.0, 0.0), Vec3::Y)
}

fn main() -> AppExit {
    culling_check_app("rwt gpu_occlusion")
        .add_plugins(RenderDiagnosticsPlugin)
        .init_resource::<Check>()
        .add_systems(Startup, setup)
        .add_systems(Update, run_check)
        .run()
}

fn setup(
    mut commands: Commands,
    mut meshes: ResMut<Assets<Mesh>>,
    mut materials: ResMut<Assets<StandardMaterial>>,
) {
    let soil = materials.add(Color::srgb(0.2, 0.3, 0.1));
    commands.spawn((
        Mesh3d(meshes.add(Plane3d::default().mesh().size(160.0, 160.0))),
        MeshMaterial3d(soil.clone()),
    ));
    // A hill 6 m high and 28 m across; the field runs on under it.
    commands.spawn((
        Mesh3d(meshes.add(Sphere::new(20.0).mesh().uv(64, 32))),
        MeshMaterial3d(soil),
        Transform::from_xyz(0.0, -14.0, 0.0),
    ));
    commands.spawn((
        Camera3d::default(),
        COMPARED_MSAA,
        DepthPrepass,
        OcclusionCulling,
        RwtViewer::all_around(),
        low(),
    ));
    // A low sun behind the camera: the hill hides part of the field beyond it from the
    // sun, and the sun's cascade culls what its depth hides too.
    let sun = spawn_shadow_sun(&mut commands, BEHIND_SUN);
    commands.entity(sun).insert(OcclusionCulling);
    let blade = meshes.add(grass_field::blade());
    let grass = ScatterClass::instanced(LayerDensity::Constant(8.0), blade, default());
    commands.spawn(
        ScatterLayer::new(vec![grass])
            .with_tile_size(2.0)
            .with_streaming(StreamingConfig {
                chunk_size: 8.0,
                load_distance: 64.0,
                unload_distance: 72.0,
                near_distance: 64.0,
            }),
    );
}

/// Bevy's count of the vertices the camera's late prepass shaded (pipeline statistics).
const LATE_PREPASS_VERTICES: DiagnosticPath =
    DiagnosticPath::const_new("render/late prepass/vertex_shader_invocations");

/// The check's progress: frames since streaming settled (or the camera came back down),
/// the report, the late prepass's vertices while chunks were drawn whole (none where the
/// adapter has no pipeline statistics).
#[derive(Resource, Default)]
struct Check {
    settled_at: Option<u32>,
    frame: u32,
    report: Option<CullingReport>,
    late_whole: Option<f64>,
}

/// The culling setting, its check, and Bevy's render diagnostics (what the passes drew).
#[derive(bevy::ecs::system::SystemParam)]
struct Culling<'w> {
    setting: ResMut<'w, InstanceCulling>,
    check: Res<'w, CullingCheck>,
    diagnostics: Res<'w, DiagnosticsStore>,
}

fn run_check(
    mut check: ResMut<Check>,
    mut captures: ResMut<Captures>,
    stats: Res<RwtStats>,
    mut culling: Culling,
    mut camera: Single<&mut Transform, With<Camera3d>>,
    mut commands: Commands,
    mut exit: MessageWriter<AppExit>,
) {
    if out_of_patience(&mut check.frame, PATIENCE, "rwt-occlusion", &mut exit) {
        return;
    }
    let settled = stats.settled() && stats.live_instanced > 0;
    let Some(since) = check.settled_at else {
        if settled {
            check.settled_at = Some(check.frame);
        }
        return;
    };
    if check.report.is_none() && captures.get("whole").is_some() {
        check.report = culling.check.report();
    }
    if captures.pending() || check.frame < since + WAIT {
        return;
    }
    let dir = output_dir("RWT_OCCLUSION_DIR", "target/occlusion");
    match (captures.get("whole"), captures.get("occluded")) {
        (None, _) => {
            // The last frames were drawn whole, from the same place.
            let late = culling.diagnostics.get(&LATE_PREPASS_VERTICES);
            check.late_whole = late.and_then(|d| d.value());
            **camera = high();
            captures.capture(&mut commands, "whole", dir);
        }
        (Some(_), None) if *culling.setting == InstanceCulling::PerChunk => {
            // Back down behind the hill, culling per instance, until last frame's depth
            // is the hill's again.
            **camera = low();
            *culling.setting = InstanceCulling::PerInstance;
            check.settled_at = Some(check.frame);
        }
        (Some(_), None) => {
            **camera = high();
            culling.check.request();
            captures.capture(&mut commands, "occluded", dir);
        }
        (Some(whole), Some(occluded)) => {
            let Some(report) = check.report else { return };
            let passed = conclude(&report, check.late_whole, whole, occluded);
            exit.write(if passed {
                AppExit::Success
            } else {
                AppExit::error()
            });
        }
    }
}

/// Prints the result line; whether every check passed.
fn conclude(
    report: &CullingReport,
    late_whole: Option<f64>,
    whole: &image::RgbImage,
    occluded: &image::RgbImage,
) -> bool {
    let difference = mean_difference(whole, occluded);
    let differing = pixels_differing(whole, occluded, BY);
    let late_vertices = late_whole.map_or("unknown".into(), |v| v.to_string());
    println!(
        "rwt-occlusion: draws {} occluding {} instances {} kept {} (gpu) {} (frustum) late {}, cascade draws {} occluded {}, pixel difference {difference:.3}, pixels differing {differing}, late prepass vertices {late_vertices} (drawn whole)",
        report.draws,
        report.occluding_draws,
        report.instances,
        report.gpu_kept,
        report.cpu_kept,
        report.late_kept,
        report.cascade_occluding_draws,
        report.cascade_occluded
    );
    let failures = [
        (report.occluding_draws == 0, "no draw occluded"),
        (
            report.mismatched > 0,
            "a draw kept an instance its frustum does not keep, or (not occluding) not the CPU's instances",
        ),
        (
            report.gpu_kept >= report.cpu_kept,
            "occlusion dropped no instance",
        ),
        (report.late_kept == 0, "the late phase kept nothing"),
        (
            report.cascade_occluding_draws == 0 || report.cascade_occluded == 0,
            "the sun's cascade occluded nothing",
        ),
        (
            difference >= MOST_DIFFERENCE || differing > MOST_PIXELS,
            "the occluded frame differs from the whole one",
        ),
        (
            late_whole.is_none(),
            "no pipeline statistics: the adapter cannot count the late prepass's vertices",
        ),
        (
            late_whole.is_some_and(|v| v > 0.0),
            "the late prepass drew chunks the early prepass had drawn whole",
        ),
    ];
    passed("rwt-occlusion", &failures)
}
