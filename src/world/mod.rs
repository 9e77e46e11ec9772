//! The open world that `open_world` and `web` stream: its sky, sun, ground and water
//! ([`WorldScenePlugin`]) and its vegetation ([`layers`]); each example adds its camera.

pub mod layers;

use crate::fly_camera::FlyCamera;
use crate::forest::forest_edge;
use crate::terrain::{GROUND_RECENTRE, Terrain, WATER, ground_centre, ground_mesh};
use bevy::light::{CascadeShadowConfig, CascadeShadowConfigBuilder};
use bevy::pbr::MAX_CASCADES_PER_LIGHT;
use bevy::prelude::*;
use bevy_rwt::prelude::RwtViewer;

/// The terrain's seed.
pub const TERRAIN_SEED: u32 = 2006;

/// The sky at the horizon; the fog fades into it.
pub const SKY: Color = Color::srgb(0.66, 0.77, 0.88);

/// The terrain ([`TERRAIN_SEED`]), the sky, the sun with cascaded shadows, sky light, and the
/// ground and water that follow the [`FlyCamera`].
pub struct WorldScenePlugin;

impl Plugin for WorldScenePlugin {
    fn build(&self, app: &mut App) {
        app.insert_resource(ClearColor(SKY))
            .insert_resource(Terrain::new(TERRAIN_SEED))
            .add_systems(Startup, setup_scene)
            .add_systems(
                Update,
                (stay_above_ground, follow_ground)
                    .chain()
                    .in_set(WorldSystems),
            );
    }
}

/// Where the ground follows the camera: after whatever moves the camera.
#[derive(SystemSet, Debug, Clone, PartialEq, Eq, Hash)]
pub struct WorldSystems;

/// A fly camera in a meadow near `near`, 2 m above the ground, looking over grass and
/// flowers at a forest's edge, streaming around it, with the world's fog.
pub fn forest_edge_camera(terrain: &Terrain, near: Vec2) -> impl Bundle {
    let (at, yaw) = forest_edge(terrain, near);
    let cam = FlyCamera {
        speed: 20.0,
        yaw,
        pitch: -0.06,
        ..default()
    };
    let eye = Vec3::new(at.x, terrain.height(at).max(WATER) + 2.0, at.y);
    (
        Camera3d::default(),
        Projection::Perspective(PerspectiveProjection {
            far: 7000.0,
            ..default()
        }),
        Transform::from_translation(eye).with_rotation(cam.rotation()),
        cam,
        RwtViewer::default(),
        world_fog(),
    )
}

/// The fog of the world's cameras: the far hills fade into the sky.
pub fn world_fog() -> DistanceFog {
    DistanceFog {
        color: SKY,
        directional_light_color: Color::srgba(1.0, 0.93, 0.78, 0.5),
        directional_light_exponent: 24.0,
        falloff: FogFalloff::from_visibility_colors(
            4500.0,
            Color::srgb(0.42, 0.52, 0.64),
            Color::srgb(0.72, 0.8, 0.9),
        ),
    }
}

#[derive(Component)]
struct Ground {
    centre: Vec2,
}

#[derive(Component)]
struct Water;

/// Sun with cascaded shadows (as many cascades as the renderer has, up to three), sky
/// light, ground and water.
fn setup_scene(
    mut commands: Commands,
    mut meshes: ResMut<Assets<Mesh>>,
    mut materials: ResMut<Assets<StandardMaterial>>,
) {
    commands.spawn((
        DirectionalLight {
            illuminance: 11_000.0,
            shadow_maps_enabled: true,
            color: Color::srgb(1.0, 0.96, 0.88),
            ..default()
        },
        Transform::from_xyz(0.55, 0.6, 0.35).looking_at(Vec3::ZERO, Vec3::Y),
        shadow_cascades(MAX_CASCADES_PER_LIGHT.min(3)),
    ));
    commands.insert_resource(GlobalAmbientLight {
        color: Color::srgb(0.75, 0.83, 1.0),
        brightness: 500.0,
        ..default()
    });
    commands.spawn((
        Ground {
            centre: Vec2::splat(f32::MAX),
        },
        Mesh3d(meshes.add(Plane3d::default().mesh().size(1.0, 1.0))),
        MeshMaterial3d(materials.add(StandardMaterial {
            perceptual_roughness: 0.95,
            reflectance: 0.2,
            ..default()
        })),
    ));
    commands.spawn((
        Water,
        Mesh3d(meshes.add(Plane3d::default().mesh().size(14_000.0, 14_000.0))),
        MeshMaterial3d(materials.add(StandardMaterial {
            base_color: Color::srgb(0.1, 0.24, 0.32),
            perceptual_roughness: 0.12,
            reflectance: 0.35,
            ..default()
        })),
        Transform::from_xyz(0.0, WATER, 0.0),
    ));
}

/// Three cascades to 350 m, or one to 120 m where the renderer has one (WebGL2).
fn shadow_cascades(count: usize) -> CascadeShadowConfig {
    CascadeShadowConfigBuilder {
        num_cascades: count,
        first_cascade_far_bound: 30.0,
        maximum_distance: if count > 1 { 350.0 } else { 120.0 },
        ..default()
    }
    .build()
}

/// Keeps the camera above the ground and the water.
fn stay_above_ground(terrain: Res<Terrain>, mut camera: Query<&mut Transform, With<FlyCamera>>) {
    for mut t in &mut camera {
        let ground = terrain.height(t.translation.xz()).max(WATER) + 1.2;
        if t.translation.y < ground {
            t.translation.y = ground;
        }
    }
}

/// Rebuilds the ground mesh (and moves the water) under the camera when it strays from the
/// mesh's centre; the near grid stays on a fixed lattice, so it does not swim.
fn follow_ground(
    terrain: Res<Terrain>,
    camera: Query<&Transform, With<FlyCamera>>,
    mut ground: Query<(&mut Ground, &Mesh3d), Without<Water>>,
    mut water: Query<&mut Transform, (With<Water>, Without<FlyCamera>)>,
    mut meshes: ResMut<Assets<Mesh>>,
) {
    let Ok(eye) = camera.single() else {
        return;
    };
    let here = ground_centre(eye.translation.xz());
    for mut w in &mut water {
        w.translation.x = here.x;
        w.translation.z = here.y;
    }
    for (mut g, mesh) in &mut ground {
        if g.centre.distance(eye.translation.xz()) > GROUND_RECENTRE {
            g.centre = here;
            if let Some(mut m) = meshes.get_mut(&mesh.0) {
                *m = ground_mesh(&terrain, here);
            }
        }
    }
}
