//! glTF assets: a file written by `testing::glb`, loaded by Bevy's glTF loader headless,
//! read back as a node tree, split into levels of detail and colliders, resolved for the
//! instanced path, and streamed as an asset class beside a class whose file is broken, in
//! code and from a layer file.

use crate::common::{app_reading_with, layer, run_until, spawn_viewer};
use bevy::camera::primitives::MeshAabb;
use bevy::gltf::{Gltf, GltfMesh, GltfNode, GltfPlugin};
use bevy::platform::collections::HashMap;
use bevy::prelude::*;
use bevy_rwt::instancing::{InstancedChunk, PromotedInstance};
use bevy_rwt::layers::file::LayerDescription;
use bevy_rwt::look::InstancedClassError;
use bevy_rwt::look::asset::{
    AssetCollider, AssetLook, AssetLookError, AssetParts, AssetPrimitive, AssetRoot,
    AssetTreeError, GltfAssets, MsftLodTable, SurfaceAlpha, asset_tree, resolve_asset,
};
use bevy_rwt::prelude::*;
use bevy_rwt::testing::glb::{Glb, GlbAlpha, GlbMaterial, GlbNode, GlbPrimitive};

/// A tree: two levels (bark and masked leaves near, one card far), a collision hull.
fn tree() -> Glb {
    let mut file = Glb::default();
    let bark = file.add_material(GlbMaterial::colored([0.3, 0.2, 0.1, 1.0]));
    let leaves = file.add_material(GlbMaterial {
        alpha: GlbAlpha::Mask(0.5),
        double_sided: true,
        ..GlbMaterial::colored([0.2, 0.6, 0.1, 1.0])
    });
    let mesh = |shape: Mesh, material| GlbPrimitive::from_mesh(&shape, material).unwrap();
    let near = file.add_mesh(vec![
        mesh(Cylinder::new(0.3, 4.0).mesh().build(), bark),
        mesh(Sphere::new(1.5).mesh().build(), leaves),
    ]);
    let far = file.add_mesh(vec![mesh(
        Cuboid::new(2.0, 5.0, 0.1).mesh().build(),
        leaves,
    )]);
    let hull = file.add_mesh(vec![mesh(Cylinder::new(0.35, 4.0).mesh().build(), bark)]);
    // Both levels stand on the asset's origin once their nodes' transforms are applied.
    let up = Transform::from_xyz(0.0, 2.0, 0.0);
    let lod0 = file.add_node(
        GlbNode::named("oak_LOD0")
            .with_mesh(near)
            .with_transform(up),
    );
    let lod1 = file.add_node(GlbNode::named("oak_LOD1").with_mesh(far).with_transform(up));
    let collider = file.add_node(
        GlbNode::named("UCX_oak")
            .with_mesh(hull)
            .with_transform(Transform::from_xyz(0.0, 2.0, 0.0)),
    );
    let root = file.add_node(GlbNode::named("oak").with_children([lod0, lod1, collider]));
    file.add_root(root);
    file
}

#[test]
fn a_written_asset_loads_and_splits_into_levels_and_a_collider() {
    let (mut app, dir) = gltf_app("assets", &[("oak.glb", &tree().to_bytes())]);
    let handle: Handle<Gltf> = app.world().resource::<AssetServer>().load("oak.glb");
    let loaded = bevy_rwt::testing::run_until(&mut app, 2_000, |app| {
        app.world()
            .resource::<AssetServer>()
            .is_loaded_with_dependencies(&handle)
    });
    assert!(loaded, "oak.glb did not load");
    check_resolved(&mut app, &handle);
    let world = app.world();
    let gltf = world.resource::<Assets<Gltf>>().get(&handle).unwrap();
    let from = GltfAssets {
        nodes: world.resource::<Assets<GltfNode>>(),
        meshes: world.resource::<Assets<GltfMesh>>(),
        materials: world.resource(),
        lods: None,
    };
    let tree = |root: AssetRoot| asset_tree(gltf, &root, from);
    // The file, its only scene and its root node name the same tree.
    let parts = AssetParts::split(&tree(AssetRoot::File).unwrap());
    let scene = AssetParts::split(&tree(AssetRoot::Scene(0)).unwrap());
    let oak = AssetParts::split(&tree(AssetRoot::Node("oak".into())).unwrap());
    assert_eq!((&scene, &oak), (&parts, &parts));
    // A node alone: one level, no collider.
    let far = AssetParts::split(&tree(AssetRoot::Node("oak_LOD1".into())).unwrap());
    assert_eq!(
        (far.levels.len(), far.levels[0].len(), far.colliders.len()),
        (1, 1, 0)
    );
    let missing = AssetRoot::Node("elm".into());
    assert_eq!(
        tree(missing).unwrap_err(),
        AssetTreeError::NoSuchNode("elm".into())
    );
    assert_eq!(
        tree(AssetRoot::Scene(1)).unwrap_err(),
        AssetTreeError::NoSuchScene(1)
    );
    assert_eq!(parts.levels.len(), 2);
    assert_eq!(parts.levels[0].len(), 2, "bark and leaves near");
    assert_eq!(parts.levels[1].len(), 1, "one card far");
    assert_eq!(parts.colliders.len(), 1);
    assert_eq!(
        parts.colliders[0].transform.translation,
        Vec3::new(0.0, 2.0, 0.0)
    );
    // Every primitive's mesh loaded with the vertices written.
    let meshes = world.resource::<Assets<Mesh>>();
    let vertices = |p: &AssetPrimitive| meshes.get(&p.mesh).unwrap().count_vertices();
    let cylinder = Cylinder::new(0.3, 4.0).mesh().build().count_vertices();
    assert_eq!(vertices(&parts.levels[0][0].primitive), cylinder);
    // The leaves' material is masked and double-sided; the bark's opaque.
    let materials = world.resource::<Assets<bevy::gltf::GltfMaterial>>();
    let material = |p: &AssetPrimitive| materials.get(p.material.as_ref().unwrap()).unwrap();
    let leaves = material(&parts.levels[0][1].primitive);
    assert_eq!(leaves.alpha_mode, AlphaMode::Mask(0.5));
    assert!(leaves.double_sided);
    assert_eq!(
        material(&parts.levels[0][0].primitive).alpha_mode,
        AlphaMode::Opaque
    );
    std::fs::remove_dir_all(&dir).ok();
}

/// The tree resolved for drawing: its levels' meshes moved by their nodes into the asset's
/// frame, their surfaces, the collider's mesh, the bounds of every level.
fn check_resolved(app: &mut App, handle: &Handle<Gltf>) {
    let world = app.world_mut();
    let resolved = world.resource_scope(|world, mut meshes: Mut<Assets<Mesh>>| {
        let from = GltfAssets {
            nodes: world.resource(),
            meshes: world.resource(),
            materials: world.resource(),
            lods: None,
        };
        let gltf = world.resource::<Assets<Gltf>>().get(handle).unwrap();
        resolve_asset(gltf, &AssetRoot::File, from, &mut meshes).unwrap()
    });
    let sizes: Vec<usize> = resolved.levels.iter().map(Vec::len).collect();
    assert_eq!((sizes, resolved.colliders.len()), (vec![2, 1], 1));
    let (lo, hi) = resolved.bounds;
    assert!(
        (lo.y + 0.5).abs() < 1e-4 && (hi.y - 4.5).abs() < 1e-4,
        "{lo} {hi}"
    );
    let meshes = world.resource::<Assets<Mesh>>();
    let lowest = |mesh: &Handle<Mesh>| meshes.get(mesh).unwrap().compute_aabb().unwrap().min().y;
    let [bark, leaves] = &resolved.levels[0][..] else {
        unreachable!()
    };
    // The node's 2 m lift is in the meshes: the trunk stands on the origin.
    assert!(lowest(&bark.mesh).abs() < 1e-4 && (lowest(&leaves.mesh) - 0.5).abs() < 1e-4);
    assert_eq!(bark.surface.alpha, SurfaceAlpha::Opaque);
    assert_eq!(leaves.surface.alpha, SurfaceAlpha::Mask(0.5));
    assert!(leaves.surface.double_sided && !bark.surface.double_sided);
    assert!((lowest(&resolved.colliders[0]) - 0.0).abs() < 1e-4);
}

/// A headless app with Bevy's glTF loader, reading a fresh folder holding `files`.
fn gltf_app(name: &str, files: &[(&str, &[u8])]) -> (App, std::path::PathBuf) {
    let dir = std::env::temp_dir().join(format!("bevy_rwt_{name}_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    for (file, bytes) in files {
        std::fs::write(dir.join(file), bytes).unwrap();
    }
    let app = app_reading_with(&dir, |app| {
        // The loader also makes the file's scenes: their asset type, without the scene
        // plugins a game has.
        app.add_plugins(GltfPlugin::default())
            .init_asset::<bevy::world_serialization::WorldAsset>();
    });
    (app, dir)
}

#[test]
fn an_asset_class_draws_each_primitive_and_a_bad_file_fails_alone() {
    let bytes = tree().to_bytes();
    let broken = &bytes[..bytes.len() / 3];
    let (mut app, dir) = gltf_app(
        "asset_class",
        &[("oak.glb", &bytes), ("broken.glb", broken)],
    );
    let server = app.world().resource::<AssetServer>().clone();
    let oak = AssetLook::new(server.load("oak.glb"));
    let broken = AssetLook::new(server.load("broken.glb"));
    let density = LayerDensity::Constant(0.05);
    let mut l = layer(density.clone());
    l.classes = vec![
        ScatterClass::asset(density.clone(), oak),
        ScatterClass::asset(density, broken),
    ];
    let layer_entity = app.world_mut().spawn(l).id();
    spawn_viewer(&mut app, Vec3::ZERO);
    let drawn = run_until(&mut app, 2_000, |app| {
        let any = app
            .world()
            .iter_entities()
            .any(|e| e.contains::<InstancedChunk>());
        let status = app.world().get::<ScatterLayerStatus>(layer_entity).unwrap();
        any && !status.class_errors.is_empty() && status.pending_tasks == 0
    });
    assert!(
        drawn,
        "the asset class drew nothing, or the broken one reported nothing"
    );
    let status = app.world().get::<ScatterLayerStatus>(layer_entity).unwrap();
    let [(1, InstancedClassError::Asset(e))] = &status.class_errors[..] else {
        panic!("{:?}", status.class_errors);
    };
    assert!(matches!(**e, AssetLookError::Load(_)), "{e}");
    // Per chunk, one entity per primitive of each level, sharing one buffer; the near
    // level fades out over the band the far one fades in over.
    let mut chunks = app.world_mut().query::<&InstancedChunk>();
    let mut per_chunk: HashMap<_, Vec<&InstancedChunk>> = HashMap::new();
    for c in chunks.iter(app.world()) {
        assert_eq!(c.class, 0, "the broken class draws nothing");
        per_chunk.entry(c.chunk).or_default().push(c);
    }
    for parts in per_chunk.values() {
        assert_eq!(parts.len(), 3, "bark and leaves near, a card far");
        assert!(
            parts
                .iter()
                .all(|p| std::sync::Arc::ptr_eq(&p.buffer, &parts[0].buffer))
        );
        let surfaces: Vec<_> = parts.iter().map(|p| p.surface.as_ref().unwrap()).collect();
        assert_eq!(surfaces.iter().filter(|s| s.double_sided).count(), 2);
        assert!(parts.iter().all(|p| (p.mesh_top - 4.5).abs() < 1e-4));
        let near: Vec<_> = parts.iter().filter(|p| p.fade_in.is_none()).collect();
        let far: Vec<_> = parts.iter().filter(|p| p.fade_in.is_some()).collect();
        assert_eq!((near.len(), far.len()), (2, 1));
        assert!(
            near.iter()
                .all(|p| p.fade_out == far[0].fade_in && p.fade_out.is_some())
        );
        assert_eq!(far[0].fade_out, None, "the last level is drawn to the edge");
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_promoted_asset_instance_gets_the_files_collider_or_its_hull() {
    let (mut app, dir) = gltf_app("promoted", &[("oak.glb", &tree().to_bytes())]);
    let server = app.world().resource::<AssetServer>().clone();
    let oak = AssetLook::new(server.load("oak.glb"));
    // The far card alone has no collider node: its hull stands for it.
    let card = oak.clone().with_root(AssetRoot::Node("oak_LOD1".into()));
    let bare = AssetLook {
        collider: false,
        ..oak.clone()
    };
    let density = LayerDensity::Constant(0.05);
    let mut l = layer(density.clone());
    l.classes = [oak, card, bare]
        .map(|look| ScatterClass::asset(density.clone(), look).with_promotion(20.0, |_| {}))
        .into();
    app.world_mut().spawn(l);
    spawn_viewer(&mut app, Vec3::ZERO);
    let promoted = |app: &mut App| {
        let mut q = app
            .world_mut()
            .query_filtered::<(&ScatterEntity, Option<&AssetCollider>, &Children), With<PromotedInstance>>();
        q.iter(app.world())
            .map(|(e, c, children)| (e.class, c.cloned(), children.len()))
            .collect::<Vec<_>>()
    };
    let all = run_until(&mut app, 2_000, |app| {
        let classes: std::collections::HashSet<u16> = app
            .world()
            .iter_entities()
            .filter(|e| e.contains::<PromotedInstance>())
            .filter_map(|e| e.get::<ScatterEntity>().map(|s| s.class))
            .collect();
        classes.len() == 3
    });
    assert!(all, "every class promoted an instance");
    let meshes_of = |app: &App, handles: &[Handle<Mesh>]| -> Vec<f32> {
        let meshes = app.world().resource::<Assets<Mesh>>();
        handles
            .iter()
            .map(|h| meshes.get(h).unwrap().compute_aabb().unwrap().min().y)
            .collect()
    };
    for (class, collider, children) in promoted(&mut app) {
        match (class, collider) {
            (0, Some(AssetCollider::Meshes(hull))) => {
                // The UCX node's hull, lifted 2 m by its node: it stands on the origin.
                let lowest = meshes_of(&app, &hull);
                assert!(lowest.len() == 1 && lowest[0].abs() < 1e-4, "{lowest:?}");
                assert_eq!(children, 3, "a child per primitive of each level");
            }
            (1, Some(AssetCollider::Hull(points))) => {
                // The card: a box of 8 corners 5 m tall, in its own node's frame (the
                // root's transform is the asset's frame), so centred on the origin.
                assert_eq!(points.len(), 8);
                let lowest = points.iter().map(|p| p.y).fold(f32::INFINITY, f32::min);
                assert!((lowest + 2.5).abs() < 1e-4, "{lowest}");
                assert_eq!(children, 1);
            }
            (2, None) => {}
            other => panic!("class {class}: {other:?}"),
        }
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_changed_file_is_drawn_again_as_it_now_is() {
    let (mut app, dir) = gltf_app("reload", &[("oak.glb", &tree().to_bytes())]);
    let server = app.world().resource::<AssetServer>().clone();
    let density = LayerDensity::Constant(0.05);
    let mut l = layer(density.clone());
    l.classes = vec![ScatterClass::asset(
        density,
        AssetLook::new(server.load("oak.glb")),
    )];
    app.world_mut().spawn(l);
    spawn_viewer(&mut app, Vec3::ZERO);
    // Parts per chunk entity's chunk, once every chunk draws `parts`.
    let drawn_with = |parts: usize| {
        move |app: &App| {
            let mut per_chunk: HashMap<_, usize> = HashMap::new();
            for e in app.world().iter_entities() {
                if let Some(c) = e.get::<InstancedChunk>() {
                    *per_chunk.entry(c.chunk).or_default() += 1;
                }
            }
            !per_chunk.is_empty() && per_chunk.values().all(|n| *n == parts)
        }
    };
    assert!(
        run_until(&mut app, 2_000, drawn_with(3)),
        "two levels: 2 + 1 parts"
    );
    // The file becomes a rock of one primitive, read again as the file watcher would.
    let mut rock = Glb::default();
    let grey = rock.add_material(GlbMaterial::colored([0.5, 0.5, 0.5, 1.0]));
    let boulder = GlbPrimitive::from_mesh(&Sphere::new(1.0).mesh().build(), grey).unwrap();
    let mesh = rock.add_mesh(vec![boulder]);
    let node = rock.add_node(GlbNode::named("rock").with_mesh(mesh));
    rock.add_root(node);
    std::fs::write(dir.join("oak.glb"), rock.to_bytes()).unwrap();
    server.reload("oak.glb");
    assert!(
        run_until(&mut app, 2_000, drawn_with(1)),
        "the rock's one part"
    );
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_part_every_level_shares_is_moved_into_the_assets_frame_once() {
    let mut file = Glb::default();
    let grey = file.add_material(GlbMaterial::colored([0.5, 0.5, 0.5, 1.0]));
    let mut mesh =
        |shape: Mesh| file.add_mesh(vec![GlbPrimitive::from_mesh(&shape, grey).unwrap()]);
    let (near, far, base) = (
        mesh(Sphere::new(1.0).mesh().build()),
        mesh(Cuboid::new(1.0, 1.0, 1.0).mesh().build()),
        mesh(Cylinder::new(0.5, 0.2).mesh().build()),
    );
    let lod0 = file.add_node(GlbNode::named("rock_LOD0").with_mesh(near));
    let lod1 = file.add_node(GlbNode::named("rock_LOD1").with_mesh(far));
    let lifted = Transform::from_xyz(0.0, 0.1, 0.0);
    let plinth = file.add_node(
        GlbNode::named("plinth")
            .with_mesh(base)
            .with_transform(lifted),
    );
    let root = file.add_node(GlbNode::named("rock").with_children([lod0, lod1, plinth]));
    file.add_root(root);
    let (mut app, dir) = gltf_app("shared", &[("rock.glb", &file.to_bytes())]);
    let handle: Handle<Gltf> = app.world().resource::<AssetServer>().load("rock.glb");
    let loaded = run_until(&mut app, 2_000, |app| {
        let server = app.world().resource::<AssetServer>();
        server.is_loaded_with_dependencies(&handle)
    });
    assert!(loaded, "rock.glb did not load");
    let world = app.world_mut();
    let before = world.resource::<Assets<Mesh>>().len();
    let resolved = world.resource_scope(|world, mut meshes: Mut<Assets<Mesh>>| {
        let from = GltfAssets {
            nodes: world.resource(),
            meshes: world.resource(),
            materials: world.resource(),
            lods: None,
        };
        let gltf = world.resource::<Assets<Gltf>>().get(&handle).unwrap();
        resolve_asset(gltf, &AssetRoot::File, from, &mut meshes).unwrap()
    });
    let plinths: Vec<_> = resolved
        .levels
        .iter()
        .map(|l| l.last().unwrap().mesh.id())
        .collect();
    assert_eq!(plinths.len(), 2);
    assert_eq!(plinths[0], plinths[1], "one moved plinth for both levels");
    assert_eq!(world.resource::<Assets<Mesh>>().len(), before + 1);
    std::fs::remove_dir_all(&dir).ok();
}

/// A rock whose levels `MSFT_lod` names (node 0 naming nodes 1 and 2, which no scene
/// holds), its screen coverage hinted in its extras.
fn msft_rock() -> Glb {
    let mut file = Glb::default();
    let grey = file.add_material(GlbMaterial::colored([0.5, 0.5, 0.5, 1.0]));
    let mut mesh =
        |shape: Mesh| file.add_mesh(vec![GlbPrimitive::from_mesh(&shape, grey).unwrap()]);
    let (near, mid, far) = (
        mesh(Cuboid::new(2.0, 2.0, 2.0).mesh().build()),
        mesh(Sphere::new(1.0).mesh().ico(1).unwrap()),
        mesh(Cuboid::new(1.6, 1.6, 1.6).mesh().build()),
    );
    let lifted = Transform::from_xyz(0.0, 1.0, 0.0);
    let high = GlbNode::named("rock")
        .with_mesh(near)
        .with_transform(lifted);
    let high = file.add_node(high.with_msft_lod(vec![1, 2], vec![0.5, 0.2, 0.01]));
    for (name, mesh) in [("rock_mid", mid), ("rock_far", far)] {
        file.add_node(GlbNode::named(name).with_mesh(mesh).with_transform(lifted));
    }
    file.add_root(high);
    file
}

#[test]
fn msft_lod_gives_the_levels_and_their_coverage_gives_the_switches() {
    let (mut app, dir) = gltf_app("msft_lod", &[("rock.glb", &msft_rock().to_bytes())]);
    let server = app.world().resource::<AssetServer>().clone();
    let look = AssetLook::new(server.load("rock.glb"));
    let density = LayerDensity::Constant(0.05);
    let mut l = layer(density.clone());
    l.classes = vec![ScatterClass::asset(density, look.clone())];
    app.world_mut().spawn(l);
    spawn_viewer(&mut app, Vec3::ZERO);
    let resolved = |app: &App| {
        let assets = app
            .world()
            .resource::<bevy_rwt::instancing::ResolvedAssets>();
        assets.ready(&look).cloned()
    };
    assert!(run_until(&mut app, 2_000, |app| resolved(app).is_some()));
    let rock = resolved(&app).unwrap();
    // Three levels of one primitive each: the nodes it names are no roots of their own.
    let sizes: Vec<usize> = rock.levels.iter().map(Vec::len).collect();
    assert_eq!(sizes, [1, 1, 1]);
    assert_eq!(rock.coverage, [0.5, 0.2, 0.01]);
    // Each level stands where the node it replaces stands, lifted 1 m: a 2 m box's bottom
    // on the origin, a 1.6 m box's 0.2 m over it.
    let meshes = app.world().resource::<Assets<Mesh>>();
    let low = |level: usize| {
        let mesh = meshes.get(&rock.levels[level][0].mesh).unwrap();
        mesh.compute_aabb().unwrap().min().y
    };
    assert!(
        low(0).abs() < 1e-3 && (low(2) - 0.2).abs() < 1e-3,
        "{} {}",
        low(0),
        low(2)
    );
    // The far level switches where the hint says: the asset covering a fifth of the
    // screen's height, two and a half times as far as half of it.
    let switches = look.lods.switches(3, rock.bounds, &rock.coverage);
    let radius = 0.5 * (rock.bounds.1 - rock.bounds.0).length();
    let at = |cover: f32| radius / (cover * (std::f32::consts::PI / 8.0).tan());
    assert!((switches[0] - at(0.5)).abs() < 1e-3, "{switches:?}");
    assert!((switches[1] - at(0.2)).abs() < 1e-3, "{switches:?}");
    // The loader's handler kept the extension by the file's path.
    let table = app.world().resource::<MsftLodTable>();
    assert_eq!(table.get(&"rock.glb".into()).unwrap().nodes[&0].ids, [1, 2]);
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_layer_file_names_assets_and_describes_them_back() {
    let bytes = tree().to_bytes();
    let layer_file = r#"(format: 2, tile_size: 8.0, chunk_size: 16.0, load_distance: 48.0, unload_distance: 64.0,
        classes: [
            (density: Constant(0.05), asset: (path: "oak.glb#oak", lods: [12.0], collider: false, wind_response: 0.1)),
            (density: Constant(0.05), asset: "broken.glb"),
            (density: Constant(0.05), asset: "garbled.glb#Scene0"),
            (density: Constant(0.05), asset: "missing.glb"),
        ])"#;
    let garbled: Vec<u8> = (0..4096u32)
        .map(|i| (i.wrapping_mul(2654435761) >> 13) as u8)
        .collect();
    let (mut app, dir) = gltf_app(
        "asset_layer_file",
        &[
            ("oak.glb", &bytes),
            ("broken.glb", &bytes[..bytes.len() / 2]),
            ("garbled.glb", &garbled),
            ("forest.layer.ron", layer_file.as_bytes()),
        ],
    );
    let handle: Handle<ScatterLayerAsset> = app
        .world()
        .resource::<AssetServer>()
        .load("forest.layer.ron");
    let entity = app.world_mut().spawn(ScatterLayerSource(handle)).id();
    spawn_viewer(&mut app, Vec3::ZERO);
    let settled = run_until(&mut app, 3_000, |app| {
        let drawn = app
            .world()
            .iter_entities()
            .any(|e| e.contains::<InstancedChunk>());
        let status = app.world().get::<ScatterLayerStatus>(entity).unwrap();
        drawn && status.class_errors.len() == 3 && status.pending_tasks == 0
    });
    let status = app.world().get::<ScatterLayerStatus>(entity).unwrap();
    assert!(settled, "{status:?}");
    // Each bad file is its own class's error; the good one streams.
    let failed: Vec<u16> = status.class_errors.iter().map(|(c, _)| *c).collect();
    assert_eq!(failed, [1, 2, 3]);
    for (class, error) in &status.class_errors {
        let InstancedClassError::Asset(e) = error else {
            panic!("class {class}: {error}");
        };
        assert!(matches!(**e, AssetLookError::Load(_)), "class {class}: {e}");
    }
    let mut chunks = app.world_mut().query::<&InstancedChunk>();
    let near_out: Vec<_> = chunks
        .iter(app.world())
        .inspect(|c| assert_eq!(c.class, 0))
        .filter(|c| c.fade_in.is_none())
        .map(|c| c.fade_out)
        .collect();
    assert!(!near_out.is_empty());
    // The file's switch distance, with its crossfade (a tenth of it) centred on it.
    assert!(
        near_out.iter().all(|b| *b == Some((11.4, 12.6))),
        "{near_out:?}"
    );
    // Back to a file: the same classes, through RON and back.
    let layer = app.world().get::<ScatterLayer>(entity).unwrap();
    let names = NamedAssets::default();
    let described = LayerDescription::describe(layer, &names, |_| None).unwrap();
    let read = LayerDescription::from_ron(layer_file).unwrap();
    assert_eq!(described.classes, read.classes);
    let text = described.to_ron().unwrap();
    assert_eq!(
        LayerDescription::from_ron(&text).unwrap(),
        described,
        "{text}"
    );
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn an_asset_fades_its_last_level_into_an_impostor_of_all_its_parts() {
    let (mut app, dir) = gltf_app("asset_impostor", &[("oak.glb", &tree().to_bytes())]);
    let server = app.world().resource::<AssetServer>().clone();
    let oak = AssetLook::new(server.load("oak.glb"));
    // The near level alone: bark and leaves, both in the impostor.
    let near = oak.clone().with_root(AssetRoot::Node("oak_LOD0".into()));
    let impostor = Impostor {
        texels: 32,
        views: 4,
        rows: 1,
        ..Impostor::at(30.0)
    };
    let density = LayerDensity::Constant(0.02);
    let mut l = layer(density.clone());
    l.streaming.load_distance = 64.0;
    l.streaming.unload_distance = 80.0;
    l.classes = [oak, near]
        .map(|look| ScatterClass::asset(density.clone(), look).with_impostor(impostor))
        .into();
    let layer_entity = app.world_mut().spawn(l).id();
    spawn_viewer(&mut app, Vec3::ZERO);
    let impostors = |app: &App| {
        let mut classes: Vec<u16> = app
            .world()
            .iter_entities()
            .filter_map(|e| e.get::<InstancedChunk>())
            .filter(|c| c.impostor.is_some())
            .map(|c| c.class)
            .collect();
        classes.sort();
        classes.dedup();
        classes
    };
    assert!(
        run_until(&mut app, 4_000, |app| impostors(app) == [0, 1]),
        "no impostors drawn: {:?}",
        impostors(&app)
    );
    // The last level of each class fades out over the band the impostor fades in over.
    let band = Some(impostor.band());
    let mut q = app.world_mut().query::<&InstancedChunk>();
    for c in q.iter(app.world()) {
        let last = c.class == 1 || c.fade_in.is_some();
        match (&c.impostor, last) {
            (Some(draw), _) => assert_eq!(Some(draw.band), band),
            (None, true) => assert_eq!(c.fade_out, band, "class {}", c.class),
            (None, false) => assert_ne!(c.fade_out, band),
        }
    }
    // The near level's atlas shows the bark and the leaves, each in its colour.
    let world = app.world();
    let layer = world.get::<ScatterLayer>(layer_entity).unwrap();
    let ClassLook::Asset(look) = &layer.classes[1].look else {
        unreachable!()
    };
    let resolved = world.resource::<bevy_rwt::instancing::ResolvedAssets>();
    let atlases = world.resource::<bevy_rwt::impostor::ImpostorAtlases>();
    let atlas = atlases
        .of_asset(look, resolved.ready(look).unwrap(), &impostor)
        .unwrap();
    let image = world.resource::<Assets<Image>>().get(&atlas.image).unwrap();
    let data = image.data.as_ref().unwrap();
    let level0 = (atlas.frames.size().x * atlas.frames.size().y * 4) as usize;
    let shows = |linear: [f32; 3]| {
        let srgb = Srgba::from(LinearRgba::rgb(linear[0], linear[1], linear[2])).to_u8_array();
        data[..level0]
            .chunks_exact(4)
            .filter(|t| t[3] == 255 && (0..3).all(|k| t[k].abs_diff(srgb[k]) <= 4))
            .count()
    };
    let (bark, leaves) = (shows([0.3, 0.2, 0.1]), shows([0.2, 0.6, 0.1]));
    assert!(bark > 20 && leaves > 200, "bark {bark}, leaves {leaves}");
    std::fs::remove_dir_all(&dir).ok();
}
