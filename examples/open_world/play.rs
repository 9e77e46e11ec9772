//! The scripted gameplay of the smoke session (the `eye` view): after the brush stroke, chop
//! the three nearest trees (stumps stay), place a cabin ahead (on a tree when one stands
//! there) whose footprint clears what grows under it, fly 3 km away (every layer's chunks
//! there unload, the trees' at 2.8 km) and back along the end of the session's flight, then
//! count what is still chopped or cleared:
//! `rwt-smoke: gameplay chopped C cleared K persisted P`. Then a walker on foot
//! ([`crate::walk`]) heads straight for a tree's trunk and must stop at it:
//! `rwt-smoke: walked into a trunk: closest D m from its axis, collision at R m`.

use crate::gameplay::spawn_cabin;
use crate::walk::{RADIUS as WALKER_RADIUS, Walker, spawn_walker};
use bevy::prelude::*;
use bevy_rwt::prelude::*;
use bevy_rwt::rwt_core::query::PointId;
use rwt_examples::cabin::{CabinPlan, Cabins};
use rwt_examples::forest::{STUMP, named_tree_layer, trees_only};
use rwt_examples::prelude::*;
use rwt_examples::terrain::Terrain;
use std::collections::{HashMap, HashSet};

/// How far the script flies away.
const AWAY: f32 = 3_000.0;
/// Frames of the return: the end of the session's flight, then its landing.
const RETURN_FRAMES: u32 = 20;
/// Radius around the cabin that holds everything its footprint can clear.
const CABIN_REACH: f32 = 10.0;

/// Where the scripted gameplay stands.
#[derive(Resource, Default)]
pub struct Play {
    phase: Phase,
    chopped: Vec<PointId>,
    cleared: Vec<(Entity, PointId)>,
    cabin: Vec2,
    /// The frame the phase began.
    since: u32,
    /// The walk into a trunk.
    walk: Option<Walk>,
}

#[derive(Clone, Copy, Debug, Default, PartialEq)]
enum Phase {
    #[default]
    Waiting,
    Away,
    Back,
    /// On foot, walking into a trunk.
    Walking,
    Reported,
    /// Another view: no gameplay.
    Skipped,
}

impl Play {
    /// Whether the gameplay is over (reported or skipped).
    pub fn done(&self) -> bool {
        matches!(self.phase, Phase::Reported | Phase::Skipped)
    }

    /// Where the camera is while away, if it is.
    pub fn away(&self, home: Vec3) -> Option<Vec3> {
        (self.phase == Phase::Away).then(|| home + Vec3::X * AWAY)
    }

    /// While flying back from the trip: how far along the return, 0..1.
    pub fn returning(&self, frame: u32) -> Option<f32> {
        let f = frame.saturating_sub(self.since);
        (self.phase == Phase::Back && f < RETURN_FRAMES).then(|| f as f32 / RETURN_FRAMES as f32)
    }

    /// Whether the gameplay began (never in a view that skips it): what the session counted
    /// before it is final.
    pub fn started(&self) -> bool {
        !matches!(self.phase, Phase::Waiting | Phase::Skipped)
    }

    /// Frames since the gameplay was reported (0 before).
    pub fn frames_done(&self, frame: u32) -> u32 {
        if self.phase == Phase::Reported {
            frame.saturating_sub(self.since)
        } else {
            0
        }
    }

    /// Where the cabin stands, once placed.
    pub fn cabin(&self) -> Option<Vec2> {
        self.started().then_some(self.cabin)
    }

    /// Skips the gameplay (views other than `eye` and `clearing`).
    pub fn skip(&mut self) {
        self.phase = Phase::Skipped;
    }
}

/// What the gameplay reads.
#[derive(bevy::ecs::system::SystemParam)]
pub struct Stage<'w, 's> {
    smoke: Res<'w, Smoke>,
    stats: Res<'w, RwtStats>,
    terrain: Res<'w, Terrain>,
    cabins: Res<'w, Cabins>,
    layers: Query<'w, 's, (Entity, &'static Name), With<ScatterLayer>>,
    instances: Query<'w, 's, &'static ScatterEntity>,
    camera: Query<'w, 's, &'static Transform, With<FlyCamera>>,
    walkers: Query<'w, 's, &'static Transform, (With<Walker>, Without<FlyCamera>)>,
    picking: ScatterPicking<'w, 's>,
}

/// Runs the gameplay once the stroke is counted (`painted`), one phase a frame.
pub fn play(
    mut play: ResMut<Play>,
    mut report: ResMut<SmokeReport>,
    world: Stage,
    mut edits: MessageWriter<EditInstance>,
    mut commands: Commands,
) {
    let settled = world.stats.settled();
    let frame = world.smoke.frame;
    let waited = frame.saturating_sub(play.since);
    let phase = play.phase;
    let next = match phase {
        Phase::Waiting if report.painted.is_some() && settled => {
            start(&mut play, &world, &mut edits, &mut commands);
            Phase::Away
        }
        Phase::Away if waited > 10 && settled => Phase::Back,
        Phase::Back if waited > RETURN_FRAMES + 10 && settled => {
            let persisted = persisted(&play, &world);
            eprintln!(
                "rwt-smoke: gameplay chopped {} cleared {} persisted {persisted}",
                play.chopped.len(),
                play.cleared.len()
            );
            play.walk = start_walk(&world, &mut commands);
            Phase::Walking
        }
        Phase::Walking if follow_walk(&mut play, &world, waited) => {
            finish_walk(&play, &mut commands);
            Phase::Reported
        }
        phase => phase,
    };
    if next != play.phase {
        eprintln!("rwt-smoke: frame {frame}: gameplay {next:?}");
        play.phase = next;
        play.since = frame;
    }
    report.hold |= !play.done();
}

/// Places a cabin ahead (on a tree 12 to 40 m away in view, or 15 m ahead) and chops the
/// three trees nearest to the camera that it does not clear.
fn start(
    play: &mut Play,
    world: &Stage,
    edits: &mut MessageWriter<EditInstance>,
    commands: &mut Commands,
) {
    let Ok(eye) = world.camera.single() else {
        return;
    };
    let Some(plan) = CabinPlan::at_eye(eye, &world.layers, &world.picking, &world.terrain) else {
        return;
    };
    spawn_cabin(
        commands,
        &world.cabins,
        &world.terrain,
        plan.at,
        plan.facing,
    );
    play.cabin = plan.at;
    play.cleared = world
        .picking
        .near(plan.at, CABIN_REACH, &PickFilter::default())
        .iter()
        .filter(|h| plan.clears(h))
        .map(|h| (h.layer, h.id))
        .collect();
    for hit in &plan.chops {
        edits.write(EditInstance::reclass(hit.layer, hit.id, STUMP));
        play.chopped.push(hit.id);
    }
}

/// The chopped trees that are stumps and the cleared instances that are gone, now.
fn persisted(play: &Play, world: &Stage) -> usize {
    let live: HashMap<(Entity, PointId), u16> = world
        .instances
        .iter()
        .map(|i| ((i.layer, i.id), i.class))
        .collect();
    let layer = named_tree_layer(&world.layers);
    let stumps = play
        .chopped
        .iter()
        .filter(|id| layer.and_then(|l| live.get(&(l, **id))) == Some(&STUMP))
        .count();
    let shown: HashSet<(Entity, PointId)> = world
        .picking
        .near(play.cabin, CABIN_REACH, &PickFilter::default())
        .iter()
        .map(|h| (h.layer, h.id))
        .collect();
    let gone = play
        .cleared
        .iter()
        .filter(|key| !live.contains_key(key) && !shown.contains(key))
        .count();
    stumps + gone
}

/// Most frames of the walk into a trunk.
const WALK_FRAMES: u32 = 45;
/// Frames the walker must stand still at the trunk for the walk to end before
/// [`WALK_FRAMES`] (a slow renderer's frames each move it the most that one frame may).
const STILL_FRAMES: u32 = 5;

/// The walk into a trunk: the walker, the trunk's axis, the collision distance, the closest
/// the walker came, and the frames it has stood still since.
struct Walk {
    walker: Entity,
    axis: Vec2,
    contact: f32,
    closest: f32,
    last: Option<Vec2>,
    still: u32,
}

/// A walker 3 m from the nearest tree, heading for its axis.
fn start_walk(world: &Stage, commands: &mut Commands) -> Option<Walk> {
    let eye = world.camera.single().ok()?;
    let layer = named_tree_layer(&world.layers)?;
    let trees = world
        .picking
        .near(eye.translation.xz(), 200.0, &trees_only(layer));
    let tree = trees.first()?;
    let axis = tree.transform.translation.xz();
    let from = axis + Vec2::new(3.0, 0.0);
    let walker = spawn_walker(commands, &world.terrain, from, true);
    commands.entity(walker).insert(Walker {
        intent: (axis - from).normalize() * 4.0,
        scripted: true,
    });
    let hull = rwt_examples::pack::trees::hull_radius(tree.class as usize);
    let contact = hull * tree.transform.scale.x + WALKER_RADIUS;
    Some(Walk {
        walker,
        axis,
        contact,
        closest: f32::INFINITY,
        last: None,
        still: 0,
    })
}

/// Tracks the closest the walker came to the trunk's axis; returns whether the walk is over.
fn follow_walk(play: &mut Play, world: &Stage, waited: u32) -> bool {
    let Some(walk) = play.walk.as_mut() else {
        return true;
    };
    if let Ok(at) = world.walkers.get(walk.walker) {
        let here = at.translation.xz();
        walk.closest = walk.closest.min(here.distance(walk.axis));
        let moved = walk.last.is_none_or(|last| last.distance(here) > 1e-3);
        walk.still = if moved { 0 } else { walk.still + 1 };
        walk.last = Some(here);
    }
    let at_trunk = walk.closest < walk.contact + 0.2 && walk.still >= STILL_FRAMES;
    at_trunk || waited >= WALK_FRAMES
}

/// Reports the walk and goes back to flying.
fn finish_walk(play: &Play, commands: &mut Commands) {
    if let Some(walk) = &play.walk {
        eprintln!(
            "rwt-smoke: walked into a trunk: closest {:.2} m from its axis, collision at {:.2} m",
            walk.closest, walk.contact
        );
        commands.entity(walk.walker).despawn();
    }
}
