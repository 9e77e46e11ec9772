//! Walking on foot (K toggles): a capsule on the terrain that avian's move-and-slide keeps
//! out of tree trunks, stumps and rocks, and that grass parts around (a `Bender`); the camera rides at eye height and looks with the
//! mouse as the fly camera does. Trees and rocks near a viewer (the camera, the walker) are
//! promoted to entities with their file's `AssetCollider`, which an observer turns into
//! avian's static collider; stumps get theirs by class: the plugin knows nothing of physics.

use avian3d::prelude::*;
use bevy::prelude::*;
use bevy::transform::TransformSystems;
use bevy_rwt::look::asset::AssetCollider;
use bevy_rwt::prelude::*;
use rwt_examples::forest::STUMP;
use rwt_examples::prelude::*;
use rwt_examples::terrain::{Terrain, WATER};

/// Capsule radius and the length of its straight part.
pub const RADIUS: f32 = 0.35;
const LENGTH: f32 = 1.0;
/// Eye height above the ground.
const EYE: f32 = 1.65;

/// Physics, colliders for trunks and rocks, and the walker.
pub struct WalkPlugin;

impl Plugin for WalkPlugin {
    fn build(&self, app: &mut App) {
        app.add_plugins(PhysicsPlugins::default())
            .add_observer(add_colliders)
            .add_observer(add_asset_colliders)
            .add_systems(Update, toggle_walk)
            .add_systems(
                PostUpdate,
                (steer, walk).chain().before(TransformSystems::Propagate),
            );
    }
}

/// The player on foot.
#[derive(Component, Default)]
pub struct Walker {
    /// Where it wants to go, on the ground (x, z), in metres per second.
    pub intent: Vec2,
    /// Whether a script steers it (the keys do otherwise, and the camera rides it).
    pub scripted: bool,
}

/// The collider of a stump at scale 1 (`None` for what one walks through: trees and rocks
/// get theirs from their files, [`add_asset_colliders`]).
fn collider_of(layer: &str, class: u16) -> Option<Collider> {
    (layer == "trees" && class == STUMP).then(|| Collider::cylinder(0.36, 1.4))
}

/// A promoted tree or rock's collider from its file: the convex hull of each `UCX_` mesh
/// (a tree's trunk), or of the asset's vertices (a rock).
fn add_asset_colliders(
    add: On<Add, AssetCollider>,
    shapes: Query<&AssetCollider>,
    meshes: Res<Assets<Mesh>>,
    mut commands: Commands,
) {
    let Ok(shape) = shapes.get(add.entity) else {
        return;
    };
    let points = |mesh: &Handle<Mesh>| {
        let positions = meshes.get(mesh)?.attribute(Mesh::ATTRIBUTE_POSITION)?;
        let positions = positions.as_float3()?;
        Some(
            positions
                .iter()
                .map(|p| Vec3::from_array(*p))
                .collect::<Vec<_>>(),
        )
    };
    let collider = match shape {
        AssetCollider::Hull(points) => Collider::convex_hull(points.clone()),
        AssetCollider::Meshes(pieces) => Some(Collider::compound(
            pieces
                .iter()
                .filter_map(|piece| Collider::convex_hull(points(piece)?))
                .map(|hull| (Vec3::ZERO, Quat::IDENTITY, hull))
                .collect(),
        )),
    };
    if let Some(collider) = collider {
        commands
            .entity(add.entity)
            .insert((RigidBody::Static, collider));
    }
}

fn add_colliders(
    add: On<Add, ScatterEntity>,
    instances: Query<&ScatterEntity>,
    names: Query<&Name>,
    mut commands: Commands,
) {
    let Ok(i) = instances.get(add.entity) else {
        return;
    };
    let Some(collider) = names
        .get(i.layer)
        .ok()
        .and_then(|n| collider_of(n.as_str(), i.class))
    else {
        return;
    };
    commands
        .entity(add.entity)
        .insert((RigidBody::Static, collider));
}

/// K: on foot where the camera is, or back to flying.
fn toggle_walk(
    keys: Res<ButtonInput<KeyCode>>,
    walkers: Query<Entity, With<Walker>>,
    camera: Query<&Transform, With<FlyCamera>>,
    terrain: Res<Terrain>,
    mut commands: Commands,
) {
    if !keys.just_pressed(KeyCode::KeyK) {
        return;
    }
    match walkers.single() {
        Ok(walker) => commands.entity(walker).despawn(),
        Err(_) => {
            if let Ok(eye) = camera.single() {
                spawn_walker(&mut commands, &terrain, eye.translation.xz(), false);
            }
        }
    }
}

/// A walker standing at ground position `at`.
pub fn spawn_walker(
    commands: &mut Commands,
    terrain: &Terrain,
    at: Vec2,
    scripted: bool,
) -> Entity {
    let centre = Vec3::new(at.x, ground(terrain, at) + RADIUS + LENGTH / 2.0, at.y);
    commands
        .spawn((
            Walker {
                intent: Vec2::ZERO,
                scripted,
            },
            Transform::from_translation(centre),
            RigidBody::Kinematic,
            Collider::capsule(RADIUS, LENGTH),
            // Trees and rocks near it are promoted, with their colliders.
            RwtViewer::all_around(),
            // Grass and flowers part around the walker and stand up behind it.
            Bender {
                radius: 0.8,
                strength: 1.0,
            },
        ))
        .id()
}

fn ground(terrain: &Terrain, at: Vec2) -> f32 {
    terrain.height(at).max(WATER)
}

/// WASD in the camera's heading, 4 m/s (Shift 9).
fn steer(
    keys: Res<ButtonInput<KeyCode>>,
    camera: Query<&FlyCamera>,
    mut walkers: Query<&mut Walker>,
) {
    let Ok(cam) = camera.single() else { return };
    for mut walker in walkers.iter_mut().filter(|w| !w.scripted) {
        let key = |k: KeyCode| keys.pressed(k) as i32 as f32;
        let ahead = key(KeyCode::KeyW) - key(KeyCode::KeyS);
        let right = key(KeyCode::KeyD) - key(KeyCode::KeyA);
        let (s, c) = cam.yaw.sin_cos();
        // The fly camera looks along -z turned by its yaw.
        let forward = Vec2::new(-s, -c);
        let side = Vec2::new(c, -s);
        let speed = if keys.pressed(KeyCode::ShiftLeft) {
            9.0
        } else {
            4.0
        };
        walker.intent = (forward * ahead + side * right).normalize_or_zero() * speed;
    }
}

/// Moves the walker by its intent, sliding along what it touches, on the ground; the camera
/// follows a walker the keys steer, at eye height.
fn walk(
    time: Res<Time>,
    terrain: Res<Terrain>,
    move_and_slide: MoveAndSlide,
    mut walkers: Query<(Entity, &mut Transform, &Collider, &Walker)>,
    mut camera: Query<&mut Transform, (With<FlyCamera>, Without<Walker>)>,
) {
    for (entity, mut transform, collider, walker) in &mut walkers {
        let velocity = Vec3::new(walker.intent.x, 0.0, walker.intent.y);
        let moved = move_and_slide.move_and_slide(
            collider,
            transform.translation,
            transform.rotation,
            velocity,
            time.delta(),
            &MoveAndSlideConfig::default(),
            &SpatialQueryFilter::from_excluded_entities([entity]),
            |_| MoveAndSlideHitResponse::Accept,
        );
        let at = moved.position.xz();
        let feet = ground(&terrain, at);
        transform.translation = Vec3::new(at.x, feet + RADIUS + LENGTH / 2.0, at.y);
        if walker.scripted {
            continue;
        }
        for mut eye in &mut camera {
            eye.translation = Vec3::new(at.x, feet + EYE, at.y);
        }
    }
}
