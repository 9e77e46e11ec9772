//! The smallest complete game with rwt: a camera, a sun, ground, grass drawn instanced and
//! bushes as entities where a painted map says. It uses only `bevy` and `bevy_rwt`: copy it
//! to start your own.
//!
//! `cargo run --release --example quickstart`

use bevy::prelude::*;
use bevy_rwt::look::blade_mesh;
use bevy_rwt::prelude::*;

fn main() {
    App::new()
        .add_plugins((DefaultPlugins, RwtPlugins::default()))
        .add_systems(Startup, setup)
        .add_systems(Update, orbit)
        .run();
}

/// The world: a camera that streams, a sun, ground, grass and bushes.
pub fn setup(
    mut commands: Commands,
    assets: Res<AssetServer>,
    mut meshes: ResMut<Assets<Mesh>>,
    mut materials: ResMut<Assets<StandardMaterial>>,
) {
    commands.insert_resource(ClearColor(Color::srgb(0.55, 0.7, 0.9))); // the sky
    // The camera is the viewer: chunks stream around it.
    commands.spawn((
        Camera3d::default(),
        RwtViewer::default(),
        Transform::default(),
    ));
    commands.spawn((
        DirectionalLight {
            shadow_maps_enabled: true,
            ..default()
        },
        Transform::from_xyz(1.0, 2.0, 0.5).looking_at(Vec3::ZERO, Vec3::Y),
    ));
    commands.spawn((
        Mesh3d(meshes.add(Plane3d::default().mesh().size(2000.0, 2000.0))),
        MeshMaterial3d(materials.add(Color::srgb(0.32, 0.27, 0.18))),
    ));
    // Grass everywhere, drawn instanced (no entity per blade), thinning out from 20 m to
    // none at 60 m from the camera.
    let grass = ScatterClass::instanced(
        LayerDensity::Constant(20.0), // blades per square metre
        meshes.add(blade_mesh(0.06, 0.45, 0.1)),
        InstancedShading::default(),
    );
    commands.spawn(
        ScatterLayer::new(vec![grass])
            .with_tile_size(4.0)
            .with_falloff(20.0, 60.0),
    );
    // Bushes as entities where the map is light: white is half a bush per square metre, over
    // a 100 m square.
    let density = LayerDensity::Image(GroundMap {
        image: assets.load("images/sphere.png"),
        min: Vec2::splat(-50.0),
        size: Vec2::splat(100.0),
        scale: 0.5,
    });
    let bush = ScatterClass::new(
        density,
        meshes.add(Sphere::new(0.35).mesh().ico(1).unwrap()),
        materials.add(Color::srgb(0.18, 0.45, 0.16)),
    );
    commands.spawn(ScatterLayer::new(vec![bush]));
}

/// Circles the camera around the map.
pub fn orbit(time: Res<Time>, mut camera: Query<&mut Transform, With<Camera3d>>) {
    let angle = time.elapsed_secs() * 0.1;
    for mut t in &mut camera {
        *t = Transform::from_xyz(30.0 * angle.cos(), 4.0, 30.0 * angle.sin())
            .looking_at(Vec3::ZERO, Vec3::Y);
    }
}
