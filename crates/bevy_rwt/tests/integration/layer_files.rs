//! Layer files and the assets layers read: loading, hot reloading, failures.

use crate::common::*;
use bevy::prelude::*;
use bevy_rwt::prelude::*;
use std::time::Duration;

#[test]
fn a_layer_file_loads_and_reloads() {
    let dir = std::env::temp_dir().join(format!("bevy_rwt_layer_test_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(
        dir.join("meadow.layer.ron"),
        r#"(tile_size: 8.0, seed: 3, chunk_size: 16.0, load_distance: 48.0, unload_distance: 64.0,
            classes: [(density: Constant(0.25), mesh: Cone(radius: 0.5, height: 2.0), material: Color(0.1, 0.5, 0.1)),
                      (density: Constant(2.0), mesh: Blade(width: 0.1, height: 0.5), material: Instanced(wind_response: 0.4))])"#,
    )
    .unwrap();
    let mut app = app_reading(&dir);
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
    // The instanced class streams into chunk buffers, drawn with the file's blade.
    let status = app.world().get::<ScatterLayerStatus>(entity).unwrap();
    let ratio = status.live_instanced as f64 / first as f64;
    assert!((ratio - 8.0).abs() < 1.0, "{first} and {status:?}");
    assert!(status.class_errors.is_empty(), "{status:?}");
    let mut chunks = app.world_mut().query::<&InstancedChunk>();
    let chunk = chunks.iter(app.world()).next().unwrap();
    assert_eq!(chunk.material.wind_response, 0.4);
    assert!((chunk.mesh_top - 0.5).abs() < 1e-6, "the blade is loaded");
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
fn a_missing_density_map_is_reported_not_silently_empty() {
    let dir = std::env::temp_dir().join(format!("bevy_rwt_missing_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mut app = app_reading(&dir);
    spawn_viewer(&mut app, Vec3::ZERO);
    let missing: Handle<Image> = app
        .world()
        .resource::<AssetServer>()
        .load("maps/nowhere.png");
    let density = LayerDensity::Image(GroundMap {
        image: missing,
        min: Vec2::splat(-64.0),
        size: Vec2::splat(128.0),
        scale: 1.0,
    });
    let painted = app.world_mut().spawn(layer(density)).id();
    let fine = app
        .world_mut()
        .spawn(layer(LayerDensity::Constant(0.2)).with_seed(4))
        .id();
    let failed = run_until(&mut app, 2_000, |app| {
        app.world().resource::<RwtStats>().layers_failed == 1
    });
    assert!(failed, "{:?}", app.world().resource::<RwtStats>());
    let status = app.world().get::<ScatterLayerStatus>(painted).unwrap();
    match &status.assets {
        AssetStatus::Failed(why) => {
            assert!(why[0].to_string().contains("maps/nowhere.png"), "{why:?}")
        }
        other => panic!("{other:?}"),
    }
    assert_eq!(status.live_entities, 0);
    // The other layer streams as usual.
    tick_app(&mut app, 2_000);
    let ok = app.world().get::<ScatterLayerStatus>(fine).unwrap();
    assert_eq!(ok.assets, AssetStatus::Ready);
    assert!(ok.live_entities > 100);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_missing_layer_file_is_reported() {
    let dir = std::env::temp_dir().join(format!("bevy_rwt_nofile_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("broken.layer.ron"), "(classes: [").unwrap();
    let mut app = app_reading(&dir);
    let server = app.world().resource::<AssetServer>().clone();
    let absent = app
        .world_mut()
        .spawn(ScatterLayerSource(server.load("absent.layer.ron")))
        .id();
    let broken = app
        .world_mut()
        .spawn(ScatterLayerSource(server.load("broken.layer.ron")))
        .id();
    let both = run_until(&mut app, 2_000, |app| {
        app.world().resource::<RwtStats>().layers_failed == 2
    });
    assert!(both, "{:?}", app.world().resource::<RwtStats>());
    for (entity, name) in [(absent, "absent.layer.ron"), (broken, "broken.layer.ron")] {
        let status = app.world().get::<ScatterLayerStatus>(entity).unwrap();
        assert!(
            matches!(&status.assets, AssetStatus::Failed(why) if why[0].to_string().contains(name)),
            "{status:?}"
        );
        assert!(app.world().get::<ScatterLayer>(entity).is_none());
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_layer_waits_for_its_map_and_streams_once_it_is_there() {
    let mut app = create_app();
    spawn_viewer(&mut app, Vec3::ZERO);
    // A handle to an image that is not in the assets yet (what a loading map looks like).
    let handle: Handle<Image> = Handle::from(bevy::asset::uuid::Uuid::from_u128(0x5ca7));
    let density = LayerDensity::Image(GroundMap {
        image: handle.clone(),
        min: Vec2::splat(-64.0),
        size: Vec2::splat(128.0),
        scale: 0.5,
    });
    let l = app.world_mut().spawn(layer(density)).id();
    for _ in 0..5 {
        app.update();
    }
    let stats = app.world().resource::<RwtStats>().clone();
    assert_eq!((stats.layers_waiting, stats.live_entities), (1, 0));
    app.world_mut()
        .resource_mut::<Assets<Image>>()
        .insert(&handle, solid_image(16, [255, 255, 255, 255]))
        .unwrap();
    tick_app(&mut app, 2_000);
    let status = app.world().get::<ScatterLayerStatus>(l).unwrap();
    assert_eq!(status.assets, AssetStatus::Ready);
    assert!(status.live_entities > 1_000, "{status:?}");
    assert_eq!(app.world().resource::<RwtStats>().layers_waiting, 0);
}

#[test]
fn a_failed_reload_keeps_the_layer_and_says_so() {
    let dir = std::env::temp_dir().join(format!("bevy_rwt_reload_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let good = r#"(tile_size: 8.0, seed: 3, chunk_size: 16.0, load_distance: 48.0, unload_distance: 64.0,
        classes: [(density: Constant(0.25), mesh: Cone(radius: 0.5, height: 2.0), material: Color(0.1, 0.5, 0.1))])"#;
    let path = dir.join("meadow.layer.ron");
    std::fs::write(&path, good).unwrap();
    // Oversized files are refused after 1 MiB, not read whole.
    let mut huge = good.to_string();
    huge.push_str(&" ".repeat(2 << 20));
    std::fs::write(dir.join("huge.layer.ron"), huge).unwrap();
    let mut app = app_reading(&dir);
    spawn_viewer(&mut app, Vec3::ZERO);
    let server = app.world().resource::<AssetServer>().clone();
    let meadow = app
        .world_mut()
        .spawn(ScatterLayerSource(server.load("meadow.layer.ron")))
        .id();
    let huge = app
        .world_mut()
        .spawn(ScatterLayerSource(server.load("huge.layer.ron")))
        .id();
    let loaded = run_until(&mut app, 2_000, |app| {
        app.world().get::<ScatterLayer>(meadow).is_some()
            && app.world().resource::<RwtStats>().layers_failed == 1
    });
    assert!(loaded, "{:?}", app.world().get::<ScatterLayerStatus>(huge));
    let status = app.world().get::<ScatterLayerStatus>(huge).unwrap();
    assert!(
        matches!(&status.assets, AssetStatus::Failed(why) if why[0].to_string().contains("larger than 1048576 bytes")),
        "{status:?}"
    );
    tick_app(&mut app, 2_000);
    let before = instances(&mut app);
    assert!(before.len() > 100);
    // A broken edit, reloaded (what a file watcher does on save): the layer keeps streaming
    // its previous version, and its status names the file and why.
    std::fs::write(&path, "(classes: [").unwrap();
    server.reload("meadow.layer.ron");
    let reported = run_until(&mut app, 2_000, |app| {
        app.world()
            .get::<ScatterLayerStatus>(meadow)
            .is_some_and(|s| s.layer_file_error.is_some())
    });
    let status = app
        .world()
        .get::<ScatterLayerStatus>(meadow)
        .unwrap()
        .clone();
    assert!(reported, "{status:?}");
    let why = status.layer_file_error.unwrap();
    assert!(why.to_string().contains("meadow.layer.ron"), "{why}");
    assert_eq!(status.assets, AssetStatus::Ready);
    tick_app(&mut app, 200);
    assert_eq!(instances(&mut app), before);
    // Fixed and reloaded: the report clears.
    std::fs::write(&path, good).unwrap();
    server.reload("meadow.layer.ron");
    let cleared = run_until(&mut app, 2_000, |app| {
        app.world()
            .get::<ScatterLayerStatus>(meadow)
            .is_some_and(|s| s.layer_file_error.is_none())
    });
    assert!(cleared);
    let _ = std::fs::remove_dir_all(&dir);
}
