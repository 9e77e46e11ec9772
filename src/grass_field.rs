//! The scene the cost benchmarks time (`grass_cost`, `gpu_bench`): a flat field of grass
//! streamed around a camera 2 m above it, under a sun with cascaded shadow maps.

use bevy::prelude::*;
use bevy_rwt::look::{blade_mesh, far_blade_mesh};
use bevy_rwt::prelude::*;

/// Streaming radius of the field, metres.
pub const RADIUS: f64 = 150.0;
/// Chunk side, metres.
pub const CHUNK: f64 = 32.0;

/// Where the camera stands and looks: 2 m above the field, across it.
pub fn camera_transform() -> Transform {
    Transform::from_xyz(0.0, 2.0, 0.0).looking_at(Vec3::new(40.0, 0.0, 30.0), Vec3::Y)
}

/// Spawns the sun (cascaded shadow maps on) and the ground under the field.
pub fn spawn_sun_and_ground(
    commands: &mut Commands,
    meshes: &mut Assets<Mesh>,
    materials: &mut Assets<StandardMaterial>,
) {
    commands.spawn((
        DirectionalLight {
            shadow_maps_enabled: true,
            ..default()
        },
        Transform::from_xyz(1.0, 2.0, 0.5).looking_at(Vec3::ZERO, Vec3::Y),
    ));
    commands.spawn((
        Mesh3d(meshes.add(Plane3d::default().mesh().size(600.0, 600.0))),
        MeshMaterial3d(materials.add(Color::srgb(0.2, 0.3, 0.1))),
    ));
}

/// The field's blade: width at the root, height and forward bend (metres).
const BLADE: (f32, f32, f32) = (0.09, 0.72, 0.12);

/// The grass blade every field draws.
pub fn blade() -> Mesh {
    blade_mesh(BLADE.0, BLADE.1, BLADE.2)
}

/// [`blade`] for far chunks ([`ScatterClass::with_instanced_far`]).
pub fn far_blade() -> Mesh {
    far_blade_mesh(BLADE.0, BLADE.1, BLADE.2)
}

/// About `count` blades a square metre spread over the field's streamed disc (the loaded
/// chunks reach a little past [`RADIUS`]; measure the live count for an exact figure).
pub fn nominal_density(count: f64) -> f64 {
    count / (std::f64::consts::PI * (RADIUS + CHUNK).powi(2))
}

/// The field's layer: `class` streamed in [`CHUNK`]-metre chunks to [`RADIUS`].
pub fn field_layer(class: ScatterClass) -> ScatterLayer {
    ScatterLayer::new(vec![class])
        .with_tile_size(2.0)
        .with_streaming(StreamingConfig {
            chunk_size: CHUNK,
            load_distance: RADIUS,
            unload_distance: RADIUS + 24.0,
            near_distance: 48.0,
        })
}

/// Gives every instanced class of `layer` these shadows.
pub fn set_instanced_shadows(layer: &mut ScatterLayer, shadows: InstancedShadows) {
    for class in &mut layer.classes {
        if let ClassLook::Instanced(look) = &mut class.look {
            look.material.shadows = shadows;
        }
    }
}
