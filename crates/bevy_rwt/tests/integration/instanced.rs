//! Instanced classes hold exactly what the entity path would spawn: the same points, places,
//! turns, scales and classes, through level-of-detail changes, painting and a return to the
//! start; and their chunk entities never leak.

use crate::common::*;
use bevy::asset::RenderAssetUsages;
use bevy::mesh::PrimitiveTopology;
use bevy::prelude::*;
use bevy::render::render_resource::{Extent3d, TextureDimension, TextureFormat};
use bevy_rwt::instancing::InstancedChunk;
use bevy_rwt::look::InstancedClassError;
use bevy_rwt::prelude::*;
use std::collections::HashSet;

/// A layer with an entity class (sparse) and a second class on a painted map, entity or
/// instanced, with a level-of-detail fall-off.
fn two_class_layer(app: &mut App, instanced: bool) -> Handle<Image> {
    let (map, painted) = gray_map(app, 0.8);
    let bushes = ScatterClass::new(LayerDensity::Constant(0.05), default(), default());
    let grass = if instanced {
        ScatterClass::instanced(painted, default(), InstancedShading::default())
    } else {
        ScatterClass::new(painted, default(), default())
    };
    let mut l = layer(LayerDensity::Constant(0.0)).with_falloff(10.0, 70.0);
    l.classes = vec![bushes, grass];
    l.streaming.load_distance = 80.0;
    l.streaming.unload_distance = 96.0;
    app.world_mut().spawn(l);
    map
}

/// One (chunk, class) entity per loaded chunk with instances of the class; none elsewhere.
fn assert_no_leak(app: &mut App) {
    let mut statuses = app.world_mut().query::<&ScatterLayerStatus>();
    let loaded: HashSet<_> = statuses
        .iter(app.world())
        .flat_map(|s| s.loaded_chunks.iter().copied())
        .collect();
    let live_instanced: usize = statuses.iter(app.world()).map(|s| s.live_instanced).sum();
    let mut chunks = app.world_mut().query::<&InstancedChunk>();
    let mut seen = HashSet::new();
    let mut held = 0;
    for c in chunks.iter(app.world()) {
        assert!(loaded.contains(&c.chunk), "{:?} is not loaded", c.chunk);
        assert!(!c.is_empty(), "an empty chunk entity stays");
        assert!(
            seen.insert((c.chunk, c.class)),
            "two entities for {:?}",
            c.chunk
        );
        held += c.len();
    }
    assert_eq!(held, live_instanced, "status counts what the chunks hold");
}

#[test]
fn instanced_chunks_hold_what_entities_would() {
    let path = [
        Vec3::ZERO,
        Vec3::new(40.0, 0.0, 10.0),
        Vec3::new(90.0, 0.0, -20.0),
    ];
    let mut apps = [create_app(), instanced_app()];
    let maps: Vec<_> = apps
        .iter_mut()
        .enumerate()
        .map(|(i, app)| two_class_layer(app, i == 1))
        .collect();
    let viewers: Vec<_> = apps
        .iter_mut()
        .map(|app| spawn_viewer(app, path[0]))
        .collect();
    let compare = |apps: &mut [App; 2], step: &str| {
        for app in apps.iter_mut() {
            tick_app(app, 4_000);
        }
        let (entities, instanced) = (placed(&mut apps[0]), placed(&mut apps[1]));
        assert!(
            entities.len() > 1_000,
            "{step}: {} instances",
            entities.len()
        );
        assert_same(&entities, &instanced);
        assert_no_leak(&mut apps[1]);
        let stats = apps[1].world().resource::<RwtStats>();
        assert!(stats.live_instanced > 500, "{step}: {stats:?}");
    };
    compare(&mut apps, "start");
    for at in &path[1..] {
        for (app, v) in apps.iter_mut().zip(&viewers) {
            move_viewer(app, *v, *at);
        }
        compare(&mut apps, "flight");
    }
    for (app, map) in apps.iter_mut().zip(&maps) {
        paint_square(app, map, 40, 40, Color::WHITE);
    }
    compare(&mut apps, "painted");
    for (app, v) in apps.iter_mut().zip(&viewers) {
        move_viewer(app, *v, path[0]);
    }
    compare(&mut apps, "back at the start");
}

#[test]
fn instanced_chunks_go_with_their_layer() {
    let mut app = instanced_app();
    spawn_viewer(&mut app, Vec3::ZERO);
    two_class_layer(&mut app, true);
    tick_app(&mut app, 4_000);
    let mut chunks = app.world_mut().query::<&InstancedChunk>();
    assert!(chunks.iter(app.world()).count() > 4);
    let layer = app
        .world_mut()
        .query_filtered::<Entity, With<ScatterLayer>>()
        .single(app.world())
        .unwrap();
    app.world_mut().despawn(layer);
    tick_app(&mut app, 100);
    assert_eq!(chunks.iter(app.world()).count(), 0, "chunk entities leaked");
}

#[test]
fn instances_appear_at_their_level_of_detail_factor() {
    // Far from the viewer the fall-off keeps fewer points: every kept point appears at a
    // factor below its chunk's, so the shader can grow it in before its neighbours come.
    let mut app = instanced_app();
    spawn_viewer(&mut app, Vec3::ZERO);
    two_class_layer(&mut app, true);
    tick_app(&mut app, 4_000);
    let mut chunks = app.world_mut().query::<(&InstancedChunk, &Transform)>();
    let mut by_distance = Vec::new();
    for (c, t) in chunks.iter(app.world()) {
        for g in &c.buffer.instances {
            let p = t.translation + Vec3::from_array(g.offset);
            by_distance.push((Vec2::new(p.x, p.z).length(), g.appear_factor()));
        }
    }
    // Fall-off: full within 10, none from 70.
    let factor = |d: f32| (1.0 - (d - 10.0) / 60.0).clamp(0.0, 1.0);
    let band = 60.0 / 8.0;
    for (d, appear) in &by_distance {
        // Generated for the chunk's nearest band: at most one band and a chunk above.
        assert!(
            *appear <= factor(d - 16.0 * 1.5 - band) + 1e-3,
            "{d}: {appear}"
        );
    }
    let spread: HashSet<_> = by_distance.iter().map(|(_, a)| (a * 10.0) as i32).collect();
    assert!(spread.len() >= 8, "appearance factors spread over [0, 1]");
}

/// A mesh of `topology` with these positions and normals.
fn mesh(topology: PrimitiveTopology, positions: usize, normals: usize) -> Mesh {
    let mut m = Mesh::new(topology, RenderAssetUsages::default());
    if positions > 0 {
        let p: Vec<[f32; 3]> = (0..positions).map(|i| [i as f32, i as f32, 0.0]).collect();
        m.insert_attribute(Mesh::ATTRIBUTE_POSITION, p);
    }
    if normals > 0 {
        m.insert_attribute(Mesh::ATTRIBUTE_NORMAL, vec![[0.0, 0.0, 1.0]; normals]);
    }
    m
}

/// The class errors of the only layer.
fn class_errors(app: &mut App) -> Vec<(u16, InstancedClassError)> {
    let mut q = app.world_mut().query::<&ScatterLayerStatus>();
    q.single(app.world()).unwrap().class_errors.clone()
}

#[test]
fn meshes_that_cannot_be_drawn_are_reported_per_class() {
    use InstancedClassError::*;
    let mut app = create_app_with(|app| {
        app.init_asset::<Mesh>();
    });
    let mut meshes = app.world_mut().resource_mut::<Assets<Mesh>>();
    let list = PrimitiveTopology::TriangleList;
    let looks = [
        meshes.add(mesh(list, 3, 3)),
        meshes.add(mesh(list, 0, 0)),
        meshes.add(mesh(PrimitiveTopology::LineList, 2, 0)),
        meshes.add(mesh(list, 3, 2)),
        meshes.add(mesh(list, 0, 0)),
    ];
    // The last mesh is given positions but no vertex.
    let empty: Vec<[f32; 3]> = Vec::new();
    meshes
        .get_mut(&looks[4])
        .unwrap()
        .insert_attribute(Mesh::ATTRIBUTE_POSITION, empty);
    let classes = looks
        .iter()
        .map(|m| ScatterClass::instanced(LayerDensity::Constant(0.1), m.clone(), default()))
        .collect();
    let mut l = layer(LayerDensity::Constant(0.0));
    l.classes = classes;
    app.world_mut().spawn(l);
    spawn_viewer(&mut app, Vec3::ZERO);
    tick_app(&mut app, 4_000);
    let normals = AttributeLength {
        attribute: Mesh::ATTRIBUTE_NORMAL.name.to_string(),
        len: 2,
        vertices: 3,
    };
    assert_eq!(
        class_errors(&mut app),
        [
            (1, MissingPositions),
            (2, Topology(PrimitiveTopology::LineList)),
            (3, normals.clone()),
            (4, Empty)
        ]
    );
    // The classes still stream (every class has chunks) and nothing panicked.
    let mut chunks = app.world_mut().query::<&InstancedChunk>();
    let classes: HashSet<u16> = chunks.iter(app.world()).map(|c| c.class).collect();
    assert_eq!(classes.len(), 5);

    // Fixed meshes are checked again.
    let mut meshes = app.world_mut().resource_mut::<Assets<Mesh>>();
    *meshes.get_mut(&looks[1]).unwrap() = mesh(list, 3, 3);
    *meshes.get_mut(&looks[2]).unwrap() = mesh(PrimitiveTopology::TriangleStrip, 4, 0);
    app.update();
    app.update();
    assert_eq!(class_errors(&mut app), [(3, normals), (4, Empty)]);

    // A layer on the x-y plane cannot draw instanced classes.
    let mut q = app.world_mut().query::<&mut ScatterLayer>();
    let mut layer = q.single_mut(app.world_mut()).unwrap();
    layer.plane = GroundPlane::Xy;
    app.update();
    let errors = class_errors(&mut app);
    assert_eq!(errors.len(), 5, "{errors:?}");
    assert!(errors.iter().all(|(_, e)| *e == Plane(GroundPlane::Xy)));
}

#[test]
fn chunks_over_the_point_budget_are_refused_and_counted() {
    let mut app = create_app();
    app.world_mut()
        .resource_mut::<RwtSettings>()
        .chunk_point_budget = 10_000;
    spawn_viewer(&mut app, Vec3::ZERO);
    // 100 per square unit: about 25 600 points in a 16-unit chunk, over the budget.
    let grass = ScatterClass::instanced(LayerDensity::Constant(100.0), default(), default());
    let mut dense = layer(LayerDensity::Constant(0.0));
    dense.classes = vec![grass];
    let dense = app.world_mut().spawn(dense).id();
    let sparse = app
        .world_mut()
        .spawn(layer(LayerDensity::Constant(0.2)).with_seed(9))
        .id();
    tick_app(&mut app, 4_000);
    let status = app.world().get::<ScatterLayerStatus>(dense).unwrap();
    assert!(!status.loaded_chunks.is_empty());
    assert_eq!(
        status.refused_chunks,
        status.loaded_chunks.len(),
        "{status:?}"
    );
    assert_eq!(status.live_instanced, 0);
    let fine = app.world().get::<ScatterLayerStatus>(sparse).unwrap();
    assert_eq!(fine.refused_chunks, 0);
    assert!(fine.live_entities > 100);
}

#[test]
fn chunk_bounds_follow_a_mesh_that_loads_late() {
    use bevy::camera::primitives::Aabb;
    let mut app = create_app_with(|app| {
        app.init_asset::<Mesh>();
    });
    let late = app.world().resource::<Assets<Mesh>>().reserve_handle();
    let grass = ScatterClass::instanced(LayerDensity::Constant(0.5), late.clone(), default());
    let mut l = layer(LayerDensity::Constant(0.0));
    l.classes = vec![grass];
    app.world_mut().spawn(l);
    spawn_viewer(&mut app, Vec3::ZERO);
    tick_app(&mut app, 4_000);
    let tops = |app: &mut App| -> Vec<(f32, f32)> {
        let mut q = app.world_mut().query::<(&InstancedChunk, &Aabb)>();
        q.iter(app.world())
            .map(|(c, a)| (c.mesh_top, a.max().y / c.max_scale))
            .collect()
    };
    let before = tops(&mut app);
    assert!(!before.is_empty());
    // Not loaded yet: a unit box.
    assert!(
        before
            .iter()
            .all(|&(top, y)| top == 1.0 && (y - 1.0).abs() < 0.2)
    );
    // A 5-unit tall mesh arrives: every chunk drawing it is refitted.
    let tall = Mesh::from(Cuboid::new(0.2, 5.0, 0.2)).translated_by(Vec3::Y * 2.5);
    app.world_mut()
        .resource_mut::<Assets<Mesh>>()
        .insert(late.id(), tall)
        .unwrap();
    app.update();
    app.update();
    let after = tops(&mut app);
    assert_eq!(after.len(), before.len());
    assert!(
        after.iter().all(|&(top, y)| top == 5.0 && y > 4.9),
        "{after:?}"
    );
}

/// An image of `layers` layers of 4×4 texels in `format`, filled with zeros.
fn texture(dimension: TextureDimension, layers: u32, format: TextureFormat) -> Image {
    let size = Extent3d {
        width: 4,
        height: 4,
        depth_or_array_layers: layers,
    };
    let texel = vec![0; format.block_copy_size(None).unwrap() as usize];
    Image::new_fill(size, dimension, &texel, format, RenderAssetUsages::all())
}

#[test]
fn textures_that_cannot_be_drawn_are_reported_per_class() {
    use InstancedClassError::*;
    let mut app = create_app_with(|app| {
        app.init_asset::<Mesh>();
    });
    let list = PrimitiveTopology::TriangleList;
    let with_uvs =
        mesh(list, 3, 3).with_inserted_attribute(Mesh::ATTRIBUTE_UV_0, vec![[0.0f32; 2]; 3]);
    let mut meshes = app.world_mut().resource_mut::<Assets<Mesh>>();
    let (uvs, no_uvs) = (meshes.add(with_uvs), meshes.add(mesh(list, 3, 3)));
    let mut images = app.world_mut().resource_mut::<Assets<Image>>();
    let d2 = TextureDimension::D2;
    let good = images.add(texture(d2, 1, TextureFormat::Rgba8UnormSrgb));
    let integer = images.add(texture(d2, 1, TextureFormat::R32Uint));
    let volume = images.add(texture(TextureDimension::D3, 4, TextureFormat::Rgba8Unorm));
    let class = |mesh: &Handle<Mesh>, image: Option<&Handle<Image>>| {
        let material = InstancedShading {
            texture: image.cloned(),
            ..default()
        };
        ScatterClass::instanced(LayerDensity::Constant(0.1), mesh.clone(), material)
    };
    let mut l = layer(LayerDensity::Constant(0.0));
    l.classes = vec![
        class(&uvs, Some(&good)),
        class(&no_uvs, Some(&good)),
        class(&uvs, Some(&integer)),
        class(&uvs, Some(&volume)),
        class(&no_uvs, None),
    ];
    app.world_mut().spawn(l);
    spawn_viewer(&mut app, Vec3::ZERO);
    tick_app(&mut app, 4_000);
    let integer_error = Texture {
        dimension: d2,
        layers: 1,
        format: TextureFormat::R32Uint,
    };
    assert_eq!(
        class_errors(&mut app),
        [
            (1, MissingUvs),
            (2, integer_error),
            (
                3,
                Texture {
                    dimension: TextureDimension::D3,
                    layers: 4,
                    format: TextureFormat::Rgba8Unorm,
                }
            )
        ]
    );
    // The classes stream all the same; a fixed texture is checked again.
    let mut chunks = app.world_mut().query::<&InstancedChunk>();
    let classes: HashSet<u16> = chunks.iter(app.world()).map(|c| c.class).collect();
    assert_eq!(classes.len(), 5);
    let mut images = app.world_mut().resource_mut::<Assets<Image>>();
    *images.get_mut(&volume).unwrap() = texture(d2, 1, TextureFormat::Rgba8Unorm);
    app.update();
    assert_eq!(class_errors(&mut app).len(), 2);
}

#[test]
fn far_chunks_draw_the_far_mesh_and_near_ones_the_class_mesh() {
    let mut app = create_app_with(|app| {
        app.init_asset::<Mesh>();
    });
    let list = PrimitiveTopology::TriangleList;
    let mut meshes = app.world_mut().resource_mut::<Assets<Mesh>>();
    // Small meshes: a chunk's bounds grow by its mesh's reach.
    let small = |n| mesh(list, n, 0).scaled_by(Vec3::splat(0.1));
    let (near, far) = (meshes.add(small(6)), meshes.add(small(3)));
    let class = ScatterClass::instanced(LayerDensity::Constant(0.5), near.clone(), default())
        .with_instanced_far(far.clone(), 12.0);
    let mut l = layer(LayerDensity::Constant(0.0));
    l.classes = vec![class];
    app.world_mut().spawn(l);
    let viewer = spawn_viewer(&mut app, Vec3::ZERO);
    tick_app(&mut app, 4_000);
    // Each chunk's mesh follows the distance from the viewer to its bounds, with the
    // hysteresis around the boundary; its bounds hold both meshes' bounds.
    let check = |app: &mut App, eye: Vec3| {
        let mut q = app
            .world_mut()
            .query::<(&InstancedChunk, &Transform, &bevy::camera::primitives::Aabb)>();
        let (mut n, mut f) = (0, 0);
        for (chunk, at, aabb) in q.iter(app.world()) {
            let centre = Vec3::from(aabb.center) + at.translation;
            let gap = ((centre - eye).abs() - Vec3::from(aabb.half_extents)).max(Vec3::ZERO);
            let d = gap.length();
            if d < 12.0 / 1.05 {
                assert_eq!(chunk.mesh, near, "a chunk {d} m away");
                n += 1;
            } else if d > 12.0 * 1.05 {
                assert_eq!(chunk.mesh, far, "a chunk {d} m away");
                f += 1;
            }
        }
        assert!(n > 0 && f > 0, "near {n} far {f}");
    };
    check(&mut app, Vec3::ZERO);
    let eye = Vec3::new(40.0, 0.0, 8.0);
    move_viewer(&mut app, viewer, eye);
    tick_app(&mut app, 4_000);
    check(&mut app, eye);
    // The far mesh is lower than the class's (the shader's reference for colour and sway):
    // culling per instance may not choose between them per instance. Once as tall, it may.
    let per_instance = |app: &mut App| {
        let mut q = app.world_mut().query::<&InstancedChunk>();
        let chunks: Vec<bool> = q.iter(app.world()).map(|c| c.far_per_instance).collect();
        assert!(!chunks.is_empty());
        assert!(chunks.iter().all(|&p| p == chunks[0]), "every chunk alike");
        chunks[0]
    };
    assert!(!per_instance(&mut app));
    let mut meshes = app.world_mut().resource_mut::<Assets<Mesh>>();
    *meshes.get_mut(&far).unwrap() = small(6);
    app.update();
    app.update();
    assert!(per_instance(&mut app));
}
