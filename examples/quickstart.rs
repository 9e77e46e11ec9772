//! The smallest game with rwt: one layer of bushes from a painted density map.
//!
//! `cargo run --release --example quickstart`

use bevy::prelude::*;
use bevy_rwt::prelude::*;
use rwt_examples::prelude::*;

fn main() {
    App::new()
        .add_plugins((example_plugins("rwt quickstart"), SmokePlugin))
        .add_plugins(RwtPlugins::default())
        .add_systems(Startup, setup)
        .add_systems(Update, orbit)
        .run();
}

fn setup(
    mut commands: Commands,
    assets: Res<AssetServer>,
    mut meshes: ResMut<Assets<Mesh>>,
    mut materials: ResMut<Assets<StandardMaterial>>,
) {
    // The camera is the viewer: chunks stream around it.
    commands.spawn((
        Camera3d::default(),
        RwtViewer::default(),
        Transform::default(),
    ));
    commands.spawn((
        DirectionalLight::default(),
        Transform::from_xyz(1.0, 2.0, 0.5).looking_at(Vec3::ZERO, Vec3::Y),
    ));
    commands.spawn((
        Mesh3d(meshes.add(Plane3d::default().mesh().size(200.0, 200.0))),
        MeshMaterial3d(materials.add(Color::srgb(0.45, 0.38, 0.28))),
    ));
    // White in the map = 3 bushes per square metre, over a 100 m square.
    let density = LayerDensity::Image(GroundMap {
        image: assets.load("images/sphere.png"),
        min: Vec2::splat(-50.0),
        size: Vec2::splat(100.0),
        scale: 3.0,
    });
    let bush = ScatterClass::new(
        density,
        meshes.add(Sphere::new(0.35).mesh().ico(1).unwrap()),
        materials.add(Color::srgb(0.18, 0.45, 0.16)),
    );
    commands.spawn(ScatterLayer::new(vec![bush]));
}

/// Circles the camera around the map.
fn orbit(time: Res<Time>, mut camera: Query<&mut Transform, With<Camera3d>>) {
    let angle = time.elapsed_secs() * 0.1;
    for mut t in &mut camera {
        *t = Transform::from_xyz(70.0 * angle.cos(), 45.0, 70.0 * angle.sin())
            .looking_at(Vec3::ZERO, Vec3::Y);
    }
}
