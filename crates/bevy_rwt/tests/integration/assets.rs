//! glTF assets: a file written by `testing::glb`, loaded by Bevy's glTF loader headless,
//! read back as a node tree and split into levels of detail and colliders.

use crate::common::app_reading_with;
use bevy::gltf::{Gltf, GltfMesh, GltfNode, GltfPlugin};
use bevy::prelude::*;
use bevy_rwt::look::asset::{AssetParts, AssetPrimitive, AssetRoot, AssetTreeError, asset_tree};
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
    let lod0 = file.add_node(GlbNode::named("oak_LOD0").with_mesh(near));
    let lod1 = file.add_node(GlbNode::named("oak_LOD1").with_mesh(far));
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
    let dir = std::env::temp_dir().join(format!("bevy_rwt_assets_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("oak.glb"), tree().to_bytes()).unwrap();
    let mut app = app_reading_with(&dir, |app| {
        // The loader also makes the file's scenes: their asset type, without the scene
        // plugins a game has.
        app.add_plugins(GltfPlugin::default())
            .init_asset::<bevy::world_serialization::WorldAsset>();
    });
    let handle: Handle<Gltf> = app.world().resource::<AssetServer>().load("oak.glb");
    let loaded = bevy_rwt::testing::run_until(&mut app, 2_000, |app| {
        app.world()
            .resource::<AssetServer>()
            .is_loaded_with_dependencies(&handle)
    });
    assert!(loaded, "oak.glb did not load");
    let world = app.world();
    let gltf = world.resource::<Assets<Gltf>>().get(&handle).unwrap();
    let (nodes, gltf_meshes) = (
        world.resource::<Assets<GltfNode>>(),
        world.resource::<Assets<GltfMesh>>(),
    );
    let tree = |root: AssetRoot| asset_tree(gltf, &root, nodes, gltf_meshes);
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
