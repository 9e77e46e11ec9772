//! Culling per instance on the GPU, checked in a real renderer (`scripts/smoke.sh` runs it
//! under Xvfb and lavapipe): `cargo run --example gpu_culling`.
//!
//! A field of grass that thins out with distance ([`InstancedThinning`]), sparse poles 6 m
//! tall, no wind (so that two frames can match), a low sun with shadows across the view
//! (with Bevy's `OcclusionCulling`, which its cascade must ignore: the camera has none, so
//! nothing reduces the cascade's depth pyramid), and a camera at the field's edge looking
//! across it, so that many chunks are cut by the view's sides, and the sun's cascade holds
//! blades whose shadows fall outside the view and poles outside it whose long shadows fall
//! inside (on one side of the view they do, on the other they fall away: a cascade that
//! took the light's direction the wrong way round would keep the latter and lose the
//! former). The blades have a far mesh from 20 m, the same blade made again: drawn whole, a
//! chunk draws the mesh its nearest point calls for, culled, each blade the one its own
//! distance calls for; the same pixels either way, and the check counts each mesh's draw.
//! Two screenshots: chunks drawn whole, every chunk in the cascade's box casting
//! ([`InstanceCulling::PerChunk`], [`CascadeCasters::All`]), then culled per instance, the
//! cascade drawing only the blades whose shadows fall in view
//! ([`InstanceCulling::PerInstance`], [`CascadeCasters::WhereRead`]), whose frame is also
//! checked by [`CullingCheck`]: every culled draw's instances, read back from its indirect
//! arguments and the pool of kept instances, must be those the same test keeps on the CPU.
//!
//! Then the buffer of every chunk's instances is made to grow and shrink under the field: a
//! denser second layer comes and goes, and the field's instances, moved to a smaller buffer,
//! must draw the same frame and pass the same check.
//!
//! It prints `rwt-culling: draws D (far F) instances N kept G (gpu) C (cpu) mismatched M,
//! cascade dropped K, pixel difference P, pixels differing X`, then `rwt-culling: slab
//! grown to G, shrunk to S instances: draws D kept G (gpu) C (cpu) mismatched M, pixel
//! difference P`, and exits with an error unless the counts agree, culling kept fewer
//! instances than it was given, some blades drew the far mesh and some the near one, the
//! cascade left blades out and did not occlude, the slab shrank, and the frames match
//! (`MOST_DIFFERENCE` in the mean, `MOST_PIXELS`).
//! Screenshots go to `RWT_CULLING_DIR` (default `target/culling`).

use bevy::app::AppExit;
use bevy::prelude::*;
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
/// multisampling, so a blade or a blade's shadow dropped while in view is whole pixels off.
const MOST_PIXELS: usize = 0;
/// What a channel may differ by in a pixel that matches.
const BY: u8 = 24;
/// Frames each step waits once streaming has settled (pipelines compile on the CPU).
const WAIT: u32 = 12;
/// Most frames the check may take.
const PATIENCE: u32 = 900;

fn main() -> AppExit {
    culling_check_app("rwt gpu_culling")
        .insert_resource(CascadeCasters::All)
        .init_resource::<Check>()
        .add_systems(Startup, setup)
        .add_systems(Update, run_check)
        .run()
}

fn setup(
    mut commands: Commands,
    mut meshes: ResMut<Assets<Mesh>>,
    mut materials: ResMut<Assets<StandardMaterial>>,
    mut check: ResMut<Check>,
) {
    commands.spawn((
        Mesh3d(meshes.add(Plane3d::default().mesh().size(120.0, 120.0))),
        MeshMaterial3d(materials.add(Color::srgb(0.2, 0.3, 0.1))),
    ));
    commands.spawn((
        Camera3d::default(),
        COMPARED_MSAA,
        RwtViewer::all_around(),
        Transform::from_xyz(-30.0, 3.0, -10.0).looking_at(Vec3::new(0.0, 0.0, 5.0), Vec3::Y),
    ));
    // The sun asks for occlusion, the camera does not: nothing reduces the cascade's depth
    // pyramid then, so the cascade must not occlude.
    let sun = spawn_shadow_sun(&mut commands, LOW_SUN);
    commands.entity(sun).insert(OcclusionCulling);
    commands.spawn(pole_layer(&mut meshes));
    check.blades = Blades {
        near: meshes.add(grass_field::blade()),
        far: meshes.add(grass_field::blade()),
    };
    commands.spawn(grass_layer(&check.blades, FIELD_DENSITY));
}

/// Towards the sun: 17 degrees up, across the camera's view (its right side: poles beyond
/// it cast shadows 20 m long into the view).
const LOW_SUN: Vec3 = Vec3::new(-0.447, 0.3, 0.894);
/// Poles per square metre, and their width and height (metres).
const POLE_DENSITY: f64 = 0.02;
const POLE_WIDTH: f32 = 0.6;
const POLE_HEIGHT: f32 = 6.0;

/// Sparse tall poles, instanced, streamed as the field is.
fn pole_layer(meshes: &mut Assets<Mesh>) -> ScatterLayer {
    let pole = Mesh::from(Cuboid::new(POLE_WIDTH, POLE_HEIGHT, POLE_WIDTH))
        .translated_by(Vec3::Y * POLE_HEIGHT / 2.0);
    let poles = ScatterClass::instanced(
        LayerDensity::Constant(POLE_DENSITY),
        meshes.add(pole),
        InstancedShading::default(),
    );
    ScatterLayer::new(vec![poles])
        .with_tile_size(2.0)
        .with_streaming(FIELD_STREAMING)
}

/// Blades per square metre of the field.
const FIELD_DENSITY: f64 = 12.0;
/// Of the layer that makes the slab grow: enough that the field alone then uses a quarter of
/// the slab or less.
const DENSE_DENSITY: f64 = 36.0;

/// Where the blades turn to their far mesh (metres from the camera).
const FAR_BLADE: f32 = 20.0;

/// The blade both layers draw, near and far: two meshes of the same blade.
#[derive(Default)]
struct Blades {
    near: Handle<Mesh>,
    far: Handle<Mesh>,
}

/// A field of grass thinning out from 10 m, streamed to 40 m.
fn grass_layer(blades: &Blades, density: f64) -> ScatterLayer {
    let material = InstancedShading {
        thinning: Some(InstancedThinning::from(10.0)),
        ..default()
    };
    let near = blades.near.clone();
    let grass = ScatterClass::instanced(LayerDensity::Constant(density), near, material)
        .with_instanced_far(blades.far.clone(), FAR_BLADE);
    ScatterLayer::new(vec![grass])
        .with_tile_size(2.0)
        .with_streaming(FIELD_STREAMING)
}

/// Streaming to 40 m in 8 m chunks.
const FIELD_STREAMING: StreamingConfig = StreamingConfig {
    chunk_size: 8.0,
    load_distance: 40.0,
    unload_distance: 48.0,
    near_distance: 40.0,
};

/// The check's progress: frames since streaming settled, whether a report was asked and
/// the report, and for the slab's part the dense layer while it lives, the slab's size with
/// it and the field's blades without it; the blade both layers draw.
#[derive(Resource, Default)]
struct Check {
    blades: Blades,
    settled_at: Option<u32>,
    frame: u32,
    report: Option<CullingReport>,
    dense: Option<Entity>,
    grown: Option<u64>,
    asked: bool,
    /// The field's live blades, alone.
    field_live: Option<usize>,
}

impl Check {
    /// Waits for streaming to settle again, then asks for a new report.
    fn restart(&mut self) {
        self.settled_at = None;
        self.report = None;
        self.asked = false;
    }
}

fn run_check(
    mut check: ResMut<Check>,
    mut captures: ResMut<Captures>,
    stats: Res<RwtStats>,
    // What the check switches: culling, and which blades the cascade draws.
    (mut culling, mut casters): (ResMut<InstanceCulling>, ResMut<CascadeCasters>),
    culling_check: Res<CullingCheck>,
    mut commands: Commands,
    mut exit: MessageWriter<AppExit>,
) {
    if out_of_patience(&mut check.frame, PATIENCE, "rwt-culling", &mut exit) {
        return;
    }
    let live = stats.live_instanced;
    // Once the field was checked: settled only with the dense layer fully in (it has three
    // times the field's blades), then fully gone.
    let layers_as_meant = match (check.field_live, check.dense) {
        (Some(field), Some(_)) => live > 2 * field,
        (Some(field), None) => live <= field,
        (None, _) => true,
    };
    let settled = stats.settled() && live > 0 && layers_as_meant;
    let Some(since) = check.settled_at else {
        if settled {
            check.settled_at = Some(check.frame);
        }
        return;
    };
    if check.asked && check.report.is_none() {
        check.report = culling_check.report();
    }
    if captures.pending() || check.frame < since + WAIT {
        return;
    }
    let dir = output_dir("RWT_CULLING_DIR", "target/culling");
    let shots = (
        captures.get("whole"),
        captures.get("culled"),
        captures.get("shrunk"),
    );
    match shots {
        (None, ..) => captures.capture(&mut commands, "whole", dir),
        (Some(_), None, _) if *culling == InstanceCulling::PerChunk => {
            *culling = InstanceCulling::PerInstance;
            *casters = CascadeCasters::WhereRead;
            culling_check.request();
            check.asked = true;
            check.settled_at = Some(check.frame);
        }
        (Some(_), None, _) => captures.capture(&mut commands, "culled", dir),
        (Some(whole), Some(culled), None) if check.dense.is_none() && check.grown.is_none() => {
            let Some(report) = check.report else { return };
            if !conclude(&report, whole, culled) {
                exit.write(AppExit::error());
                return;
            }
            check.field_live = Some(live);
            let dense = grass_layer(&check.blades, DENSE_DENSITY);
            check.dense = Some(commands.spawn(dense).id());
            check.restart();
        }
        (Some(_), Some(_), None) if !check.asked => {
            // Once settled, a report of the slab's size with the dense layer, or of the
            // field's instances moved; asked in the frame the screenshot shows.
            culling_check.request();
            check.asked = true;
            if check.dense.is_none() {
                captures.capture(&mut commands, "shrunk", dir);
            }
        }
        (Some(_), Some(_), None) => {
            if let (Some(report), Some(dense)) = (check.report, check.dense) {
                check.grown = Some(report.slab_capacity);
                commands.entity(dense).despawn();
                check.dense = None;
                check.restart();
            }
        }
        (Some(_), Some(culled), Some(shrunk)) => {
            let (Some(report), Some(grown)) = (check.report, check.grown) else {
                return;
            };
            let passed = conclude_shrunk(&report, grown, culled, shrunk);
            exit.write(if passed {
                AppExit::Success
            } else {
                AppExit::error()
            });
        }
    }
}

/// Prints the result line; whether every check passed.
fn conclude(report: &CullingReport, whole: &image::RgbImage, culled: &image::RgbImage) -> bool {
    let difference = mean_difference(whole, culled);
    let differing = pixels_differing(whole, culled, BY);
    println!(
        "rwt-culling: draws {} (far {}) instances {} kept {} (gpu) {} (cpu) mismatched {}, cascade dropped {}, pixel difference {difference:.3}, pixels differing {differing}",
        report.draws,
        report.far_draws,
        report.instances,
        report.gpu_kept,
        report.cpu_kept,
        report.mismatched,
        report.cascade_dropped,
    );
    let failures = [
        (report.draws == 0, "no culled draw"),
        (report.far_draws == 0, "no blade drew the far mesh"),
        (
            report.far_draws >= report.draws,
            "no chunk drew its near mesh",
        ),
        (
            report.mismatched > 0 || report.gpu_kept != report.cpu_kept,
            "the GPU's kept instances differ from the CPU's",
        ),
        (
            report.gpu_kept >= report.instances,
            "culling kept every instance",
        ),
        (
            report.cascade_dropped == 0,
            "the cascade drew every blade in its box",
        ),
        (
            report.occluding_draws > 0,
            "a view occluded with a depth pyramid nothing reduced",
        ),
        (
            difference >= MOST_DIFFERENCE || differing > MOST_PIXELS,
            "the culled frame differs from the whole one",
        ),
    ];
    passed("rwt-culling", &failures)
}

/// Prints the line of the slab's part; whether it passed: the slab shrank below the size
/// the dense layer made it grow to, and the field drew and culled as before.
fn conclude_shrunk(
    report: &CullingReport,
    grown: u64,
    culled: &image::RgbImage,
    shrunk: &image::RgbImage,
) -> bool {
    let difference = mean_difference(culled, shrunk);
    println!(
        "rwt-culling: slab grown to {grown}, shrunk to {} instances: draws {} kept {} (gpu) {} (cpu) mismatched {}, pixel difference {difference:.3}",
        report.slab_capacity, report.draws, report.gpu_kept, report.cpu_kept, report.mismatched
    );
    let failures = [
        (
            report.slab_capacity >= grown,
            "the slab did not shrink once the dense layer went",
        ),
        (report.draws == 0, "no culled draw after shrinking"),
        (
            report.mismatched > 0 || report.gpu_kept != report.cpu_kept,
            "after shrinking, the GPU's kept instances differ from the CPU's",
        ),
        (
            difference >= MOST_DIFFERENCE,
            "after shrinking, the frame differs from the first culled one",
        ),
    ];
    passed("rwt-culling", &failures)
}
