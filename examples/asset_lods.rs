//! An asset's levels of detail chosen per instance on the GPU, checked in a real renderer
//! (`scripts/smoke.sh` runs it under Xvfb and lavapipe): `cargo run --example asset_lods`.
//!
//! The example writes a two-level asset (`assets/generated/asset_lods.glb`: a fine sphere
//! at `ball_LOD0`, a coarse one at `ball_LOD1`) and scatters it in a patch ahead of the
//! camera, the second level taking over at 40 m. The camera steps back three times
//! (the patch all nearer than the switch, across it, all beyond it); at each step the
//! culling pass's indirect arguments are read back ([`CullingCheck`]; the camera occludes, so
//! that every chunk is culled per instance). It prints
//! `rwt-lods: step S, eye to patch D m, kept K, vertices V` per step, then
//! `rwt-lods: vertices A > B > C, mismatched M`, and exits with an error unless the vertices
//! drawn fall at each step, the near step draws every kept instance with the fine sphere
//! and the far step with the coarse one, and the GPU kept exactly the instances the CPU's
//! test keeps (each level within its distances and crossfade bands).

use bevy::app::AppExit;
use bevy::core_pipeline::prepass::DepthPrepass;
use bevy::math::DVec2;
use bevy::prelude::*;
use bevy::render::occlusion_culling::OcclusionCulling;
use bevy_rwt::look::asset::{AssetLods, AssetLook};
use bevy_rwt::prelude::*;
use bevy_rwt::testing::glb::{Glb, GlbMaterial, GlbNode, GlbPrimitive};
use bevy_rwt::testing::{CullingCheck, CullingReport};
use rwt_examples::frame_check::{Disc, out_of_patience, passed};
use std::sync::Arc;

/// Where the coarse sphere takes over (metres from the camera to an instance's root).
const SWITCH: f32 = 40.0;
/// The patch, ahead of the camera (+x).
const PATCH: Disc = Disc {
    center: DVec2::new(25.0, 0.0),
    radius: 7.0,
    density: 0.3,
};
/// The camera's x at each step: the patch at 18..32 m, 38..52 m, 78..92 m.
const STEPS: [f32; 3] = [0.0, -20.0, -60.0];
/// Frames each step waits once streaming settled.
const WAIT: u32 = 10;
/// Most frames the check may take.
const PATIENCE: u32 = 900;
/// The file, under the asset folder.
const FILE: &str = "generated/asset_lods.glb";

/// The two levels' meshes: a fine sphere and a coarse one, standing on the origin.
fn levels() -> [Mesh; 2] {
    let ball = |mesh: Mesh| mesh.translated_by(Vec3::Y);
    [
        ball(Sphere::new(1.0).mesh().uv(48, 24)),
        ball(Sphere::new(1.0).mesh().ico(1).expect("a small icosphere")),
    ]
}

/// Index counts of the two levels.
fn indices() -> [u64; 2] {
    levels().map(|m| m.indices().map_or(0, |i| i.len() as u64))
}

fn asset() -> Glb {
    let mut file = Glb::default();
    let material = file.add_material(GlbMaterial::colored([0.7, 0.5, 0.2, 1.0]));
    let [fine, coarse] = levels().map(|mesh| {
        let primitive = GlbPrimitive::from_mesh(&mesh, material).expect("a triangle mesh");
        file.add_mesh(vec![primitive])
    });
    let near = file.add_node(GlbNode::named("ball_LOD0").with_mesh(fine));
    let far = file.add_node(GlbNode::named("ball_LOD1").with_mesh(coarse));
    let root = file.add_node(GlbNode::named("ball").with_children([near, far]));
    file.add_root(root);
    file
}

fn main() -> AppExit {
    rwt_examples::generated::write_asset(FILE, &asset().to_bytes());
    App::new()
        .add_plugins(rwt_examples::example_plugins("rwt asset_lods"))
        .add_plugins(RwtPlugins::default())
        .init_resource::<CullingCheck>()
        .init_resource::<Check>()
        .add_systems(Startup, setup)
        .add_systems(Update, run_check)
        .run()
}

fn setup(mut commands: Commands, server: Res<AssetServer>) {
    // An occluding camera culls every chunk per instance (none is drawn whole, unculled),
    // so every draw's arguments are read back.
    commands.spawn((
        Camera3d::default(),
        DepthPrepass,
        OcclusionCulling,
        RwtViewer::all_around(),
        Transform::from_xyz(STEPS[0], 4.0, 0.0)
            .looking_at(Vec3::new(PATCH.center.x as f32, 0.0, 0.0), Vec3::Y),
    ));
    commands.spawn((
        DirectionalLight::default(),
        Transform::default().looking_to(Vec3::new(-1.0, -2.0, -0.5), Vec3::Y),
    ));
    let look = AssetLook {
        shadows: InstancedShadows::Off,
        lods: AssetLods {
            distances: vec![SWITCH],
            ..default()
        },
        ..AssetLook::new(server.load(FILE))
    };
    let class = ScatterClass::asset(LayerDensity::Custom(Arc::new(PATCH)), look);
    commands.spawn(ScatterLayer::new(vec![class]).with_tile_size(16.0));
}

/// The check's progress: the step, frames since it settled, each step's report.
#[derive(Resource, Default)]
struct Check {
    step: usize,
    settled_at: Option<u32>,
    frame: u32,
    requested: bool,
    reports: Vec<CullingReport>,
}

fn run_check(
    mut check: ResMut<Check>,
    stats: Res<RwtStats>,
    culling: Res<CullingCheck>,
    mut camera: Single<&mut Transform, With<Camera3d>>,
    mut exit: MessageWriter<AppExit>,
) {
    if out_of_patience(&mut check.frame, PATIENCE, "rwt-lods", &mut exit) {
        return;
    }
    let settled = stats.pending_tasks == 0 && stats.live_instanced > 0;
    let Some(since) = check.settled_at else {
        if settled {
            check.settled_at = Some(check.frame);
        }
        return;
    };
    if check.frame < since + WAIT {
        return;
    }
    if !check.requested {
        culling.request();
        check.requested = true;
        return;
    }
    let Some(report) = culling.report() else {
        return;
    };
    let eye = PATCH.center.x as f32 - STEPS[check.step];
    println!(
        "rwt-lods: step {}, eye to patch {eye:.0} m, kept {}, vertices {}",
        check.step, report.gpu_kept, report.camera_vertices
    );
    check.reports.push(report);
    check.step += 1;
    check.requested = false;
    check.settled_at = None;
    match STEPS.get(check.step) {
        Some(x) => camera.translation.x = *x,
        None => {
            let ok = conclude(&check.reports);
            exit.write(if ok {
                AppExit::Success
            } else {
                AppExit::error()
            });
        }
    }
}

/// Prints the summary line; whether every check passed.
fn conclude(reports: &[CullingReport]) -> bool {
    let vertices: Vec<u64> = reports.iter().map(|r| r.camera_vertices).collect();
    let mismatched: usize = reports.iter().map(|r| r.mismatched).sum();
    println!(
        "rwt-lods: vertices {} > {} > {}, mismatched {mismatched}",
        vertices[0], vertices[1], vertices[2]
    );
    let [fine, coarse] = indices();
    let (near, far) = (&reports[0], &reports[2]);
    let failures = [
        (near.gpu_kept < 20, "too few instances in view"),
        (
            !vertices.windows(2).all(|w| w[1] < w[0]),
            "the vertices drawn do not fall as the camera moves away",
        ),
        (
            near.camera_vertices != near.gpu_kept * fine,
            "the near step does not draw every instance with the fine level",
        ),
        (
            far.camera_vertices != far.gpu_kept * coarse,
            "the far step does not draw every instance with the coarse level",
        ),
        (
            mismatched > 0,
            "culling kept other instances than the CPU's",
        ),
    ];
    passed("rwt-lods", &failures)
}
