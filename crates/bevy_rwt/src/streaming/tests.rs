//! Headless tests of streaming: `MinimalPlugins` plus assets, no renderer.

use super::*;
use crate::layer::{LayerDensity, ScatterClass};
use crate::{RwtPlugin, RwtStats};
use bevy::asset::AssetPlugin;
use rwt_core::streaming::StreamingConfig;
use std::collections::HashMap;
use std::time::Duration;

fn create_app() -> App {
    create_app_with(|_| {})
}

/// A headless app; `extra` adds plugins before the app is finished.
fn create_app_with(extra: impl FnOnce(&mut App)) -> App {
    let mut app = App::new();
    app.add_plugins((
        MinimalPlugins,
        AssetPlugin::default(),
        RwtPlugin::default().with_spawn_budget(50_000),
    ));
    extra(&mut app);
    app.finish();
    app.cleanup();
    app
}

/// Runs frames until nothing is pending or queued (or `max` frames).
pub(super) fn tick_app(app: &mut App, max: usize) {
    for _ in 0..max {
        app.update();
        let s = app.world().resource::<RwtStats>();
        if s.pending_tasks == 0 && s.queued_spawns == 0 {
            app.update();
            let s = app.world().resource::<RwtStats>();
            if s.pending_tasks == 0 && s.queued_spawns == 0 {
                return;
            }
        }
        std::thread::sleep(Duration::from_millis(1));
    }
    panic!("streaming did not settle in {max} frames");
}

/// A `size x size` image of one colour.
pub(super) fn solid_image(size: u32, rgba: [u8; 4]) -> Image {
    use bevy::render::render_resource::{Extent3d, TextureDimension, TextureFormat};
    Image::new_fill(
        Extent3d {
            width: size,
            height: size,
            depth_or_array_layers: 1,
        },
        TextureDimension::D2,
        &rgba,
        TextureFormat::Rgba8Unorm,
        Default::default(),
    )
}

/// Paints texels `[x0, x0 + 8) x [y0, y0 + 8)` of `image` with `color`.
pub(super) fn paint_square(app: &mut App, image: &Handle<Image>, x0: u32, y0: u32, color: Color) {
    let mut images = app.world_mut().resource_mut::<Assets<Image>>();
    let mut img = images.get_mut(image).unwrap();
    for y in y0..y0 + 8 {
        for x in x0..x0 + 8 {
            img.set_color_at(x, y, color).unwrap();
        }
    }
}

/// Whether `p` lies where texels 40..48 of a 64-texel map over -64..64 reach: x in 16..32,
/// z in -32..-16 (rows count from the top, max z = 64), widened by half a texel by bilinear
/// blending.
fn in_painted_square(p: &Vec3) -> bool {
    p.x > 15.0 && p.x < 33.0 && p.z > -33.0 && p.z < -15.0
}

pub(super) fn streaming() -> StreamingConfig {
    StreamingConfig {
        chunk_size: 16.0,
        load_distance: 48.0,
        unload_distance: 64.0,
        near_distance: 20.0,
    }
}

pub(super) fn layer(density: LayerDensity) -> ScatterLayer {
    let class = ScatterClass::new(density, Handle::default(), Handle::default());
    ScatterLayer::new(vec![class])
        .with_tile_size(8.0)
        .with_seed(3)
        .with_streaming(streaming())
}

pub(super) fn spawn_viewer(app: &mut App, at: Vec3) -> Entity {
    app.world_mut()
        .spawn((
            RwtViewer::all_around(),
            Transform::from_translation(at),
            GlobalTransform::from_translation(at),
        ))
        .id()
}

pub(super) fn move_viewer(app: &mut App, viewer: Entity, at: Vec3) {
    let mut e = app.world_mut().entity_mut(viewer);
    *e.get_mut::<Transform>().unwrap() = Transform::from_translation(at);
    *e.get_mut::<GlobalTransform>().unwrap() = GlobalTransform::from_translation(at);
}

pub(super) fn instances(app: &mut App) -> HashMap<rwt_core::query::PointId, Vec3> {
    let mut q = app.world_mut().query::<(&ScatterInstance, &Transform)>();
    let mut out = HashMap::new();
    for (i, t) in q.iter(app.world()) {
        assert!(
            out.insert(i.id, t.translation).is_none(),
            "two live instances share {:?}",
            i.id
        );
    }
    out
}

#[test]
fn streams_around_a_viewer_without_duplicates() {
    let mut app = create_app();
    spawn_viewer(&mut app, Vec3::ZERO);
    app.world_mut().spawn(layer(LayerDensity::Constant(0.5)));
    tick_app(&mut app, 2_000);
    let live = instances(&mut app);
    let stats = app.world().resource::<RwtStats>().clone();
    assert_eq!(live.len(), stats.live_instances);
    // About 0.5 per square unit over the loaded chunks.
    let area = stats.loaded_chunks as f64 * 16.0 * 16.0;
    assert!(
        (live.len() as f64 - 0.5 * area).abs() < 0.05 * 0.5 * area,
        "{} vs {}",
        live.len(),
        0.5 * area
    );
    // Every instance lies in a loaded chunk near the viewer, on the ground.
    assert!(
        live.values()
            .all(|p| p.y == 0.0 && Vec2::new(p.x, p.z).length() < 48.0 + 23.0)
    );
}

#[test]
fn a_round_trip_returns_to_the_same_instances_and_stays_bounded() {
    // The path: 41 stops 10 units apart, out along a diagonal.
    let stop = |i: usize| {
        let x = i as f32 * 10.0;
        Vec3::new(x, 0.0, x * 0.5)
    };
    let mut app = create_app();
    let viewer = spawn_viewer(&mut app, stop(40));
    app.world_mut().spawn(layer(LayerDensity::Constant(0.3)));
    // Arrive at the start along the path, as the return will: chunks kept by hysteresis
    // (between load and unload distance) depend on where the viewer came from.
    let fly = |app: &mut App, stops: &mut dyn Iterator<Item = usize>| {
        let mut most = 0;
        for i in stops {
            move_viewer(app, viewer, stop(i));
            tick_app(app, 2_000);
            most = most.max(instances(app).len());
        }
        most
    };
    fly(&mut app, &mut (0..=40).rev());
    let start = instances(&mut app);
    let most = fly(&mut app, &mut (0..=40)).max(fly(&mut app, &mut (0..=40).rev()));
    let end = instances(&mut app);
    assert!(start.len() > 1_000, "{} instances", start.len());
    assert!(
        start == end,
        "{} instances at the start, {} at the end",
        start.len(),
        end.len()
    );
    // Bounded: never more than the unload disc can hold.
    let cap = 0.3 * std::f64::consts::PI * (64.0f64 + 23.0).powi(2);
    assert!((most as f64) < cap, "{most} live instances");
}

#[test]
fn two_runs_give_the_same_world() {
    let run = || {
        let mut app = create_app();
        let viewer = spawn_viewer(&mut app, Vec3::ZERO);
        app.world_mut().spawn(layer(LayerDensity::Noise(
            rwt_core::density::NoiseDensity::new(2, 0.05, 3, 0.5, 0.5, 0.8),
        )));
        for i in 0..10 {
            move_viewer(&mut app, viewer, Vec3::new(i as f32 * 7.0, 0.0, 0.0));
            tick_app(&mut app, 2_000);
        }
        let mut v: Vec<_> = instances(&mut app)
            .into_iter()
            .map(|(id, p)| (id, p.x.to_bits(), p.z.to_bits()))
            .collect();
        v.sort();
        v
    };
    assert_eq!(run(), run());
}

#[test]
fn approaching_adds_instances_and_moves_none() {
    let mut app = create_app();
    let viewer = spawn_viewer(&mut app, Vec3::new(-150.0, 0.0, 0.0));
    let mut l = layer(LayerDensity::Constant(0.6)).with_falloff(10.0, 120.0);
    l.streaming.load_distance = 160.0;
    l.streaming.unload_distance = 200.0;
    app.world_mut().spawn(l);
    tick_app(&mut app, 4_000);
    let far = instances(&mut app);
    let near_origin = |m: &HashMap<_, Vec3>| {
        m.values()
            .filter(|p| Vec2::new(p.x, p.z).length() < 8.0)
            .count()
    };
    move_viewer(&mut app, viewer, Vec3::new(-20.0, 0.0, 0.0));
    tick_app(&mut app, 4_000);
    let near = instances(&mut app);
    assert!(
        near_origin(&near) > near_origin(&far) + 10,
        "{} -> {}",
        near_origin(&far),
        near_origin(&near)
    );
    for (id, p) in &far {
        if Vec2::new(p.x, p.z).length() < 30.0 {
            assert_eq!(
                near.get(id),
                Some(p),
                "an instance near the origin moved or vanished"
            );
        }
    }
}

#[test]
fn removing_a_layer_despawns_everything() {
    let mut app = create_app();
    spawn_viewer(&mut app, Vec3::ZERO);
    let l = app
        .world_mut()
        .spawn(layer(LayerDensity::Constant(0.4)))
        .id();
    tick_app(&mut app, 2_000);
    assert!(!instances(&mut app).is_empty());
    app.world_mut().entity_mut(l).remove::<ScatterLayer>();
    app.update();
    app.update();
    assert!(instances(&mut app).is_empty());
}

#[test]
fn painting_changes_only_the_painted_region() {
    let mut app = create_app();
    spawn_viewer(&mut app, Vec3::ZERO);
    let size = 64u32;
    let image = solid_image(size, [128, 128, 128, 255]);
    let handle = app.world_mut().resource_mut::<Assets<Image>>().add(image);
    let density = LayerDensity::Image {
        image: handle.clone(),
        min: Vec2::splat(-64.0),
        size: Vec2::splat(128.0),
        scale: 1.0,
    };
    app.world_mut().spawn(layer(density));
    tick_app(&mut app, 2_000);
    let before = instances(&mut app);
    paint_square(&mut app, &handle, 40, 40, Color::WHITE);
    tick_app(&mut app, 2_000);
    let after = instances(&mut app);
    let added: Vec<_> = after
        .iter()
        .filter(|(id, _)| !before.contains_key(id))
        .collect();
    let removed = before.keys().filter(|id| !after.contains_key(id)).count();
    assert!(added.len() > 20, "painting added {} instances", added.len());
    assert_eq!(removed, 0);
    assert!(added.iter().all(|(_, p)| in_painted_square(p)), "{added:?}");
}

#[test]
fn removing_the_viewer_unloads_everything() {
    let mut app = create_app();
    let viewer = spawn_viewer(&mut app, Vec3::ZERO);
    app.world_mut().spawn(layer(LayerDensity::Constant(0.4)));
    tick_app(&mut app, 2_000);
    assert!(!instances(&mut app).is_empty());
    app.world_mut().despawn(viewer);
    tick_app(&mut app, 2_000);
    assert!(instances(&mut app).is_empty());
    let stats = app.world().resource::<RwtStats>();
    assert_eq!((stats.live_instances, stats.loaded_chunks), (0, 0));
}

#[test]
fn height_range_and_slope_filters() {
    use crate::layer::HeightSource;
    use std::sync::Arc;
    let mut app = create_app();
    spawn_viewer(&mut app, Vec3::ZERO);
    // Flat at 0 for x < 0; a ramp of slope 2 for x >= 0 (too steep); a plateau at 4 from x = 2.
    let ground = |p: Vec2| if p.x < 0.0 { 0.0 } else { (2.0 * p.x).min(4.0) };
    let steep_free = layer(LayerDensity::Constant(0.5))
        .with_height(HeightSource::Function(Arc::new(ground)))
        .with_max_slope(1.0)
        .with_height_range(-1.0, 3.0);
    app.world_mut().spawn(steep_free);
    tick_app(&mut app, 2_000);
    let live = instances(&mut app);
    assert!(live.len() > 500);
    // Left of the ramp only (the plateau at height 4 is out of range, the ramp too steep).
    assert!(
        live.values().all(|p| p.x < 0.3 && p.y == 0.0),
        "{:?}",
        live.values().find(|p| p.x >= 0.3)
    );
}

#[test]
fn a_heightmap_image_lifts_instances() {
    use crate::layer::HeightSource;
    let mut app = create_app();
    spawn_viewer(&mut app, Vec3::ZERO);
    let white = solid_image(4, [255, 255, 255, 255]);
    let handle = app.world_mut().resource_mut::<Assets<Image>>().add(white);
    let height = HeightSource::Image {
        image: handle,
        min: Vec2::splat(-100.0),
        size: Vec2::splat(200.0),
        scale: 7.5,
    };
    app.world_mut()
        .spawn(layer(LayerDensity::Constant(0.3)).with_height(height));
    tick_app(&mut app, 2_000);
    let live = instances(&mut app);
    assert!(!live.is_empty());
    assert!(
        live.values().all(|p| (p.y - 7.5).abs() < 1e-4),
        "{:?}",
        live.values().next()
    );
}

#[test]
fn replacing_a_layer_restreams_it() {
    let mut app = create_app();
    spawn_viewer(&mut app, Vec3::ZERO);
    let l = app
        .world_mut()
        .spawn(layer(LayerDensity::Constant(0.2)))
        .id();
    tick_app(&mut app, 2_000);
    let sparse = instances(&mut app).len();
    app.world_mut()
        .entity_mut(l)
        .insert(layer(LayerDensity::Constant(0.6)));
    tick_app(&mut app, 2_000);
    let dense = instances(&mut app);
    let ratio = dense.len() as f64 / sparse as f64;
    assert!((ratio - 3.0).abs() < 0.2, "{sparse} -> {}", dense.len());
    let stats = app.world().resource::<RwtStats>();
    assert_eq!(
        stats.live_instances,
        dense.len(),
        "no leftovers of the old layer"
    );
}

#[test]
fn a_layer_file_loads_and_reloads() {
    use crate::layer_asset::{ScatterLayerAsset, ScatterLayerSource};
    let dir = std::env::temp_dir().join(format!("bevy_rwt_layer_test_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(
        dir.join("meadow.layer.ron"),
        r#"(tile_size: 8.0, seed: 3, chunk_size: 16.0, load_distance: 48.0, unload_distance: 64.0,
            classes: [(density: Constant(0.25), mesh: Cone(radius: 0.5, height: 2.0), material: Color(0.1, 0.5, 0.1))])"#,
    )
    .unwrap();
    let mut app = App::new();
    app.add_plugins((
        MinimalPlugins,
        AssetPlugin {
            file_path: dir.to_string_lossy().into_owned(),
            ..Default::default()
        },
        RwtPlugin::default().with_spawn_budget(50_000),
    ))
    .init_asset::<Mesh>()
    .init_asset::<StandardMaterial>();
    app.finish();
    app.cleanup();
    spawn_viewer(&mut app, Vec3::ZERO);
    let handle: Handle<ScatterLayerAsset> = app
        .world()
        .resource::<AssetServer>()
        .load("meadow.layer.ron");
    let entity = app
        .world_mut()
        .spawn(ScatterLayerSource(handle.clone()))
        .id();
    for _ in 0..2_000 {
        app.update();
        if app.world().get::<ScatterLayer>(entity).is_some() {
            break;
        }
        std::thread::sleep(Duration::from_millis(1));
    }
    assert!(
        app.world().get::<ScatterLayer>(entity).is_some(),
        "the layer file never loaded"
    );
    tick_app(&mut app, 2_000);
    let first = instances(&mut app).len();
    assert!(first > 100);
    // What a file watcher does on save: the asset changes, the layer restreams.
    {
        let mut assets = app.world_mut().resource_mut::<Assets<ScatterLayerAsset>>();
        let mut asset = assets.get_mut(&handle).unwrap();
        asset.0.classes[0].density = LayerDensity::Constant(0.75);
    }
    for _ in 0..5 {
        app.update();
    }
    tick_app(&mut app, 2_000);
    let second = instances(&mut app).len();
    let ratio = second as f64 / first as f64;
    assert!((ratio - 3.0).abs() < 0.25, "{first} -> {second}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_camera_streams_what_it_can_see() {
    let mut app = create_app();
    let looking = Transform::from_xyz(0.0, 2.0, 0.0).looking_to(Vec3::X, Vec3::Y);
    let projection = Projection::Perspective(PerspectiveProjection {
        fov: 60f32.to_radians(),
        aspect_ratio: 1.0,
        ..Default::default()
    });
    app.world_mut().spawn((
        RwtViewer::default(),
        projection,
        looking,
        GlobalTransform::from(looking),
    ));
    app.world_mut().spawn(layer(LayerDensity::Constant(0.3)));
    tick_app(&mut app, 2_000);
    let live = instances(&mut app);
    let ahead = live.values().filter(|p| p.x > 30.0).count();
    // The near ring (20) loads whole chunks (16): nothing beyond 36 behind.
    let behind = live.values().filter(|p| p.x < -36.0).count();
    assert!(ahead > 100, "{ahead} ahead");
    assert_eq!(behind, 0, "nothing far behind the camera");
    // Far to the side, outside 30 + 15 degrees of the view, nothing either.
    assert!(
        live.values()
            .all(|p| p.x > -24.0 || Vec2::new(p.x, p.z).length() < 48.0)
    );
    assert!(
        !live
            .values()
            .any(|p| p.x > 10.0 && p.z.abs() > p.x * 1.6 + 24.0),
        "outside the cone"
    );
}

#[test]
fn gizmos_outline_loaded_chunks_and_their_tiles() {
    use crate::debug::{RwtGizmos, outlines};
    let mut app = create_app();
    spawn_viewer(&mut app, Vec3::ZERO);
    let l = app
        .world_mut()
        .spawn(layer(LayerDensity::Constant(0.1)))
        .id();
    tick_app(&mut app, 2_000);
    let (layer, state) = app
        .world_mut()
        .query::<(&ScatterLayer, &LayerState)>()
        .get(app.world(), l)
        .unwrap();
    let chunks = state.loaded();
    let only_chunks = outlines(
        layer,
        state,
        &RwtGizmos {
            chunks: true,
            tiles: false,
            lift: 0.1,
        },
    );
    assert_eq!(only_chunks.len(), chunks);
    let both = outlines(
        layer,
        state,
        &RwtGizmos {
            chunks: true,
            tiles: true,
            lift: 0.1,
        },
    );
    // Chunks of 16 over tiles of 8: four tiles per chunk.
    assert_eq!(both.iter().filter(|o| o.2).count(), 4 * chunks);
    assert!(both.iter().filter(|o| o.2).all(|o| o.1 == 8.0));
}

#[test]
fn the_plugin_has_no_system_ambiguities() {
    use bevy::ecs::schedule::{LogLevel, ScheduleBuildSettings};
    // Every pair of plugin systems touching the same data is ordered: the schedule refuses to
    // build otherwise (what `bevy_rapier` checks in its CI).
    let mut app = create_app_with(|app| {
        app.edit_schedule(Update, |schedule| {
            schedule.set_build_settings(ScheduleBuildSettings {
                ambiguity_detection: LogLevel::Error,
                ..default()
            });
        });
    });
    spawn_viewer(&mut app, Vec3::ZERO);
    app.world_mut().spawn(layer(LayerDensity::Constant(0.2)));
    tick_app(&mut app, 2_000);
    assert!(app.world().resource::<RwtStats>().live_instances > 0);
}

#[test]
fn painting_an_exclusion_map_removes_only_what_it_covers() {
    let mut app = create_app();
    spawn_viewer(&mut app, Vec3::ZERO);
    let handle = app
        .world_mut()
        .resource_mut::<Assets<Image>>()
        .add(solid_image(64, [0, 0, 0, 255]));
    let mask = LayerDensity::Image {
        image: handle.clone(),
        min: Vec2::splat(-64.0),
        size: Vec2::splat(128.0),
        scale: 1.0,
    };
    app.world_mut()
        .spawn(layer(LayerDensity::Constant(0.5)).with_exclusion(mask));
    tick_app(&mut app, 2_000);
    let before = instances(&mut app);
    assert!(before.len() > 1000, "{} instances", before.len());
    paint_square(&mut app, &handle, 40, 40, Color::WHITE);
    tick_app(&mut app, 2_000);
    let after = instances(&mut app);
    let removed: Vec<_> = before
        .iter()
        .filter(|(id, _)| !after.contains_key(id))
        .collect();
    assert!(removed.len() > 50, "excluded {} instances", removed.len());
    assert!(
        after.keys().all(|id| before.contains_key(id)),
        "exclusion added instances"
    );
    // Removed: inside the painted square (widened by bilinear blending); kept: outside it,
    // and nothing remains well inside it.
    assert!(
        removed.iter().all(|(_, p)| in_painted_square(p)),
        "{removed:?}"
    );
    assert!(
        !after
            .values()
            .any(|p| p.x > 17.0 && p.x < 31.0 && p.z > -31.0 && p.z < -17.0)
    );
}

#[test]
fn a_custom_class_inserts_its_own_components() {
    #[derive(Component)]
    struct Tree(u32);
    let mut app = create_app();
    spawn_viewer(&mut app, Vec3::ZERO);
    let meshes = ScatterClass::new(
        LayerDensity::Constant(0.2),
        Handle::default(),
        Handle::default(),
    );
    let trees = ScatterClass::custom(LayerDensity::Constant(0.1), |e| {
        e.insert(Tree(7));
    });
    app.world_mut().spawn(
        ScatterLayer::new(vec![meshes, trees])
            .with_tile_size(8.0)
            .with_streaming(streaming()),
    );
    tick_app(&mut app, 2_000);
    let mut q = app
        .world_mut()
        .query::<(&ScatterInstance, Has<Mesh3d>, Option<&Tree>)>();
    let (mut mesh_count, mut tree_count) = (0, 0);
    for (instance, has_mesh, tree) in q.iter(app.world()) {
        match instance.class {
            0 => {
                assert!(has_mesh && tree.is_none());
                mesh_count += 1;
            }
            _ => {
                assert!(!has_mesh && tree.is_some_and(|t| t.0 == 7));
                tree_count += 1;
            }
        }
    }
    // One third of the instances are trees.
    let share = tree_count as f64 / (mesh_count + tree_count) as f64;
    assert!(
        (share - 1.0 / 3.0).abs() < 0.05,
        "{tree_count} trees of {}",
        mesh_count + tree_count
    );
}
