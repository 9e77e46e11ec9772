//! Scatter onto a glTF level: an island with a cliff, a bridge, rocks and a house, loaded
//! from a `.glb` that this example writes itself (`assets/levels/island.glb`). Grass grows
//! on the ground and on the bridge and under it, but never inside the rocks or the house,
//! nor on the cliff; spruces (the asset pack's glTF tree) clear the grass around their
//! trunks; the pack's flowers grow in clumps; moss grows on the rock tops, along their
//! slope.
//!
//! `cargo run --release --example mesh_ground`

mod check;
mod level;

use bevy::prelude::*;
use bevy_rwt::ground::{ScatterSurface, SurfacePolicy};
use bevy_rwt::look::asset::{AssetLook, AssetRoot};
use bevy_rwt::look::blade_mesh;
use bevy_rwt::prelude::*;
use bevy_rwt::rwt_core::clumps::{ClumpKernel, ClumpParams, Clumps};
use bevy_rwt::rwt_core::streaming::StreamingConfig;
use bevy_rwt::{ScatterClass, ScatterLayer};
use check::{Checked, LevelPart};
use rwt_examples::pack::PACK;
use rwt_examples::prelude::*;

fn main() {
    write_level();
    App::new()
        .add_plugins((example_plugins("rwt mesh_ground"), SmokePlugin))
        .add_plugins(RwtPlugins::default())
        .init_resource::<Checked>()
        .add_systems(Startup, setup)
        .add_systems(Update, (mark_parts, check::report))
        .run();
}

/// Writes the level's `.glb` and the asset pack where the asset server reads them (each
/// file only when it changed).
fn write_level() {
    rwt_examples::generated::write_asset("levels/island.glb", &level::glb(&level::parts()));
    rwt_examples::pack::write_pack();
}

/// The moss layer, whose ground the rocks are.
#[derive(Resource)]
struct Moss(Entity);

fn setup(
    mut commands: Commands,
    assets: Res<AssetServer>,
    mut meshes: ResMut<Assets<Mesh>>,
    mut materials: ResMut<Assets<StandardMaterial>>,
) {
    commands.spawn((
        Camera3d::default(),
        RwtViewer::default(),
        Transform::from_xyz(-48.0, 19.0, 34.0).looking_at(Vec3::new(-8.0, 2.0, -2.0), Vec3::Y),
        DistanceFog {
            color: Color::srgb(0.62, 0.72, 0.84),
            falloff: FogFalloff::Linear {
                start: 120.0,
                end: 260.0,
            },
            ..default()
        },
    ));
    commands.insert_resource(ClearColor(Color::srgb(0.62, 0.72, 0.84)));
    commands.spawn((
        DirectionalLight {
            illuminance: 9_000.0,
            shadow_maps_enabled: true,
            ..default()
        },
        Transform::from_xyz(-1.0, 2.0, 1.2).looking_at(Vec3::ZERO, Vec3::Y),
    ));
    commands.insert_resource(GlobalAmbientLight {
        brightness: 400.0,
        ..default()
    });
    // The sea: not ground (no ScatterSurface), so nothing grows on it.
    commands.spawn((
        Mesh3d(meshes.add(Plane3d::default().mesh().size(600.0, 600.0))),
        MeshMaterial3d(materials.add(Color::srgb(0.1, 0.25, 0.35))),
    ));
    let trees = commands.spawn(trees(&assets)).id();
    let grass = commands.spawn(grass(&mut meshes, trees)).id();
    let flowers = commands.spawn(flowers(&assets)).id();
    let moss = commands.spawn(moss(&mut meshes)).id();
    commands.insert_resource(Moss(moss));
    // Every mesh of the level is ground for the trees, grass and flowers, unless a part
    // says otherwise (`mark_parts`).
    commands.spawn((
        WorldAssetRoot(assets.load("levels/island.glb#Scene0")),
        ScatterSurface::for_layers([trees, grass, flowers]),
    ));
}

/// The whole island from the camera: chunks of 16 m to 140 m.
fn streaming() -> StreamingConfig {
    StreamingConfig {
        chunk_size: 16.0,
        load_distance: 140.0,
        unload_distance: 160.0,
        near_distance: 40.0,
    }
}

/// Spruces on gentle ground above the shore, sunk 0.3 m.
fn trees(assets: &AssetServer) -> ScatterLayer {
    let spruce = AssetLook {
        color_variation: 0.1,
        wind_response: 0.03,
        ..AssetLook::new(assets.load(PACK.trees[0]))
    };
    let mut tree = ScatterClass::asset(LayerDensity::Constant(0.004), spruce).with_stance(0.0, 0.3);
    tree.scale_variation = 0.3;
    ScatterLayer::new(vec![tree])
        .with_seed(21)
        .with_tile_size(40.0)
        .with_streaming(streaming())
        .on_surfaces(SurfacePolicy::TopMost)
        .with_height_range(1.0, 30.0)
        .with_max_slope(0.35)
}

/// Grass on every open surface: the ground, the bridge and under it; 1.5 m clear of trees.
fn grass(meshes: &mut Assets<Mesh>, trees: Entity) -> ScatterLayer {
    let blade = ScatterClass::instanced(
        LayerDensity::Constant(9.0),
        meshes.add(blade_mesh(0.07, 0.45, 0.08)),
        InstancedShading {
            base_color: Color::srgb(0.05, 0.14, 0.03),
            tip_color: Color::srgb(0.36, 0.5, 0.14),
            shadows: InstancedShadows::Off,
            ..default()
        },
    );
    ScatterLayer::new(vec![blade])
        .with_seed(22)
        .with_tile_size(4.0)
        .with_streaming(streaming())
        .on_surfaces(SurfacePolicy::Every)
        .with_height_range(0.3, 30.0)
        .with_max_slope(0.7)
        .with_keep_out(trees, [1.5])
}

/// The pack's red and yellow flowers, each in clumps of about 30, 4.4 m across.
fn flowers(assets: &AssetServer) -> ScatterLayer {
    let file = assets.load(PACK.flowers);
    let classes = [(4, "red"), (5, "yellow")].map(|(seed, colour)| {
        let clumps = Clumps::new(ClumpParams {
            seed,
            clumps: 0.004,
            per_clump: 30.0,
            radius: 2.2,
            kernel: ClumpKernel::Thomas,
        })
        .expect("valid clumps");
        let look = AssetLook {
            wind_response: 0.2,
            color_variation: 0.15,
            shadows: InstancedShadows::Off,
            collider: false,
            ..AssetLook::new(file.clone()).with_root(AssetRoot::Node(colour.into()))
        };
        let mut flower = ScatterClass::asset(LayerDensity::Clumps(clumps), look);
        flower.scale = 0.65;
        flower
    });
    ScatterLayer::new(classes.into())
        .with_seed(23)
        .with_tile_size(8.0)
        .with_streaming(streaming())
        .on_surfaces(SurfacePolicy::TopMost)
        .with_height_range(0.3, 30.0)
        .with_max_slope(0.6)
}

/// Moss tufts on the rock tops only, standing along the rock's slope.
fn moss(meshes: &mut Assets<Mesh>) -> ScatterLayer {
    let tuft = ScatterClass::instanced(
        LayerDensity::Constant(14.0),
        meshes.add(Sphere::new(0.12).mesh().ico(1).expect("small ico sphere")),
        InstancedShading {
            base_color: Color::srgb(0.12, 0.3, 0.06),
            tip_color: Color::srgb(0.3, 0.45, 0.1),
            wind_response: 0.0,
            shadows: InstancedShadows::Off,
            ..default()
        },
    )
    .with_stance(1.0, 0.0);
    ScatterLayer::new(vec![tuft])
        .with_seed(24)
        .with_tile_size(2.0)
        .with_streaming(streaming())
        .on_surfaces(SurfacePolicy::TopMost)
        .with_max_slope(0.5)
}

/// Marks the level's parts as they spawn: rocks are ground for the moss only (and cover
/// the ground under them from the other layers), the house is ground for no layer.
fn mark_parts(
    mut commands: Commands,
    moss: Res<Moss>,
    named: Query<(Entity, &Name), Added<Name>>,
    children: Query<&Children>,
    meshes: Query<(), With<Mesh3d>>,
) {
    for (entity, name) in &named {
        let marker = if level::ROCKS.contains(&name.as_str()) {
            Some(ScatterSurface::for_layers([moss.0]))
        } else if name.as_str().starts_with("house") {
            Some(ScatterSurface::for_layers([]))
        } else {
            None
        };
        if let Some(marker) = marker {
            commands.entity(entity).insert(marker);
        }
        for part in std::iter::once(entity).chain(children.iter_descendants(entity)) {
            if meshes.contains(part) {
                commands.entity(part).insert(LevelPart);
            }
        }
    }
}
