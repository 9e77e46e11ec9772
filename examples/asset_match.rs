//! A glTF asset drawn by rwt instanced against the same asset drawn by Bevy itself, checked
//! in a real renderer (`scripts/smoke.sh` runs it under Xvfb and lavapipe):
//! `cargo run --example asset_match`.
//!
//! The example writes a three-primitive asset (`assets/generated/asset_match.glb`): a red
//! trunk, a green leaf card cut out by its texture's alpha (double-sided), a blue stone. A
//! layer scatters it as an asset class in a patch ahead of the camera; the frame is
//! captured. The layer then goes, and Bevy spawns the file's scene once per instance, at
//! each instance's transform as the chunks hold it; the frame is captured again. It prints
//! `rwt-asset: instances N, asset pixels A, scene pixels S, silhouette IoU U, colour
//! difference C, red/green/blue IoU R G B` and exits with an error unless the silhouettes'
//! intersection over union is at least `LEAST_IOU`, the mean colour difference where both
//! show the asset is under `MOST_COLOUR`, and each primitive's colour covers the same
//! pixels in both (IoU at least `LEAST_PART_IOU`). Screenshots go to `RWT_ASSET_DIR`
//! (default `target/asset_match`).

use bevy::app::AppExit;
use bevy::math::DVec2;
use bevy::prelude::*;
use bevy_rwt::instancing::InstancedChunk;
use bevy_rwt::look::asset::AssetLook;
use bevy_rwt::prelude::*;
use bevy_rwt::testing::glb::{Glb, GlbAlpha, GlbMaterial, GlbNode, GlbPrimitive};
use rwt_examples::frame_check::{
    CHECK_SKY as SKY, COMPARED_MSAA, Captures, Disc, HIGH_SUN, off_sky, out_of_patience,
    output_dir, passed, scene_per_instance, spawn_shadow_sun, still_check_app,
};
use std::sync::Arc;

/// Least intersection over union of the two frames' asset pixels.
const LEAST_IOU: f64 = 0.98;
/// Least intersection over union of each primitive's colour in the two frames.
const LEAST_PART_IOU: f64 = 0.95;
/// Most mean colour difference (0..255 a channel) where both frames show the asset.
const MOST_COLOUR: f64 = 6.0;
/// What a channel must differ from the sky's by for a pixel to be the asset's.
const BY: u8 = 30;
/// Frames each step waits once its frame has settled.
const WAIT: u32 = 12;
/// Most frames the check may take.
const PATIENCE: u32 = 900;
/// The patch the asset stands in, ahead of the camera (+x): about 50 instances.
const PATCH: Disc = Disc {
    center: DVec2::new(24.0, 0.0),
    radius: 7.0,
    density: 0.32,
};
/// The file, under the asset folder.
const FILE: &str = "generated/asset_match.glb";

fn main() -> AppExit {
    rwt_examples::generated::write_asset(FILE, &asset().to_bytes());
    let mut app = still_check_app("rwt asset_match");
    app.insert_resource(ClearColor(SKY))
        .init_resource::<Check>()
        .add_systems(Startup, setup)
        .add_systems(Update, run_check);
    app.run()
}

/// The asset: a trunk, a masked leaf card across it, a stone at its foot.
fn asset() -> Glb {
    let mut file = Glb::default();
    let trunk = file.add_material(GlbMaterial::colored([0.8, 0.08, 0.05, 1.0]));
    let image = file.add_image(rwt_examples::generated::leaf_mask_png());
    let leaves = file.add_material(GlbMaterial {
        base_color_texture: Some(image),
        alpha: GlbAlpha::Mask(0.5),
        double_sided: true,
        ..GlbMaterial::colored([0.1, 0.75, 0.08, 1.0])
    });
    let stone = file.add_material(GlbMaterial {
        roughness: 0.6,
        ..GlbMaterial::colored([0.08, 0.15, 0.85, 1.0])
    });
    let primitive = |shape: Mesh, material| GlbPrimitive::from_mesh(&shape, material).unwrap();
    let card = Plane3d::new(Vec3::Z, Vec2::splat(0.9)).mesh().build();
    let mesh = file.add_mesh(vec![
        primitive(Cylinder::new(0.12, 2.0).mesh().build(), trunk),
        primitive(card.translated_by(Vec3::new(0.0, 1.0, 0.0)), leaves),
        primitive(
            Cuboid::new(0.5, 0.3, 0.4)
                .mesh()
                .build()
                .translated_by(Vec3::new(0.45, -0.85, 0.1)),
            stone,
        ),
    ]);
    // The node lifts the asset onto its origin: its transform is part of the asset.
    let node = file.add_node(
        GlbNode::named("shrub")
            .with_mesh(mesh)
            .with_transform(Transform::from_xyz(0.0, 1.0, 0.0)),
    );
    file.add_root(node);
    file
}

fn setup(mut commands: Commands, server: Res<AssetServer>) {
    commands.spawn((
        Camera3d::default(),
        COMPARED_MSAA,
        Projection::Perspective(PerspectiveProjection {
            fov: 36f32.to_radians(),
            ..default()
        }),
        RwtViewer::all_around(),
        Transform::from_xyz(0.0, 3.0, 0.0)
            .looking_at(Vec3::new(PATCH.center.x as f32, 0.8, 0.0), Vec3::Y),
    ));
    spawn_shadow_sun(&mut commands, HIGH_SUN);
    let look = AssetLook::new(server.load(FILE));
    let mut class = ScatterClass::asset(LayerDensity::Custom(Arc::new(PATCH)), look);
    class.scale_variation = 0.3;
    commands.spawn(ScatterLayer::new(vec![class]).with_tile_size(16.0));
}

/// The check's progress.
#[derive(Resource, Default)]
struct Check {
    settled_at: Option<u32>,
    frame: u32,
    instances: usize,
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
    if out_of_patience(&mut check.frame, PATIENCE, "rwt-asset", &mut exit) {
        return;
    }
    // The scenes stand in once the chunks are gone and every primitive is an entity.
    let drawn = match captures.get("asset") {
        None => !chunks.is_empty(),
        Some(_) => {
            check.instances == 0
                || (chunks.is_empty() && spawned.iter().count() >= 3 * check.instances)
        }
    };
    let settled = stats.settled() && drawn;
    let Some(since) = check.settled_at else {
        if settled {
            check.settled_at = Some(check.frame);
        }
        return;
    };
    if captures.pending() || check.frame < since + WAIT {
        return;
    }
    let dir = output_dir("RWT_ASSET_DIR", "target/asset_match");
    match (captures.get("asset"), captures.get("scene")) {
        (None, _) => captures.capture(&mut commands, "asset", dir),
        (Some(_), None) if check.instances == 0 => {
            let scene = server.load(format!("{FILE}#Scene0"));
            check.instances = scene_per_instance(&mut commands, &chunks, &scene);
            for layer in &layers {
                commands.entity(layer).despawn();
            }
            check.settled_at = None;
        }
        (Some(_), None) => captures.capture(&mut commands, "scene", dir),
        (Some(asset), Some(scene)) => {
            let ok = conclude(check.instances, asset, scene);
            exit.write(if ok {
                AppExit::Success
            } else {
                AppExit::error()
            });
        }
    }
}

/// Which primitive's colour a pixel shows: 0 red, 1 green, 2 blue; `None` for the sky.
fn part(p: &image::Rgb<u8>) -> Option<usize> {
    let asset = off_sky(p, BY);
    let strongest = (0..3).max_by_key(|&i| p.0[i])?;
    asset.then_some(strongest)
}

/// Intersection over union of the pixels where `a` and `b` hold.
fn iou(frames: (&image::RgbImage, &image::RgbImage), is: impl Fn(&image::Rgb<u8>) -> bool) -> f64 {
    let (mut both, mut either) = (0usize, 0usize);
    for (a, b) in frames.0.pixels().zip(frames.1.pixels()) {
        let (x, y) = (is(a), is(b));
        both += usize::from(x && y);
        either += usize::from(x || y);
    }
    both as f64 / either.max(1) as f64
}

/// Prints the result line; whether every check passed.
fn conclude(instances: usize, asset: &image::RgbImage, scene: &image::RgbImage) -> bool {
    let frames = (asset, scene);
    let count = |image: &image::RgbImage| image.pixels().filter(|p| part(p).is_some()).count();
    let (shown, spawned) = (count(asset), count(scene));
    let silhouette = iou(frames, |p| part(p).is_some());
    let parts: Vec<f64> = (0..3)
        .map(|i| iou(frames, |p| part(p) == Some(i)))
        .collect();
    let (mut both, mut colour) = (0usize, 0u64);
    for (a, b) in asset.pixels().zip(scene.pixels()) {
        if part(a).is_some() && part(b).is_some() {
            both += 1;
            colour +=
                a.0.iter()
                    .zip(b.0)
                    .map(|(x, y)| u64::from(x.abs_diff(y)))
                    .sum::<u64>();
        }
    }
    let difference = colour as f64 / (3 * both.max(1)) as f64;
    println!(
        "rwt-asset: instances {instances}, asset pixels {shown}, scene pixels {spawned}, \
         silhouette IoU {silhouette:.3}, colour difference {difference:.1}, \
         red/green/blue IoU {:.3} {:.3} {:.3}",
        parts[0], parts[1], parts[2]
    );
    let failures = [
        (instances < 20 || shown < 2_000, "too few instances in view"),
        (silhouette < LEAST_IOU, "the silhouettes differ"),
        (difference >= MOST_COLOUR, "the colours differ"),
        (
            parts.iter().any(|p| *p < LEAST_PART_IOU),
            "a primitive's colour is not where it belongs",
        ),
    ];
    passed("rwt-asset", &failures)
}
