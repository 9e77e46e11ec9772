//! Shadows of a glTF asset drawn by rwt instanced, against the shadows Bevy itself casts
//! with the same asset, checked in a real renderer (`scripts/smoke.sh` runs it under Xvfb
//! and lavapipe): `cargo run --example asset_shadows`.
//!
//! The example writes an asset (`assets/generated/asset_shadows.glb`): a thin trunk holding
//! up a level leaf card cut out by its texture's alpha (five overlapping discs, double-sided),
//! over a low blue disc of moss at its foot. A layer scatters it on a grey ground under a
//! sun from +x; the camera looks at the shadows from the side they fall on. Three frames:
//! 1. the class casting shadows (`shadows: On`);
//! 2. the class casting none (`InstancedShadows::Off`): every pixel darker in frame 1 than
//!    here is in a shadow rwt casts, on the ground or on the moss (so the asset receives
//!    them too);
//! 3. the layer gone and Bevy's own scene of the file spawned at every instance's
//!    transform, casting as Bevy casts: its shadow pixels (darker than frame 2) must be
//!    rwt's, so the cut-out card casts the cut-out's shape.
//!
//! It prints `rwt-asset-shadows: instances N, shadow pixels rwt R scene S, on moss M,
//! shadow IoU U` and exits with an error unless the shadows' intersection over union is at
//! least `LEAST_IOU`, enough pixels are shadowed, and the moss receives some. Screenshots
//! go to `RWT_ASSET_SHADOWS_DIR` (default `target/asset_shadows`).

use bevy::app::AppExit;
use bevy::math::DVec2;
use bevy::prelude::*;
use bevy_rwt::instancing::InstancedChunk;
use bevy_rwt::look::asset::AssetLook;
use bevy_rwt::prelude::*;
use bevy_rwt::testing::glb::{Glb, GlbAlpha, GlbMaterial, GlbNode, GlbPrimitive};
use rwt_examples::frame_check::{
    CHECK_SKY as SKY, COMPARED_MSAA, Captures, Disc, out_of_patience, output_dir, passed,
    scene_per_instance, spawn_shadow_sun, still_check_app,
};
use std::sync::Arc;

/// Least intersection over union of the shadows rwt and Bevy cast.
const LEAST_IOU: f64 = 0.85;
/// How much darker (mean of the channels, 0..255) a pixel must be to be in a shadow.
const DARKER: f64 = 12.0;
/// Frames each step waits once its frame has settled.
const WAIT: u32 = 12;
/// Most frames the check may take.
const PATIENCE: u32 = 1200;
/// The patch the asset stands in: about a dozen instances.
const PATCH: Disc = Disc {
    center: DVec2::ZERO,
    radius: 5.0,
    density: 0.16,
};
/// Towards the sun: from +x, 58 degrees up (shadows fall 1.44 m towards -x of the cards).
const SUN: Vec3 = Vec3::new(1.0, 1.6, 0.0);
/// The file, under the asset folder.
const FILE: &str = "generated/asset_shadows.glb";
/// The height of the leaf card.
const CANOPY: f32 = 2.3;
/// The moss's colour, and the ground's.
const MOSS: [f32; 4] = [0.1, 0.2, 0.8, 1.0];
const GROUND: Color = Color::srgb(0.55, 0.55, 0.5);

fn main() -> AppExit {
    rwt_examples::generated::write_asset(FILE, &asset().to_bytes());
    let mut app = still_check_app("rwt asset_shadows");
    app.insert_resource(ClearColor(SKY))
        .init_resource::<Check>()
        .add_systems(Startup, setup)
        .add_systems(Update, run_check);
    app.run()
}

/// The asset: a trunk, a level leaf card on it, moss at its foot.
fn asset() -> Glb {
    let mut file = Glb::default();
    let bark = file.add_material(GlbMaterial::colored([0.35, 0.2, 0.1, 1.0]));
    let image = file.add_image(rwt_examples::generated::leaf_mask_png());
    let leaves = file.add_material(GlbMaterial {
        base_color_texture: Some(image),
        alpha: GlbAlpha::Mask(0.5),
        double_sided: true,
        ..GlbMaterial::colored([0.1, 0.6, 0.08, 1.0])
    });
    let moss = file.add_material(GlbMaterial::colored(MOSS));
    let primitive = |shape: Mesh, material| GlbPrimitive::from_mesh(&shape, material).unwrap();
    let card = Plane3d::new(Vec3::Y, Vec2::splat(0.9)).mesh().build();
    let mesh = file.add_mesh(vec![
        primitive(
            Cylinder::new(0.06, CANOPY)
                .mesh()
                .build()
                .translated_by(Vec3::Y * CANOPY / 2.0),
            bark,
        ),
        primitive(card.translated_by(Vec3::Y * CANOPY), leaves),
        primitive(
            Cylinder::new(1.7, 0.04)
                .mesh()
                .build()
                .translated_by(Vec3::Y * 0.02),
            moss,
        ),
    ]);
    let node = file.add_node(GlbNode::named("parasol").with_mesh(mesh));
    file.add_root(node);
    file
}

fn setup(
    mut commands: Commands,
    server: Res<AssetServer>,
    mut meshes: ResMut<Assets<Mesh>>,
    mut materials: ResMut<Assets<StandardMaterial>>,
) {
    commands.spawn((
        Camera3d::default(),
        COMPARED_MSAA,
        Projection::Perspective(PerspectiveProjection {
            fov: 40f32.to_radians(),
            ..default()
        }),
        RwtViewer::all_around(),
        Transform::from_xyz(-13.0, 7.0, 0.0).looking_at(Vec3::new(-1.0, 0.0, 0.0), Vec3::Y),
    ));
    spawn_shadow_sun(&mut commands, SUN);
    commands.spawn((
        Mesh3d(meshes.add(Plane3d::new(Vec3::Y, Vec2::splat(40.0)))),
        MeshMaterial3d(materials.add(StandardMaterial {
            base_color: GROUND,
            perceptual_roughness: 0.9,
            ..default()
        })),
    ));
    commands.spawn(layer(&server, InstancedShadows::On));
}

/// The layer of the asset, casting as `shadows` says.
fn layer(server: &AssetServer, shadows: InstancedShadows) -> ScatterLayer {
    let look = AssetLook {
        shadows,
        ..AssetLook::new(server.load(FILE))
    };
    let class = ScatterClass::asset(LayerDensity::Custom(Arc::new(PATCH)), look);
    ScatterLayer::new(vec![class]).with_tile_size(16.0)
}

/// The check's progress.
#[derive(Resource, Default)]
struct Check {
    settled_at: Option<u32>,
    frame: u32,
    /// Whether the layer casting nothing stands in.
    shadows_off: bool,
    instances: usize,
}

/// Whether the step now under way has drawn what it shows: rwt's chunks, or once the scenes
/// stand in, no chunk and every primitive an entity (beside the ground).
fn drawn(check: &Check, captures: &Captures, chunks: usize, entities: usize) -> bool {
    match captures.get("off") {
        None => chunks > 0,
        Some(_) => check.instances == 0 || (chunks == 0 && entities > 3 * check.instances),
    }
}

#[allow(clippy::too_many_arguments)]
fn run_check(
    mut check: ResMut<Check>,
    mut captures: ResMut<Captures>,
    stats: Res<RwtStats>,
    layers: Query<Entity, With<ScatterLayer>>,
    chunks: Query<(&InstancedChunk, &Transform)>,
    spawned: Query<(), With<Mesh3d>>,
    server: Res<AssetServer>,
    mut commands: Commands,
    mut exit: MessageWriter<AppExit>,
) {
    if out_of_patience(&mut check.frame, PATIENCE, "rwt-asset-shadows", &mut exit) {
        return;
    }
    let shown = drawn(&check, &captures, chunks.iter().len(), spawned.iter().len());
    // Settled for WAIT frames in a row.
    if !(stats.settled() && shown) {
        check.settled_at = None;
        return;
    }
    let frame = check.frame;
    let since = *check.settled_at.get_or_insert(frame);
    if captures.pending() || check.frame < since + WAIT {
        return;
    }
    let dir = output_dir("RWT_ASSET_SHADOWS_DIR", "target/asset_shadows");
    let step = ["cast", "off", "scene"].map(|name| captures.get(name).is_some());
    match step {
        [false, _, _] => captures.capture(&mut commands, "cast", dir),
        [true, false, _] if !check.shadows_off => {
            // The same layer casting nothing.
            for layer in &layers {
                commands.entity(layer).despawn();
            }
            commands.spawn(layer(&server, InstancedShadows::Off));
            check.shadows_off = true;
            check.settled_at = None;
        }
        [true, false, _] => captures.capture(&mut commands, "off", dir),
        [true, true, false] if layers.iter().len() == 1 => {
            let scene = server.load(format!("{FILE}#Scene0"));
            check.instances = scene_per_instance(&mut commands, &chunks, &scene);
            for layer in &layers {
                commands.entity(layer).despawn();
            }
            check.settled_at = None;
        }
        [true, true, false] => captures.capture(&mut commands, "scene", dir),
        [true, true, true] => {
            let frames = ["cast", "off", "scene"].map(|name| captures.get(name).unwrap());
            let ok = conclude(check.instances, frames);
            exit.write(if ok {
                AppExit::Success
            } else {
                AppExit::error()
            });
        }
    }
}

/// The mean of a pixel's channels.
fn brightness(p: &image::Rgb<u8>) -> f64 {
    p.0.iter().map(|c| f64::from(*c)).sum::<f64>() / 3.0
}

/// Whether a pixel of the frame drawn without shadows shows the moss.
fn moss(p: &image::Rgb<u8>) -> bool {
    let [r, g, b] = p.0.map(i32::from);
    b > r + 40 && b > g + 20
}

/// Prints the result line; whether every check passed.
fn conclude(instances: usize, [cast, off, scene]: [&image::RgbImage; 3]) -> bool {
    let shadowed = |frame: &image::RgbImage| -> Vec<bool> {
        frame
            .pixels()
            .zip(off.pixels())
            .map(|(a, o)| brightness(o) - brightness(a) >= DARKER)
            .collect()
    };
    let (ours, bevys) = (shadowed(cast), shadowed(scene));
    let count = |mask: &[bool]| mask.iter().filter(|s| **s).count();
    let both = ours.iter().zip(&bevys).filter(|(a, b)| **a && **b).count();
    let either = ours.iter().zip(&bevys).filter(|(a, b)| **a || **b).count();
    let iou = both as f64 / either.max(1) as f64;
    let on_moss = ours
        .iter()
        .zip(off.pixels())
        .filter(|(s, p)| **s && moss(p))
        .count();
    println!(
        "rwt-asset-shadows: instances {instances}, shadow pixels rwt {} scene {}, on moss \
         {on_moss}, shadow IoU {iou:.3}",
        count(&ours),
        count(&bevys)
    );
    let failures = [
        (instances < 5, "too few instances"),
        (
            count(&ours) < 2_000,
            "too few shadowed pixels: the asset casts no shadow",
        ),
        (on_moss < 200, "the moss receives no shadow"),
        (iou < LEAST_IOU, "rwt's shadows are not where Bevy's are"),
    ];
    passed("rwt-asset-shadows", &failures)
}
