//! Streaming around viewers: loading, unloading, level of detail, filters, determinism.

use crate::common::*;
use bevy::prelude::*;
use bevy_rwt::prelude::*;
use std::collections::HashMap;

#[test]
fn streams_around_a_viewer_without_duplicates() {
    let mut app = create_app();
    spawn_viewer(&mut app, Vec3::ZERO);
    app.world_mut().spawn(layer(LayerDensity::Constant(0.5)));
    tick_app(&mut app, 2_000);
    let live = instances(&mut app);
    let stats = app.world().resource::<RwtStats>().clone();
    assert_eq!(live.len(), stats.live_entities);
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
            bevy_rwt::rwt_core::NoiseDensity::new(bevy_rwt::rwt_core::NoiseParams {
                seed: 2,
                frequency: 0.05,
                octaves: 3,
                base: 0.5,
                amplitude: 0.5,
                scale: 0.8,
            }),
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
    assert_eq!((stats.live_entities, stats.loaded_chunks), (0, 0));
}

#[test]
fn height_range_and_slope_filters() {
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
    let mut app = create_app();
    spawn_viewer(&mut app, Vec3::ZERO);
    let white = solid_image(4, [255, 255, 255, 255]);
    let handle = app.world_mut().resource_mut::<Assets<Image>>().add(white);
    let height = HeightSource::Image(GroundMap {
        image: handle,
        min: Vec2::splat(-100.0),
        size: Vec2::splat(200.0),
        scale: 7.5,
    });
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
        stats.live_entities,
        dense.len(),
        "no leftovers of the old layer"
    );
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
    assert!(app.world().resource::<RwtStats>().live_entities > 0);
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
        .query::<(&ScatterEntity, Has<Mesh3d>, Option<&Tree>)>();
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

#[test]
fn a_class_with_a_far_look_crossfades_between_its_two_meshes() {
    use bevy::camera::visibility::VisibilityRange;
    let mut app = create_app();
    spawn_viewer(&mut app, Vec3::ZERO);
    let far_mesh = Handle::<Mesh>::default();
    let class = ScatterClass::new(
        LayerDensity::Constant(0.05),
        Handle::default(),
        Handle::default(),
    )
    .with_lod(far_mesh.clone(), Handle::default(), 40.0);
    app.world_mut().spawn(
        ScatterLayer::new(vec![class])
            .with_tile_size(8.0)
            .with_streaming(streaming()),
    );
    tick_app(&mut app, 2_000);
    let mut q = app
        .world_mut()
        .query::<(&ScatterEntity, &VisibilityRange, &Children)>();
    let near: Vec<(VisibilityRange, Entity)> = q
        .iter(app.world())
        .map(|(_, r, c)| {
            assert_eq!(c.len(), 1, "one far child");
            (r.clone(), c[0])
        })
        .collect();
    assert!(near.len() > 100, "{} instances", near.len());
    assert_eq!(
        near.len(),
        instances(&mut app).len(),
        "every instance has its far look"
    );
    for (range, child) in near {
        assert_eq!(
            (range.start_margin, range.end_margin.clone()),
            (0.0..0.0, 38.0..42.0)
        );
        let far = app.world().get::<VisibilityRange>(child).unwrap();
        assert_eq!(
            far.start_margin, range.end_margin,
            "the crossfade bands match"
        );
        assert!(far.end_margin.start > 1e6);
        assert!(
            app.world().get::<ScatterEntity>(child).is_none(),
            "counted once"
        );
    }
    // Unloading despawns the far looks with their instances.
    let viewer = app
        .world_mut()
        .query_filtered::<Entity, With<RwtViewer>>()
        .single(app.world())
        .unwrap();
    move_viewer(&mut app, viewer, Vec3::new(5_000.0, 0.0, 0.0));
    tick_app(&mut app, 2_000);
    move_viewer(&mut app, viewer, Vec3::new(10_000.0, 0.0, 0.0));
    tick_app(&mut app, 2_000);
    let far_left = app
        .world_mut()
        .query_filtered::<(), (With<VisibilityRange>, Without<ScatterEntity>)>()
        .iter(app.world())
        .count();
    let live = instances(&mut app).len();
    assert_eq!(far_left, live);
}
