//! The scripted session (`RWT_SCREENSHOT`): a 1.5 km flight, then down to the view the
//! screenshot shows (`RWT_VIEW`: `eye` in the grass, the default; `forest` at a forest
//! edge; `aerial` to the horizon; `brush` painting from above), and one brush stroke of red
//! flowers, whose added instances the smoke line reports; in the `eye` view the gameplay of
//! [`crate::play`] (chop, cabin, away and back; `clearing` plays it too, then looks down at
//! the cabin's clearing from above); then the brush saves the painted world (maps, layer
//! files and edits) to `RWT_PAINT_DIR`.

use crate::play::{Play, play};
use bevy::prelude::*;
use bevy_rwt::brush::{BrushCommand, BrushSystems, DensityBrush, PaintDab};
use bevy_rwt::prelude::*;
use rwt_examples::forest::forest_edge;
use rwt_examples::prelude::*;
use rwt_examples::terrain::{Terrain, WATER};

/// Runs the script while a smoke session is active.
pub struct ScriptPlugin;

/// The script's systems (after the brush's, so that it can place the brush).
#[derive(SystemSet, Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct ScriptSystems;

impl Plugin for ScriptPlugin {
    fn build(&self, app: &mut App) {
        let script = Script::from_env();
        let mut gameplay = Play::default();
        if !matches!(script.view, View::Eye | View::Clearing) {
            gameplay.skip();
        }
        app.insert_resource(script)
            .insert_resource(gameplay)
            .configure_sets(Update, ScriptSystems.after(BrushSystems))
            .add_systems(
                Update,
                (fly, stroke, play, save_painting, overlook)
                    .chain()
                    .in_set(ScriptSystems)
                    .run_if(|s: Res<Smoke>| s.active()),
            );
    }
}

/// The view the script ends in.
#[derive(Clone, Copy, Debug, PartialEq)]
enum View {
    Eye,
    /// The eye view's gameplay, then the cabin's clearing from above.
    Clearing,
    Forest,
    Aerial,
    Brush,
}

#[derive(Resource)]
struct Script {
    view: View,
    /// Where the camera ends: position and yaw, pitch.
    end: Option<(Vec3, f32, f32)>,
    stroke: Stroke,
    save: Save,
}

/// Whether the stroke's count may still change (not once the gameplay began: its trip
/// away and the cabin change the flower layer too).
fn counting(gameplay: &Play) -> bool {
    !gameplay.started()
}

/// The save after the stroke.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Save {
    NotYet,
    Asked,
    Reported,
}

/// The scripted stroke: waits for the painted layers to settle, counts their instances,
/// paints, then reports how many instances it added or removed.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Stroke {
    Waiting,
    Painting { baseline: usize, dabs: u32 },
    Done { baseline: usize },
}

impl Script {
    fn from_env() -> Self {
        let view = match std::env::var("RWT_VIEW").as_deref() {
            Ok("forest") => View::Forest,
            Ok("aerial") => View::Aerial,
            Ok("brush") => View::Brush,
            Ok("clearing") => View::Clearing,
            _ => View::Eye,
        };
        Self {
            view,
            end: None,
            stroke: Stroke::Waiting,
            save: Save::NotYet,
        }
    }
}

/// Share of the session spent flying, and landing.
const FLIGHT: f32 = 0.55;
const LANDING: f32 = 0.15;

/// The flight path: 1.5 km along a gentle curve; position (x, z) and yaw at `t` in 0..1.
fn path(t: f32) -> (Vec2, f32) {
    let along = 1500.0 * t;
    let p = Vec2::new(-along * (0.3 * t).sin(), -along * (0.3 * t).cos());
    (p, 0.6 * t)
}

fn fly(
    smoke: Res<Smoke>,
    terrain: Res<Terrain>,
    gameplay: Res<Play>,
    mut script: ResMut<Script>,
    mut camera: Query<(&mut FlyCamera, &mut Transform)>,
) {
    let mut t = (smoke.progress() / FLIGHT).min(1.0);
    let mut landing = ((smoke.progress() - FLIGHT) / LANDING).clamp(0.0, 1.0);
    // Back from the scripted gameplay's trip away: the end of the flight again (its last
    // tenth), then the landing.
    if let Some(back) = gameplay.returning(smoke.frame) {
        t = 0.9 + 0.1 * (back * 2.0).min(1.0);
        landing = (back * 2.0 - 1.0).max(0.0);
    }
    let (p, yaw) = path(t);
    let cruise = Vec3::new(p.x, terrain.height(p).max(WATER) + 22.0, p.y);
    let view = script.view;
    let (end, end_yaw, end_pitch) = *script
        .end
        .get_or_insert_with(|| end_pose(view, &terrain, path(1.0)));
    let s = landing * landing * (3.0 - 2.0 * landing);
    for (mut cam, mut transform) in &mut camera {
        cam.yaw = yaw + (end_yaw - yaw) * s;
        cam.pitch = -0.12 + (end_pitch + 0.12) * s;
        transform.translation = cruise.lerp(end, s);
        if let Some(away) = gameplay.away(end) {
            transform.translation = away;
        }
        transform.rotation = cam.rotation();
    }
}

/// How far back from the cabin, and how high above its ground, the `clearing` view looks.
const OVERLOOK: (f32, f32) = (17.0, 11.0);
/// Frames the `clearing` view holds the screenshot after moving, for streaming to follow.
const OVERLOOK_FRAMES: u32 = 30;

/// The `clearing` view, once the gameplay is over: above and behind where the eye stood,
/// looking down at the cabin, its clearing and the stumps.
fn overlook(
    smoke: Res<Smoke>,
    terrain: Res<Terrain>,
    gameplay: Res<Play>,
    script: Res<Script>,
    mut report: ResMut<SmokeReport>,
    mut camera: Query<(&mut FlyCamera, &mut Transform)>,
) {
    let (View::Clearing, Some(cabin), Some((eye, ..))) =
        (script.view, gameplay.cabin(), script.end)
    else {
        return;
    };
    if !gameplay.done() {
        return;
    }
    let back = (eye.xz() - cabin).normalize_or(Vec2::Y);
    let at = cabin + back * OVERLOOK.0;
    let ground = terrain.height(cabin);
    let from = Vec3::new(at.x, ground.max(WATER) + OVERLOOK.1, at.y);
    let target = Vec3::new(cabin.x, ground + 1.5, cabin.y);
    for (mut cam, mut transform) in &mut camera {
        cam.place(&mut transform, from, target);
    }
    report.hold |= gameplay.frames_done(smoke.frame) < OVERLOOK_FRAMES;
}

/// Where each view ends, from the end of the flight at `(p, yaw)`.
fn end_pose(view: View, terrain: &Terrain, (p, yaw): (Vec2, f32)) -> (Vec3, f32, f32) {
    let ground = |p: Vec2| terrain.height(p).max(WATER);
    match view {
        View::Eye | View::Clearing => (Vec3::new(p.x, ground(p) + 1.5, p.y), yaw, -0.1),
        View::Aerial => (Vec3::new(p.x, ground(p) + 230.0, p.y), yaw, -0.16),
        View::Brush => (Vec3::new(p.x, ground(p) + 16.0, p.y), yaw, -0.62),
        View::Forest => {
            let (at, yaw) = forest_edge(terrain, p);
            (Vec3::new(at.x, ground(at) + 2.0, at.y), yaw, 0.0)
        }
    }
}

/// Live instances of the layer the stroke paints, once it has settled.
fn painted_instances(brush: &DensityBrush, layers: &Query<&ScatterLayerStatus>) -> Option<usize> {
    let s = layers.get(brush.targets.first()?.layer).ok()?;
    (s.pending_tasks == 0 && s.queued_spawns == 0).then_some(s.live_entities + s.live_instanced)
}

/// The scripted stroke, and its count for the smoke line.
#[allow(clippy::too_many_arguments)]
fn stroke(
    smoke: Res<Smoke>,
    mut script: ResMut<Script>,
    mut brush: ResMut<DensityBrush>,
    mut report: ResMut<SmokeReport>,
    mut paint: MessageWriter<PaintDab>,
    layers: Query<&ScatterLayerStatus>,
    camera: Query<&Transform, With<FlyCamera>>,
    terrain: Res<Terrain>,
    stats: Res<RwtStats>,
    gameplay: Res<Play>,
) {
    let Ok(eye) = camera.single() else { return };
    let (ahead, radius, count) = match script.view {
        View::Brush => (26.0, 6.0, 14),
        _ => (9.0, 3.5, 6),
    };
    let forward = eye.forward().xz().normalize_or_zero();
    let centre = eye.translation.xz() + forward * ahead;
    if script.view == View::Brush && smoke.progress() > FLIGHT {
        brush.enabled = true;
        brush.radius = radius;
        let h = terrain.height(centre);
        brush.cursor = Some(Vec3::new(centre.x, h, centre.y));
    }
    let landed = smoke.progress() >= FLIGHT + LANDING;
    let settled = painted_instances(&brush, &layers);
    let before = script.stroke;
    script.stroke = match script.stroke {
        Stroke::Waiting => match settled.filter(|_| landed) {
            Some(baseline) => Stroke::Painting { baseline, dabs: 0 },
            None => Stroke::Waiting,
        },
        Stroke::Painting { baseline, dabs } if dabs < count => {
            let side = eye.right().xz() * radius * (dabs as f32 / count as f32 - 0.5);
            paint.write(PaintDab {
                target: 0,
                centre: centre + side,
                radius,
                amount: 0.5,
            });
            Stroke::Painting {
                baseline,
                dabs: dabs + 1,
            }
        }
        Stroke::Painting { baseline, .. } => Stroke::Done { baseline },
        Stroke::Done { baseline } => {
            if let Some(now) = settled.filter(|_| counting(&gameplay)) {
                report.painted = Some(now.abs_diff(baseline));
            }
            Stroke::Done { baseline }
        }
    };
    if std::mem::discriminant(&before) != std::mem::discriminant(&script.stroke) {
        eprintln!(
            "rwt-smoke: frame {}: stroke {:?}, pending tasks {}",
            smoke.frame, script.stroke, stats.pending_tasks
        );
    }
    // The screenshot waits for the stroke's count and for streaming to settle.
    report.hold = report.painted.is_none() || stats.pending_tasks > 0;
}

/// Saves the painted world once the stroke is counted, and reports how it went.
fn save_painting(
    gameplay: Res<Play>,
    mut script: ResMut<Script>,
    brush: Res<DensityBrush>,
    mut report: ResMut<SmokeReport>,
    mut commands: MessageWriter<BrushCommand>,
    mut saved: MessageReader<WorldSaved>,
) {
    match script.save {
        Save::NotYet if report.painted.is_some() && gameplay.done() => {
            commands.write(BrushCommand::Save(brush.save_dir.clone()));
            script.save = Save::Asked;
        }
        Save::Asked => {
            if let Some(answer) = saved.read().last() {
                let to = answer.dir.display();
                match &answer.result {
                    Ok(done) => eprintln!("rwt-smoke: brush {done} to {to}"),
                    Err(e) => eprintln!("rwt-smoke: brush save failed: {e}"),
                }
                script.save = Save::Reported;
            }
        }
        _ => {}
    }
    report.hold |= script.save != Save::Reported;
}
