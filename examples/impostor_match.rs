//! Impostors checked in a real renderer (`scripts/smoke.sh` runs it under Xvfb and
//! lavapipe): `cargo run --example impostor_match`.
//!
//! open_world's three tree species (entities) and an instanced broadleaf stand in a strip
//! 180 to 220 m ahead of a long-lens camera, against the sky (no ground, so that every
//! pixel that is not sky is a tree).
//! The same trees are taken twice: as meshes (their far level of detail, from which the
//! impostors are baked), then with the impostors' crossfade moved near, so that every tree
//! is a card, culled per instance ([`CullingCheck`] reads that frame's counts back). It
//! prints `rwt-impostor: trees T, mesh pixels M, impostor pixels I, silhouette IoU U, colour
//! difference C` (`T`: the tree entities of the first frame) and exits with an error unless the silhouettes' intersection over union
//! is at least `LEAST_IOU`, the mean colour difference where both show a tree is under
//! `MOST_COLOUR`, and culling kept the CPU's instances. Screenshots go to
//! `RWT_IMPOSTOR_DIR` (default `target/impostor`).

use bevy::app::AppExit;
use bevy::math::DVec2;
use bevy::prelude::*;
use bevy_rwt::prelude::*;
use bevy_rwt::rwt_core::density::Density;
use bevy_rwt::testing::{CullingCheck, CullingReport};
use rwt_examples::foliage;
use rwt_examples::frame_check::{
    CHECK_SKY as SKY, COMPARED_MSAA, Captures, HIGH_SUN, off_sky, out_of_patience, output_dir,
    passed, spawn_shadow_sun,
};
use std::sync::Arc;

/// Least intersection over union of the two frames' tree pixels.
const LEAST_IOU: f64 = 0.8;
/// Most mean colour difference (0..255 a channel) where both frames show a tree.
const MOST_COLOUR: f64 = 24.0;
/// What a channel must differ from the sky's by for a pixel to be a tree's.
const BY: u8 = 40;
/// Frames each step waits once streaming has settled.
const WAIT: u32 = 12;
/// Most frames the check may take.
const PATIENCE: u32 = 900;
/// Where the trees stand: this far from the camera, within 20 m.
const DISTANCE: f64 = 200.0;

/// Trees in a strip around [`DISTANCE`] ahead (+x), a narrow wedge of it.
struct Strip;

impl Strip {
    fn inside(p: DVec2) -> bool {
        let r = p.length();
        (DISTANCE - 20.0..DISTANCE + 20.0).contains(&r) && p.y.abs() < 0.17 * p.x
    }
}

impl Density for Strip {
    fn density(&self, p: DVec2) -> f64 {
        if Self::inside(p) { 0.004 } else { 0.0 }
    }

    fn max_over(&self, min: DVec2, max: DVec2) -> f64 {
        // Any rectangle reaching the wedge's bounding box may hold some.
        let reaches = max.x >= DISTANCE - 20.0 && min.x <= DISTANCE + 20.0;
        let across = min.y <= 0.17 * (DISTANCE + 20.0) && max.y >= -0.17 * (DISTANCE + 20.0);
        if reaches && across { 0.004 } else { 0.0 }
    }
}

fn main() -> AppExit {
    let mut app = App::new();
    app.add_plugins(rwt_examples::example_plugins("rwt impostor_match"))
        .add_plugins(RwtPlugins::default())
        .insert_resource(ClearColor(SKY))
        .insert_resource(RwtWind {
            strength: 0.0,
            ..default()
        })
        .init_resource::<CullingCheck>()
        .init_resource::<Captures>()
        .init_resource::<Check>()
        .add_systems(Startup, setup)
        .add_systems(Update, run_check);
    app.run()
}

fn setup(
    mut commands: Commands,
    mut meshes: ResMut<Assets<Mesh>>,
    mut materials: ResMut<Assets<StandardMaterial>>,
) {
    commands.spawn((
        Camera3d::default(),
        COMPARED_MSAA,
        Projection::Perspective(PerspectiveProjection {
            fov: 9f32.to_radians(),
            far: 2000.0,
            ..default()
        }),
        RwtViewer::all_around(),
        Transform::from_xyz(0.0, 6.0, 0.0).looking_at(Vec3::new(200.0, 5.0, 0.0), Vec3::Y),
    ));
    spawn_shadow_sun(&mut commands, HIGH_SUN);
    let white = materials.add(StandardMaterial {
        perceptual_roughness: 0.9,
        ..default()
    });
    let density = LayerDensity::Custom(Arc::new(Strip));
    let mut classes: Vec<ScatterClass> =
        [foliage::conifer(), foliage::broadleaf(), foliage::birch()]
            .into_iter()
            .map(|tree| {
                let (near, far) = (meshes.add(tree.near), meshes.add(tree.far));
                let mut class = ScatterClass::new(density.clone(), near, white.clone())
                    .with_lod(far, white.clone(), 100.0)
                    .with_impostor(Impostor::at(1000.0));
                class.scale_variation = 0.3;
                class
            })
            .collect();
    // An instanced tree: its meshes fade out where its impostors fade in.
    let shading = InstancedShading {
        base_color: Color::srgb(0.25, 0.16, 0.08),
        tip_color: Color::srgb(0.2, 0.45, 0.12),
        tip_from: 0.35,
        color_variation: 0.15,
        wind_response: 0.0,
        shadows: InstancedShadows::Off,
        ..default()
    };
    let canopy = meshes.add(foliage::broadleaf().far);
    classes.push(
        ScatterClass::instanced(density, canopy, shading).with_impostor(Impostor::at(1000.0)),
    );
    commands.spawn(
        ScatterLayer::new(classes)
            .with_tile_size(64.0)
            .with_streaming(StreamingConfig {
                chunk_size: 64.0,
                load_distance: 300.0,
                unload_distance: 340.0,
                near_distance: 300.0,
            }),
    );
}

/// The check's progress: frames since streaming settled, the report of the impostors'
/// frame.
#[derive(Resource, Default)]
struct Check {
    settled_at: Option<u32>,
    frame: u32,
    report: Option<CullingReport>,
    trees: usize,
}

fn run_check(
    mut check: ResMut<Check>,
    mut captures: ResMut<Captures>,
    stats: Res<RwtStats>,
    culling: Res<CullingCheck>,
    mut layer: Single<&mut ScatterLayer>,
    mut commands: Commands,
    mut exit: MessageWriter<AppExit>,
) {
    if out_of_patience(&mut check.frame, PATIENCE, "rwt-impostor", &mut exit) {
        return;
    }
    let meshes_done = captures.get("meshes").is_some();
    let shown = if meshes_done {
        stats.live_instanced
    } else {
        stats.live_entities
    };
    let settled = stats.settled() && shown > 0;
    let Some(since) = check.settled_at else {
        if settled {
            check.settled_at = Some(check.frame);
        }
        return;
    };
    if check.report.is_none() && captures.get("impostors").is_some() {
        check.report = culling.report();
    }
    if captures.pending() || check.frame < since + WAIT {
        return;
    }
    let dir = output_dir("RWT_IMPOSTOR_DIR", "target/impostor");
    match (captures.get("meshes"), captures.get("impostors")) {
        (None, _) => {
            check.trees = stats.live_entities;
            captures.capture(&mut commands, "meshes", dir);
        }
        (Some(_), None)
            if layer.classes[0]
                .impostor
                .is_some_and(|i| i.distance > 500.0) =>
        {
            // Every tree an impostor: the crossfade well before the strip.
            for class in &mut layer.classes {
                class.impostor = Some(Impostor::at(120.0));
            }
            check.settled_at = None;
        }
        (Some(_), None) => {
            culling.request();
            captures.capture(&mut commands, "impostors", dir);
        }
        (Some(meshes), Some(cards)) => {
            let Some(report) = check.report else { return };
            let trees = check.trees;
            exit.write(if conclude(trees, &report, meshes, cards) {
                AppExit::Success
            } else {
                AppExit::error()
            });
        }
    }
}

/// Whether a pixel is a tree's (not the sky's).
fn tree(p: &image::Rgb<u8>) -> bool {
    off_sky(p, BY)
}

/// Prints the result line; whether every check passed.
fn conclude(
    trees: usize,
    report: &CullingReport,
    meshes: &image::RgbImage,
    cards: &image::RgbImage,
) -> bool {
    let (mut mesh, mut card, mut both, mut colour) = (0usize, 0usize, 0usize, 0u64);
    for (a, b) in meshes.pixels().zip(cards.pixels()) {
        let (m, c) = (tree(a), tree(b));
        mesh += usize::from(m);
        card += usize::from(c);
        if m && c {
            both += 1;
            colour +=
                a.0.iter()
                    .zip(b.0)
                    .map(|(x, y)| u64::from(x.abs_diff(y)))
                    .sum::<u64>();
        }
    }
    let either = mesh + card - both;
    let iou = both as f64 / either.max(1) as f64;
    let difference = colour as f64 / (3 * both.max(1)) as f64;
    println!(
        "rwt-impostor: trees {trees}, mesh pixels {mesh}, impostor pixels {card}, silhouette IoU {iou:.3}, colour difference {difference:.1}"
    );
    let failures = [
        (trees == 0 || mesh < 500, "too few trees in view"),
        (
            iou < LEAST_IOU,
            "the impostors do not cover the meshes' pixels",
        ),
        (
            difference >= MOST_COLOUR,
            "the impostors are not coloured as the meshes",
        ),
        (
            report.draws == 0,
            "no impostor chunk was culled per instance",
        ),
        (
            report.mismatched > 0,
            "culling kept other instances than the CPU's",
        ),
    ];
    passed("rwt-impostor", &failures)
}
