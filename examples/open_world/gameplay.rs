//! Acting on the world: a left click (brush off) chops the tree under the cursor, leaving a
//! stump; H places a cabin (a house) 14 m ahead whose footprint clears trees, rocks, bushes,
//! grass and flowers under it. Both persist (edits, and a footprint on an entity) and the
//! brush's F5 saves the edits with the painted maps.

use bevy::prelude::*;
use bevy_rwt::brush::DensityBrush;
use bevy_rwt::prelude::*;
use rwt_examples::foliage;
use rwt_examples::forest::{STUMP, TREE_SPECIES};
use rwt_examples::prelude::*;
use rwt_examples::terrain::Terrain;

/// Click to chop, H for a cabin.
pub struct GameplayPlugin;

impl Plugin for GameplayPlugin {
    fn build(&self, app: &mut App) {
        app.init_resource::<Cabins>()
            .add_systems(Startup, cabin_assets)
            .add_systems(Update, (chop_on_click, place_cabin_on_key));
    }
}

/// The cabin's mesh and material, made once.
#[derive(Resource, Default)]
pub struct Cabins {
    mesh: Handle<Mesh>,
    material: Handle<StandardMaterial>,
}

fn cabin_assets(
    mut cabins: ResMut<Cabins>,
    mut meshes: ResMut<Assets<Mesh>>,
    mut materials: ResMut<Assets<StandardMaterial>>,
) {
    cabins.mesh = meshes.add(foliage::cabin());
    cabins.material = materials.add(StandardMaterial {
        perceptual_roughness: 0.85,
        ..default()
    });
}

/// The tree layer's entity, by its name.
pub fn tree_layer(layers: &Query<(Entity, &Name), With<ScatterLayer>>) -> Option<Entity> {
    layers
        .iter()
        .find(|(_, n)| n.as_str() == "trees")
        .map(|(e, _)| e)
}

/// The trees (not stumps) a pick considers, up to 300 m away.
pub fn trees_only(layer: Entity) -> PickFilter {
    PickFilter::default()
        .layers([layer])
        .classes(TREE_SPECIES)
        .max_distance(300.0)
}

/// Left click with the brush off: the tree under the cursor becomes a stump.
fn chop_on_click(
    buttons: Res<ButtonInput<MouseButton>>,
    brush: Res<DensityBrush>,
    cameras: Query<(&Camera, &GlobalTransform)>,
    windows: Query<&Window>,
    layers: Query<(Entity, &Name), With<ScatterLayer>>,
    picking: ScatterPicking,
    mut edits: MessageWriter<EditInstance>,
) {
    if brush.enabled || !buttons.just_pressed(MouseButton::Left) {
        return;
    }
    let (Ok((camera, at)), Ok(window), Some(layer)) =
        (cameras.single(), windows.single(), tree_layer(&layers))
    else {
        return;
    };
    let Some(ray) = window
        .cursor_position()
        .and_then(|c| camera.viewport_to_world(at, c).ok())
    else {
        return;
    };
    if let Some(hit) = picking.cast_ray(ray, &trees_only(layer)) {
        edits.write(EditInstance::reclass(hit.layer, hit.id, STUMP));
    }
}

/// H: a cabin 14 m ahead of the camera, facing it (C is the fly camera's down key).
fn place_cabin_on_key(
    keys: Res<ButtonInput<KeyCode>>,
    camera: Query<&Transform, With<FlyCamera>>,
    terrain: Res<Terrain>,
    cabins: Res<Cabins>,
    mut commands: Commands,
) {
    if !keys.just_pressed(KeyCode::KeyH) {
        return;
    }
    let Ok(eye) = camera.single() else { return };
    let ahead = eye.forward().xz().normalize_or(Vec2::Y);
    let at = eye.translation.xz() + ahead * 14.0;
    spawn_cabin(&mut commands, &cabins, &terrain, at, -ahead);
}

/// A cabin at ground position `at` whose door looks along `facing`, clearing the ground
/// under it and 1.5 m around; returns its footprint.
pub fn spawn_cabin(
    commands: &mut Commands,
    cabins: &Cabins,
    terrain: &Terrain,
    at: Vec2,
    facing: Vec2,
) -> (Transform, Footprint) {
    // The door is on the cabin's +x side.
    let yaw = (-facing.y).atan2(-facing.x);
    let transform = Transform::from_xyz(at.x, terrain.height(at) - 0.2, at.y)
        .with_rotation(Quat::from_rotation_y(yaw));
    let footprint = Footprint::rectangle(Vec2::new(3.0, 2.0)).with_margin(1.5);
    commands.spawn((
        Mesh3d(cabins.mesh.clone()),
        MeshMaterial3d(cabins.material.clone()),
        transform,
        footprint.clone(),
        CountedInstance,
    ));
    (transform, footprint)
}
