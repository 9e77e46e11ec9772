//! The density brush: dabs re-scatter only what they cover, strokes undo, maps save and load.

mod common;

use bevy::prelude::*;
use bevy_rwt::brush::{BrushError, PaintedMaps};
use bevy_rwt::layers::file::NamedAssets;
use bevy_rwt::prelude::*;
use common::*;

/// A headless app with the brush, a blank map over -64..64 read by one class (up to 1
/// instance per square unit), and the brush aimed at it.
fn painted_app() -> (App, Handle<Image>) {
    let mut app = create_app_with(|app| {
        app.add_plugins(RwtBrushPlugin);
    });
    spawn_viewer(&mut app, Vec3::ZERO);
    let (map, density) = bevy_rwt::brush::blank_map(
        &mut app.world_mut().resource_mut::<Assets<Image>>(),
        64,
        Vec2::splat(-64.0),
        Vec2::splat(128.0),
        1.0,
    );
    let meadow = app
        .world_mut()
        .spawn((Name::new("meadow"), layer(density)))
        .id();
    let constant = app
        .world_mut()
        .spawn(layer(LayerDensity::Constant(0.0)))
        .id();
    let mut brush = app.world_mut().resource_mut::<DensityBrush>();
    brush.targets = vec![
        BrushTarget::new(meadow, 0, "meadow"),
        BrushTarget::new(constant, 0, "constant"),
        BrushTarget::new(meadow, 7, "no class"),
    ];
    tick_app(&mut app, 2_000);
    (app, map)
}

/// A stroke of `frames` dabs at `centre` (one per frame), then a frame without.
fn stroke(app: &mut App, target: usize, centre: Vec2, amount: f32, frames: usize) {
    for _ in 0..frames {
        app.world_mut().write_message(PaintDab {
            target,
            centre,
            radius: 8.0,
            amount,
        });
        app.update();
    }
    app.update();
}

fn command(app: &mut App, command: BrushCommand) -> Result<String, BrushError> {
    app.world_mut().write_message(command);
    app.update();
    let last = app.world_mut().resource_mut::<DensityBrush>().last.take();
    last.expect("the command reports")
}

#[test]
fn a_stroke_scatters_under_the_brush_only_and_undo_takes_it_back() {
    let (mut app, _) = painted_app();
    let blank = instances(&mut app);
    let centre = Vec2::new(20.0, -10.0);
    stroke(&mut app, 0, centre, 0.5, 2);
    tick_app(&mut app, 2_000);
    let painted = instances(&mut app);
    let added: Vec<_> = painted
        .iter()
        .filter(|(id, _)| !blank.contains_key(id))
        .collect();
    assert!(added.len() > 60, "a full dab added {}", added.len());
    assert!(
        blank.keys().all(|id| painted.contains_key(id)),
        "painting removed instances"
    );
    // Only where the brush reached (radius 8, widened by a texel of blending).
    for (_, p) in &added {
        assert!(p.xz().distance(centre) < 8.0 + 2.5, "{p}");
    }
    // A second stroke on top, then undo it: back to the first stroke's instances.
    stroke(&mut app, 0, centre + Vec2::X * 4.0, 0.5, 1);
    tick_app(&mut app, 2_000);
    assert!(instances(&mut app).len() > painted.len());
    command(&mut app, BrushCommand::Undo).unwrap();
    tick_app(&mut app, 2_000);
    assert_eq!(
        instances(&mut app)
            .keys()
            .collect::<std::collections::HashSet<_>>(),
        painted.keys().collect()
    );
    command(&mut app, BrushCommand::Undo).unwrap();
    tick_app(&mut app, 2_000);
    assert!(instances(&mut app).keys().all(|id| blank.contains_key(id)));
    assert_eq!(
        command(&mut app, BrushCommand::Undo),
        Err(BrushError::NothingToUndo)
    );
}

#[test]
fn erasing_removes_what_was_painted() {
    let (mut app, _) = painted_app();
    let blank = instances(&mut app).len();
    stroke(&mut app, 0, Vec2::ZERO, 1.0, 1);
    tick_app(&mut app, 2_000);
    assert!(instances(&mut app).len() > blank + 40);
    stroke(&mut app, 0, Vec2::ZERO, -1.0, 1);
    tick_app(&mut app, 2_000);
    assert_eq!(instances(&mut app).len(), blank);
}

#[test]
fn dabs_that_change_nothing_leave_the_map_and_its_chunks_alone() {
    let (mut app, _) = painted_app();
    let before = instances(&mut app);
    // Erasing a blank map, and painting off the map: no texel changes.
    for centre in [Vec2::new(10.0, 10.0), Vec2::new(1_000.0, 1_000.0)] {
        app.world_mut().write_message(PaintDab {
            target: 0,
            centre,
            radius: 8.0,
            amount: -1.0,
        });
        for _ in 0..3 {
            app.update();
            let pending = app.world().resource::<RwtStats>().pending_tasks;
            assert_eq!(pending, 0, "a dab that changed nothing re-scattered chunks");
        }
    }
    assert_eq!(instances(&mut app), before);
    // Nothing to undo either.
    assert_eq!(
        command(&mut app, BrushCommand::Undo),
        Err(BrushError::NothingToUndo)
    );
}

#[test]
fn maps_save_and_load_into_another_world() {
    let dir = std::env::temp_dir().join(format!("rwt-brush-{}", std::process::id()));
    let (mut app, _) = painted_app();
    stroke(&mut app, 0, Vec2::new(-30.0, 25.0), 0.8, 2);
    tick_app(&mut app, 2_000);
    let painted = instances(&mut app);
    assert!(!painted.is_empty());
    // The non-image target cannot be saved: keep only the paintable one.
    app.world_mut()
        .resource_mut::<DensityBrush>()
        .targets
        .truncate(1);
    name_marker_assets(&app);
    let saved = command(&mut app, BrushCommand::Save(dir.clone())).unwrap();
    assert!(saved.contains("saved 1 maps and 1 layer files"), "{saved}");
    let index = PaintedMaps::read(&dir).unwrap();
    assert_eq!(index.maps.len(), 1);
    assert_eq!(
        (index.maps[0].min, index.maps[0].scale),
        ((-64.0, -64.0), 1.0)
    );

    let (mut fresh, _) = painted_app();
    let loaded = command(&mut fresh, BrushCommand::Load(dir.clone())).unwrap();
    assert!(loaded.contains("loaded 1 maps"), "{loaded}");
    tick_app(&mut fresh, 2_000);
    assert_eq!(instances(&mut fresh), painted);

    // Another game loads the saved layer file, which reads the saved map beside it.
    assert_eq!(index.layers, ["meadow.layer.ron"]);
    let mut game = app_reading_with(&dir, |app| {
        app.add_plugins(RwtBrushPlugin);
    });
    name_marker_assets(&game);
    spawn_viewer(&mut game, Vec3::ZERO);
    let file = game
        .world()
        .resource::<AssetServer>()
        .load(&index.layers[0]);
    let meadow = game.world_mut().spawn(ScatterLayerSource(file)).id();
    let loaded = run_until(&mut game, 5_000, |app| {
        app.world()
            .get::<ScatterLayerStatus>(meadow)
            .map(|s| &s.assets)
            == Some(&AssetStatus::Ready)
            && app.world().get::<ScatterLayer>(meadow).is_some()
    });
    assert!(
        loaded,
        "{:?}",
        game.world().get::<ScatterLayerStatus>(meadow)
    );
    tick_app(&mut game, 2_000);
    assert_eq!(instances(&mut game), painted);
    std::fs::remove_dir_all(&dir).ok();
}

/// Names the test layers' mesh and material (the default handles), as a game names the
/// assets its layers share with layer files.
fn name_marker_assets(app: &App) {
    let names = app.world().resource::<NamedAssets>();
    names.insert_mesh("marker", Handle::default());
    names.insert_material("marker", Handle::default());
}

#[test]
fn layers_a_file_cannot_name_still_save_their_maps() {
    let dir = std::env::temp_dir().join(format!("rwt-brush-unnamed-{}", std::process::id()));
    let (mut app, _) = painted_app();
    app.world_mut()
        .resource_mut::<DensityBrush>()
        .targets
        .truncate(1);
    let err = command(&mut app, BrushCommand::Save(dir.clone())).unwrap_err();
    match &err {
        BrushError::LayerNotSaved(why) => {
            assert!(why.starts_with("meadow: ") && why.contains("mesh"), "{why}")
        }
        other => panic!("{other:?}"),
    }
    let index = PaintedMaps::read(&dir).unwrap();
    assert_eq!((index.maps.len(), index.layers.len()), (1, 0));
    assert!(dir.join(&index.maps[0].file).exists());
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn bad_targets_and_files_are_typed_errors() {
    let (mut app, _) = painted_app();
    let before = instances(&mut app);
    for (target, expected) in [
        (1, BrushError::NotPaintable("constant".into())),
        (2, BrushError::NoLayer("no class".into())),
        (9, BrushError::NoTarget(9)),
    ] {
        stroke(&mut app, target, Vec2::ZERO, 1.0, 1);
        let last = app.world_mut().resource_mut::<DensityBrush>().last.take();
        assert_eq!(last, Some(Err(expected)));
    }
    let missing = std::env::temp_dir().join("rwt-brush-no-such-dir");
    assert!(matches!(
        command(&mut app, BrushCommand::Load(missing)),
        Err(BrushError::Io(_))
    ));
    tick_app(&mut app, 2_000);
    assert_eq!(instances(&mut app), before);
}
