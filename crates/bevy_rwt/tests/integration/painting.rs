//! Painted density and exclusion maps: only what the paint covers changes.

use crate::common::*;
use bevy::prelude::*;
use bevy_rwt::prelude::*;
use bevy_rwt::rwt_core::Rect;
use glam::DVec2;

#[test]
fn painting_changes_only_the_painted_region() {
    let mut app = create_app();
    spawn_viewer(&mut app, Vec3::ZERO);
    let (handle, density) = gray_map(&mut app, 1.0);
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
fn painting_an_exclusion_map_removes_only_what_it_covers() {
    let mut app = create_app();
    spawn_viewer(&mut app, Vec3::ZERO);
    let (handle, mask) = solid_map(&mut app, [0, 0, 0, 255], 1.0);
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
fn a_painted_region_message_limits_what_re_scatters() {
    // The same stroke twice: once announced with its region, once not. Only chunks under
    // the region are re-queried when it is announced.
    let run = |announce: bool| {
        let mut app = create_app();
        spawn_viewer(&mut app, Vec3::ZERO);
        let (handle, density) = gray_map(&mut app, 1.0);
        app.world_mut().spawn(layer(density));
        tick_app(&mut app, 2_000);
        let before = instances(&mut app);
        let mut loaded = app.world_mut().resource_mut::<Messages<ChunkLoaded>>();
        loaded.clear();
        paint_square(&mut app, &handle, 40, 40, Color::WHITE);
        if announce {
            let region = Rect::new(DVec2::new(16.0, -32.0), DVec2::new(32.0, -16.0)).unwrap();
            app.world_mut().write_message(DensityMapPainted {
                image: handle.id(),
                region,
            });
        }
        let mut regenerated = 0;
        for _ in 0..2_000 {
            app.update();
            let mut reader = app.world_mut().resource_mut::<Messages<ChunkLoaded>>();
            regenerated += reader.drain().count();
            let s = app.world().resource::<RwtStats>();
            if s.settled() && regenerated > 0 {
                break;
            }
        }
        let after = instances(&mut app);
        let added = after.keys().filter(|id| !before.contains_key(id)).count();
        (regenerated, added)
    };
    let (whole, added_whole) = run(false);
    let (stroke, added_stroke) = run(true);
    // The painted texels 40..48 lie in x 16..32, z -32..-16, widened by a texel for bilinear
    // blending: at most 3 x 3 chunks of 16, against every loaded chunk the map covers.
    assert!(stroke <= 9, "{stroke} chunks re-queried for the stroke");
    assert!(whole > 20, "{whole} chunks re-queried without the region");
    assert_eq!(added_stroke, added_whole, "same result either way");
    assert!(added_stroke > 20);
}

#[test]
fn repainting_one_class_map_keeps_the_others_snapshots() {
    // Two classes on two maps: painting one changes only instances of that class.
    let mut app = create_app();
    spawn_viewer(&mut app, Vec3::ZERO);
    let (grass_map, grass) = gray_map(&mut app, 0.6);
    let (_, flowers) = gray_map(&mut app, 0.6);
    let classes = vec![
        ScatterClass::new(grass, Handle::default(), Handle::default()),
        ScatterClass::new(flowers, Handle::default(), Handle::default()),
    ];
    app.world_mut().spawn(
        ScatterLayer::new(classes)
            .with_tile_size(8.0)
            .with_seed(3)
            .with_streaming(streaming()),
    );
    tick_app(&mut app, 2_000);
    let class_of = |app: &mut App| {
        let mut q = app.world_mut().query::<&ScatterEntity>();
        q.iter(app.world())
            .map(|i| (i.id, i.class))
            .collect::<std::collections::HashMap<_, _>>()
    };
    let before = class_of(&mut app);
    paint_square(&mut app, &grass_map, 40, 40, Color::BLACK);
    tick_app(&mut app, 2_000);
    let after = class_of(&mut app);
    let removed: Vec<_> = before
        .iter()
        .filter(|(id, _)| !after.contains_key(id))
        .collect();
    assert!(!removed.is_empty());
    // Class 0 is the first of the shared point set: erasing it removes some points and turns
    // others into class 1 (the classes share one point set, paper section 6.3), but adds none.
    assert!(after.keys().all(|id| before.contains_key(id)));
    let positions = instances(&mut app);
    let mut changed = 0;
    for (id, class) in &after {
        if before[id] != *class {
            changed += 1;
            assert!(in_painted_square(&positions[id]), "{:?}", positions[id]);
        }
    }
    assert!(changed > 0, "no instance changed class");
}

#[test]
fn a_layer_on_the_xy_plane_places_sprites_in_two_dimensions() {
    let mut app = create_app();
    let viewer = app
        .world_mut()
        .spawn((
            RwtViewer::all_around(),
            Transform::from_xyz(0.0, 0.0, 10.0),
            GlobalTransform::from_xyz(0.0, 0.0, 10.0),
        ))
        .id();
    let (handle, density) = gray_map(&mut app, 0.8);
    app.world_mut()
        .spawn(layer(density).on_plane(GroundPlane::Xy));
    tick_app(&mut app, 2_000);
    let live = instances(&mut app);
    assert!(live.len() > 1_000, "{}", live.len());
    // On the x-y plane around the viewer, at depth 0 plus the hashed order offset.
    assert!(live.values().all(|p| p.z >= 0.0 && p.z < 1e-3));
    assert!(live.values().any(|p| p.y > 20.0) && live.values().any(|p| p.y < -20.0));
    // Painting re-scatters in the plane: row 40..48 of the map is y -32..-16.
    let before = live;
    paint_square(&mut app, &handle, 40, 40, Color::WHITE);
    tick_app(&mut app, 2_000);
    let after = instances(&mut app);
    let added: Vec<Vec3> = after
        .iter()
        .filter(|(id, _)| !before.contains_key(id))
        .map(|(_, p)| *p)
        .collect();
    assert!(added.len() > 20);
    assert!(
        added
            .iter()
            .all(|p| p.x > 15.0 && p.x < 33.0 && p.y > -33.0 && p.y < -15.0)
    );
    let _ = viewer;
}

#[test]
fn a_map_over_the_pixel_limit_fails_its_layer_with_the_reason() {
    use bevy::render::render_resource::{Extent3d, TextureDimension, TextureFormat};
    use bevy_rwt::AssetProblem;
    let mut app = create_app();
    spawn_viewer(&mut app, Vec3::ZERO);
    // 20000 x 20000 texels declared, none allocated: the size alone is refused.
    let huge = Image::new_uninit(
        Extent3d {
            width: 20_000,
            height: 20_000,
            depth_or_array_layers: 1,
        },
        TextureDimension::D2,
        TextureFormat::R8Unorm,
        Default::default(),
    );
    let handle = app.world_mut().resource_mut::<Assets<Image>>().add(huge);
    let density = LayerDensity::Image(GroundMap {
        image: handle,
        min: Vec2::splat(-64.0),
        size: Vec2::splat(128.0),
        scale: 1.0,
    });
    let layer = app.world_mut().spawn(layer(density)).id();
    for _ in 0..5 {
        app.update();
    }
    let status = app.world().get::<ScatterLayerStatus>(layer).unwrap();
    let AssetStatus::Failed(why) = &status.assets else {
        panic!("{:?}", status.assets);
    };
    let expected = AssetProblem::TooLarge {
        width: 20_000,
        height: 20_000,
        limit: rwt_core::density::MAX_IMAGE_PIXELS,
    };
    assert_eq!(why[0].why, expected);
    assert!(why[0].to_string().contains("20000x20000"), "{}", why[0]);
    assert_eq!(app.world().resource::<RwtStats>().live_entities, 0);
}
