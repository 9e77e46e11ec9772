//! The cabin a player places: its look (made once, [`CabinPlugin`]), where it stands on the
//! terrain and the ground it clears. open_world spawns cabins itself; the multiplayer
//! example's server places them for every player.

use crate::foliage;
use crate::forest::{named_tree_layer, trees_only};
use crate::terrain::Terrain;
use bevy::prelude::*;
use bevy_rwt::footprints::{Footprint, GroundFootprint};
use bevy_rwt::prelude::{GroundPlane, ScatterHit, ScatterLayer, ScatterPicking};
use glam::DVec2;

/// Makes the cabin's mesh and material at start-up ([`Cabins`]).
pub struct CabinPlugin;

impl Plugin for CabinPlugin {
    fn build(&self, app: &mut App) {
        app.init_resource::<Cabins>()
            .add_systems(Startup, cabin_assets);
    }
}

/// The cabin's mesh and material.
#[derive(Resource, Default)]
pub struct Cabins {
    mesh: Handle<Mesh>,
    material: Handle<StandardMaterial>,
}

impl Cabins {
    /// What draws a cabin.
    pub fn look(&self) -> (Mesh3d, MeshMaterial3d<StandardMaterial>) {
        (
            Mesh3d(self.mesh.clone()),
            MeshMaterial3d(self.material.clone()),
        )
    }
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

/// A cabin standing at ground position `at` (sunk 0.2 m into the terrain) whose door looks
/// along `facing`.
pub fn cabin_transform(terrain: &Terrain, at: Vec2, facing: Vec2) -> Transform {
    // The door is on the cabin's +x side.
    let yaw = (-facing.y).atan2(-facing.x);
    Transform::from_xyz(at.x, terrain.height(at) - 0.2, at.y)
        .with_rotation(Quat::from_rotation_y(yaw))
}

/// How far ahead of the camera a player's cabin goes (metres).
pub const CABIN_AHEAD: f32 = 14.0;

/// Where a cabin placed from `eye` stands on the ground, [`CABIN_AHEAD`] ahead, and where
/// its door looks: back at the eye.
pub fn cabin_ahead(eye: &Transform) -> (Vec2, Vec2) {
    let ahead = eye.forward().xz().normalize_or(Vec2::Y);
    (eye.translation.xz() + ahead * CABIN_AHEAD, -ahead)
}

/// The ground a cabin clears: under it and 1.5 m around.
pub fn cabin_footprint() -> Footprint {
    Footprint::rectangle(Vec2::new(3.0, 2.0)).with_margin(1.5)
}

/// A scripted player's gameplay at a forest's edge: where a cabin goes and which trees to
/// chop.
pub struct CabinPlan {
    /// The cabin's ground position: on a tree 12 to 40 m away in view, else 15 m ahead.
    pub at: Vec2,
    /// Where its door looks: back at the eye.
    pub facing: Vec2,
    /// The ground it clears.
    pub clearing: GroundFootprint,
    /// The three trees nearest the eye in front of it (then any others) that the cabin
    /// does not clear.
    pub chops: Vec<ScatterHit>,
}

impl CabinPlan {
    /// The plan for `eye` among the trees of the layer named "trees" within 300 m.
    pub fn at_eye(
        eye: &Transform,
        layers: &Query<(Entity, &Name), With<ScatterLayer>>,
        picking: &ScatterPicking,
        terrain: &Terrain,
    ) -> Option<Self> {
        let layer = named_tree_layer(layers)?;
        let trees = picking.near(eye.translation.xz(), 300.0, &trees_only(layer));
        Some(Self::new(eye, &trees, terrain))
    }

    /// The plan for `eye`, among `trees` (nearest first).
    pub fn new(eye: &Transform, trees: &[ScatterHit], terrain: &Terrain) -> Self {
        let forward = eye.forward().xz().normalize_or(Vec2::Y);
        let here = eye.translation.xz();
        let in_view = |h: &&ScatterHit| {
            let d = h.transform.translation.xz() - here;
            (12.0..40.0).contains(&d.length()) && d.normalize_or_zero().dot(forward) > 0.9
        };
        let at = trees
            .iter()
            .find(in_view)
            .map(|h| h.transform.translation.xz())
            .unwrap_or(here + forward * 15.0);
        let transform = GlobalTransform::from(cabin_transform(terrain, at, -forward));
        let mut plan = Self {
            at,
            facing: -forward,
            clearing: cabin_footprint().on_ground(&transform, GroundPlane::Xz),
            chops: Vec::new(),
        };
        let in_front = |h: &&ScatterHit| {
            let d = h.transform.translation.xz() - here;
            d.length() < 60.0 && d.normalize_or_zero().dot(forward) > 0.8
        };
        let (front, others): (Vec<&ScatterHit>, Vec<&ScatterHit>) =
            trees.iter().partition(in_front);
        let standing = front.into_iter().chain(others).filter(|h| !plan.clears(h));
        plan.chops = standing.take(3).cloned().collect();
        plan
    }

    /// Whether the cabin clears `hit`.
    pub fn clears(&self, hit: &ScatterHit) -> bool {
        let p = hit.transform.translation;
        self.clearing
            .clears(DVec2::new(p.x as f64, p.z as f64), hit.class)
    }
}
