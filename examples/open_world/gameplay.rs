//! Acting on the world: a left click (brush off) chops the tree under the cursor, leaving a
//! stump; H places a cabin (a house) 14 m ahead whose footprint clears trees, rocks, bushes,
//! grass and flowers under it. Both persist (edits, and a footprint on an entity) and the
//! brush's F5 saves the edits with the painted maps.

use bevy::prelude::*;
use bevy_rwt::brush::DensityBrush;
use bevy_rwt::prelude::*;
use rwt_examples::cabin::{CabinPlugin, Cabins, cabin_ahead, cabin_footprint, cabin_transform};
use rwt_examples::forest::{STUMP, TreeUnderCursor};
use rwt_examples::prelude::*;
use rwt_examples::terrain::Terrain;

/// Click to chop, H for a cabin.
pub struct GameplayPlugin;

impl Plugin for GameplayPlugin {
    fn build(&self, app: &mut App) {
        app.add_plugins(CabinPlugin)
            .add_systems(Update, (chop_on_click, place_cabin_on_key));
    }
}

/// Left click with the brush off: the tree under the cursor becomes a stump.
fn chop_on_click(
    buttons: Res<ButtonInput<MouseButton>>,
    brush: Res<DensityBrush>,
    cursor: TreeUnderCursor,
    mut edits: MessageWriter<EditInstance>,
) {
    if brush.enabled || !buttons.just_pressed(MouseButton::Left) {
        return;
    }
    if let Some(hit) = cursor.tree() {
        edits.write(EditInstance::reclass(hit.layer, hit.id, STUMP));
    }
}

/// H: a cabin ahead of the camera, facing it (C is the fly camera's down key).
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
    let (at, facing) = cabin_ahead(eye);
    spawn_cabin(&mut commands, &cabins, &terrain, at, facing);
}

/// A cabin at ground position `at` whose door looks along `facing`, clearing the ground
/// under it and 1.5 m around.
pub fn spawn_cabin(
    commands: &mut Commands,
    cabins: &Cabins,
    terrain: &Terrain,
    at: Vec2,
    facing: Vec2,
) {
    let transform = cabin_transform(terrain, at, facing);
    commands.spawn((cabins.look(), transform, cabin_footprint(), CountedInstance));
}
