//! The launcher's scripted players: `--script chop` chops the three trees nearest to the
//! camera and asks for a cabin ahead (the same plan as open_world's gameplay) once it has
//! joined and its world has settled; `--script watch` only watches. A scripted player with
//! `RWT_SCREENSHOT`, once joined, looks down at the cabin and holds its screenshot until its
//! world there has settled.

use crate::client::{Player, report_line};
use crate::options::ScriptRole;
use crate::world::CabinRequest;
use bevy::prelude::*;
use bevy_rwt::prelude::*;
use bevy_rwt_net::{NetClientStatus, NetFootprint};
use rwt_examples::cabin::CabinPlan;
use rwt_examples::forest::{STUMP, named_tree_layer};
use rwt_examples::prelude::*;
use rwt_examples::terrain::{Terrain, WATER};

/// Frames a joined, settled player waits before its screenshot (a few frames for the last
/// spawns to be drawn).
const SETTLE_FRAMES: u32 = 10;
/// Where the screenshot looks at the cabin from: metres back and up.
const OVERLOOK: (f32, f32) = (22.0, 10.0);

/// Adds the scripted part `role`.
pub fn plugin(app: &mut App, role: ScriptRole) {
    app.insert_resource(Scripted {
        role,
        acted: false,
        ready_frames: 0,
        overlooks: false,
    })
    .add_systems(Update, (act, (hold_screenshot, overlook_cabin).chain()));
}

#[derive(Resource)]
struct Scripted {
    role: ScriptRole,
    /// Whether the chopper chopped and asked.
    acted: bool,
    /// Frames joined and settled in a row.
    ready_frames: u32,
    /// Whether the camera moved to look at the cabin.
    overlooks: bool,
}

/// What the chopper reads.
#[derive(bevy::ecs::system::SystemParam)]
struct View<'w, 's> {
    camera: Query<'w, 's, &'static Transform, With<FlyCamera>>,
    layers: Query<'w, 's, (Entity, &'static Name), With<ScatterLayer>>,
    picking: ScatterPicking<'w, 's>,
    terrain: Res<'w, Terrain>,
}

/// The chopper, once joined and settled: chops three trees, asks for a cabin.
fn act(
    mut script: ResMut<Scripted>,
    status: Res<NetClientStatus>,
    stats: Res<RwtStats>,
    player: Res<Player>,
    view: View,
    mut edits: MessageWriter<EditInstance>,
    mut cabins: MessageWriter<CabinRequest>,
) {
    let ready = *status == NetClientStatus::Joined && stats.settled();
    if script.role != ScriptRole::Chop || script.acted || !ready {
        return;
    }
    let Ok(eye) = view.camera.single() else {
        return;
    };
    let Some(plan) = CabinPlan::at_eye(eye, &view.layers, &view.picking, &view.terrain) else {
        return;
    };
    for hit in &plan.chops {
        edits.write(EditInstance::reclass(hit.layer, hit.id, STUMP));
    }
    cabins.write(CabinRequest {
        at: plan.at,
        facing: plan.facing,
    });
    script.acted = true;
    report_line(
        &player,
        &format!("asked chops={} cabins=1", plan.chops.len()),
    );
}

/// With a screenshot to take: holds it until the player has joined, looks at the cabin
/// ([`overlook_cabin`]) and its world there has settled for [`SETTLE_FRAMES`] frames.
fn hold_screenshot(
    mut script: ResMut<Scripted>,
    smoke: Res<Smoke>,
    status: Res<NetClientStatus>,
    stats: Res<RwtStats>,
    mut report: ResMut<SmokeReport>,
) {
    if !smoke.active() {
        return;
    }
    let ready = *status == NetClientStatus::Joined && stats.settled();
    script.ready_frames = if ready { script.ready_frames + 1 } else { 0 };
    report.hold = script.ready_frames < SETTLE_FRAMES || !script.overlooks;
}

/// Once joined and settled, with a screenshot to take: looks down at the first cabin and
/// the stumps near it from [`OVERLOOK`] (back towards where the camera was, and up).
fn overlook_cabin(
    mut script: ResMut<Scripted>,
    smoke: Res<Smoke>,
    cabins: Query<&NetFootprint>,
    stumps: Stumps,
    terrain: Res<Terrain>,
    mut camera: Query<(&mut FlyCamera, &mut Transform)>,
) {
    let waiting = !smoke.active() || script.overlooks || script.ready_frames == 0;
    let Some(cabin) = cabins.iter().next().filter(|_| !waiting) else {
        return;
    };
    // The cabin and the stumps near it, in the middle of the view.
    let places: Vec<Vec3> = std::iter::once(cabin.translation)
        .chain(stumps.near(cabin.translation.xz()))
        .collect();
    let middle = places.iter().sum::<Vec3>() / places.len() as f32;
    let spread = places
        .iter()
        .map(|p| p.distance(middle))
        .fold(0.0, f32::max);
    for (mut cam, mut transform) in &mut camera {
        let back = (transform.translation.xz() - middle.xz()).normalize_or(Vec2::Y);
        let at = middle.xz() + back * (OVERLOOK.0 + spread);
        let from = Vec3::new(at.x, terrain.height(at).max(WATER) + OVERLOOK.1, at.y);
        cam.place(&mut transform, from, middle + Vec3::Y * 1.5);
    }
    script.overlooks = true;
    script.ready_frames = 0;
}

/// The stumps a player sees.
#[derive(bevy::ecs::system::SystemParam)]
struct Stumps<'w, 's> {
    layers: Query<'w, 's, (Entity, &'static Name), With<ScatterLayer>>,
    picking: ScatterPicking<'w, 's>,
}

impl Stumps<'_, '_> {
    /// Where the stumps within 60 m of `centre` stand.
    fn near(&self, centre: Vec2) -> Vec<Vec3> {
        let Some(layer) = named_tree_layer(&self.layers) else {
            return Vec::new();
        };
        let stumps = PickFilter::default().layers([layer]).classes([STUMP]);
        let hits = self.picking.near(centre, 60.0, &stumps);
        hits.iter().map(|h| h.transform.translation).collect()
    }
}
