//! The brush plugin: cursor, input, dabs, strokes and their undo, files, the gizmo circle.

use super::paint::{StrokeRecord, dab, restore, target_map};
use super::{
    BrushCommand, BrushError, BrushOutcome, BrushSystems, DensityBrush, PaintDab, ground_hit,
};
use crate::layers::{HeightFn, ScatterLayer};
use crate::look::GroundPlane;
use crate::save::{LoadWorld, MapProblem, RwtSavePlugin, SaveSystems, SaveWorld, WorldLoaded};
use crate::settings::{RwtSystems, configure_sets, in_schedule};
use crate::streaming::DensityMapPainted;
use crate::streaming::LayerState;
use crate::viewers::RwtViewer;
use bevy::ecs::schedule::InternedScheduleLabel;
use bevy::ecs::system::SystemParam;
use bevy::input::mouse::AccumulatedMouseScroll;
use bevy::prelude::*;
use bevy::window::PrimaryWindow;
use std::collections::VecDeque;
use std::sync::Arc;

/// Paints density maps with the mouse (see [`crate::brush`]). Part of [`crate::RwtPlugins`],
/// disabled there (enable it, or add it alone with the group's schedule); its systems run in
/// [`BrushSystems`], before [`SaveSystems`] and
/// [`RwtSystems::Viewers`](crate::RwtSystems::Viewers) in the same schedule. Saves and loads
/// through [`RwtSavePlugin`] (added with the same schedule if the app has none). Draws its
/// circle when Bevy's gizmos are there, reads the mouse and keyboard when Bevy's input is.
pub struct RwtBrushPlugin {
    schedule: InternedScheduleLabel,
}

in_schedule!(RwtBrushPlugin);

impl Plugin for RwtBrushPlugin {
    fn build(&self, app: &mut App) {
        configure_sets(app, self.schedule);
        if !app.is_plugin_added::<RwtSavePlugin>() {
            app.add_plugins(RwtSavePlugin::new(self.schedule));
        }
        app.register_type::<DensityBrush>()
            .register_type::<PaintDab>()
            .register_type::<BrushCommand>()
            .init_resource::<DensityBrush>()
            .init_resource::<BrushHistory>()
            .add_message::<PaintDab>()
            .add_message::<BrushCommand>()
            .add_message::<BrushOutcome>()
            .add_message::<DensityMapPainted>()
            .configure_sets(
                self.schedule,
                BrushSystems.before(SaveSystems).before(RwtSystems::Viewers),
            )
            .add_systems(
                self.schedule,
                (
                    forget_strokes_on_load,
                    locate_cursor,
                    brush_input,
                    apply_dabs,
                    apply_commands,
                )
                    .chain()
                    .in_set(BrushSystems),
            );
    }

    fn finish(&self, app: &mut App) {
        if app
            .world()
            .contains_resource::<bevy::gizmos::config::GizmoConfigStore>()
        {
            app.add_systems(PostUpdate, draw_circle);
        }
    }
}

/// Strokes: the one being painted and the finished ones that can be undone.
#[derive(Resource, Default)]
struct BrushHistory {
    open: Option<StrokeRecord>,
    done: VecDeque<StrokeRecord>,
}

impl BrushHistory {
    fn close(&mut self, depth: usize) {
        if let Some(stroke) = self.open.take().filter(|s| !s.is_empty()) {
            self.done.push_back(stroke);
            while self.done.len() > depth.max(1) {
                self.done.pop_front();
            }
        }
    }
}

/// The selected target's plane and the height of its ground (its top-most surface; below
/// everything where there is none), as the layer's chunks are generated on.
fn target_ground(
    brush: &DensityBrush,
    layers: &Query<(&ScatterLayer, &LayerState)>,
) -> Option<(GroundPlane, HeightFn)> {
    let target = brush.target()?;
    let (layer, state) = layers.get(target.layer).ok()?;
    let ground = state.ground()?.clone();
    let height = move |p: Vec2| ground.top(p).map_or(f32::NEG_INFINITY, |h| h.height);
    Some((layer.plane, Arc::new(height)))
}

/// The ground point under the cursor, on the selected target's layer: on the ground of a
/// 3-D world or on a 2-D plane, seen by a 3-D or a 2-D camera.
fn locate_cursor(
    mut brush: ResMut<DensityBrush>,
    windows: Query<&Window, With<PrimaryWindow>>,
    cameras: Query<(&Camera, &GlobalTransform, Has<RwtViewer>)>,
    layers: Query<(&ScatterLayer, &LayerState)>,
) {
    if !brush.enabled {
        brush.cursor = None;
        return;
    }
    let cursor = windows.iter().find_map(Window::cursor_position);
    let camera = cameras
        .iter()
        .filter(|(c, ..)| c.is_active)
        .max_by_key(|(.., viewer)| *viewer);
    let hit = match (cursor, camera, target_ground(&brush, &layers)) {
        (Some(cursor), Some((camera, transform, _)), Some((plane, height))) => camera
            .viewport_to_world(transform, cursor)
            .ok()
            .and_then(|ray| plane_hit(plane, ray.origin, *ray.direction, &*height)),
        _ => None,
    };
    if brush.cursor != hit {
        brush.cursor = hit;
    }
}

/// Where a ray meets the ground of `plane` (the height field `height` over it).
fn plane_hit(
    plane: GroundPlane,
    origin: Vec3,
    direction: Vec3,
    height: &dyn Fn(Vec2) -> f32,
) -> Option<Vec3> {
    // In the plane's own frame, x and z lie on the ground and y is the height.
    let up = plane.point_at(Vec2::ZERO, 1.0);
    let local = |p: Vec3| GroundPlane::Xz.point_at(plane.ground_of(p), p.dot(up));
    let hit = ground_hit(local(origin), local(direction), height, 5000.0)?;
    Some(plane.point_at(hit.xz(), hit.y))
}

/// Keys, wheel and buttons to brush settings, [`PaintDab`]s and [`BrushCommand`]s.
#[allow(clippy::too_many_arguments)]
fn brush_input(
    mut brush: ResMut<DensityBrush>,
    keys: Option<Res<ButtonInput<KeyCode>>>,
    buttons: Option<Res<ButtonInput<MouseButton>>>,
    scroll: Option<Res<AccumulatedMouseScroll>>,
    time: Res<Time>,
    layers: Query<&ScatterLayer>,
    mut dabs: MessageWriter<PaintDab>,
    mut commands: MessageWriter<BrushCommand>,
) {
    let Some(keys) = keys else { return };
    let k = brush.keys.clone();
    let pressed = |key: Option<KeyCode>| key.is_some_and(|key| keys.just_pressed(key));
    if pressed(k.toggle) {
        brush.enabled = !brush.enabled;
    }
    if !brush.enabled {
        return;
    }
    if pressed(k.strength) {
        let next = DensityBrush::STRENGTHS
            .iter()
            .position(|s| *s > brush.strength + 1e-6)
            .unwrap_or(0);
        brush.strength = DensityBrush::STRENGTHS[next];
    }
    for (key, command) in [
        (k.undo, BrushCommand::Undo),
        (k.save, BrushCommand::Save(brush.save_dir.clone())),
        (k.load, BrushCommand::Load(brush.save_dir.clone())),
    ] {
        if pressed(key) {
            commands.write(command);
        }
    }
    if k.wheel_and_digits {
        select_and_size(&mut brush, &keys, scroll.as_deref());
    }
    let Some((buttons, cursor)) = buttons.zip(brush.cursor) else {
        return;
    };
    let sign = match (buttons.pressed(k.paint), buttons.pressed(k.erase)) {
        (true, false) => 1.0,
        (false, true) => -1.0,
        _ => return,
    };
    let plane = brush
        .target()
        .and_then(|t| layers.get(t.layer).ok())
        .map_or(GroundPlane::Xz, |l| l.plane);
    dabs.write(PaintDab {
        target: brush.selected,
        centre: plane.ground_of(cursor),
        radius: brush.radius,
        amount: sign * brush.strength * time.delta_secs().min(0.1),
    });
}

/// Digits 1-9 select a target; the wheel scales the radius.
fn select_and_size(
    brush: &mut DensityBrush,
    keys: &ButtonInput<KeyCode>,
    scroll: Option<&AccumulatedMouseScroll>,
) {
    const DIGITS: [KeyCode; 9] = [
        KeyCode::Digit1,
        KeyCode::Digit2,
        KeyCode::Digit3,
        KeyCode::Digit4,
        KeyCode::Digit5,
        KeyCode::Digit6,
        KeyCode::Digit7,
        KeyCode::Digit8,
        KeyCode::Digit9,
    ];
    if let Some(i) = DIGITS.iter().position(|d| keys.just_pressed(*d))
        && i < brush.targets.len()
    {
        brush.selected = i;
    }
    let wheel = scroll.map_or(0.0, |s| s.delta.y);
    if wheel != 0.0 {
        let (lo, hi) = brush.radius_range;
        brush.radius = (brush.radius * 1.15f32.powf(wheel.clamp(-5.0, 5.0))).clamp(lo, hi);
    }
}

/// Paints this frame's dabs into their maps and tells the plugin what changed; dabs in
/// consecutive frames make one stroke.
fn apply_dabs(
    brush: Res<DensityBrush>,
    mut history: ResMut<BrushHistory>,
    mut dabs: MessageReader<PaintDab>,
    mut painted: MessageWriter<DensityMapPainted>,
    mut outcomes: MessageWriter<BrushOutcome>,
    mut images: ResMut<Assets<Image>>,
    layers: Query<&ScatterLayer>,
) {
    let mut any = false;
    for d in dabs.read() {
        any = true;
        let map = match target_map(&brush, d.target, &layers) {
            Ok(map) => map,
            Err(e) => {
                outcomes.write(BrushOutcome::Failed(e));
                continue;
            }
        };
        let record = history.open.get_or_insert_with(StrokeRecord::default);
        // Read first: the map is only modified (and re-read, its chunks re-scattered) when
        // the dab changes a texel.
        let planned = images
            .get(&map.image)
            .ok_or(MapProblem::NotLoaded)
            .and_then(|image| dab(image, &map, d.centre, d.radius, d.amount));
        let written = match planned {
            Ok(planned) if planned.is_empty() => Ok(None),
            Ok(planned) => match images.get_mut(&map.image) {
                Some(mut image) => planned.apply(&mut image, map.image.id(), record),
                None => Err(MapProblem::NotLoaded),
            },
            Err(why) => Err(why),
        };
        match written {
            Ok(Some(region)) => {
                painted.write(DensityMapPainted {
                    image: map.image.id(),
                    region,
                });
            }
            Ok(None) => {}
            Err(why) => {
                let error = why.at(&brush.targets[d.target].name).into();
                outcomes.write(BrushOutcome::Failed(error));
            }
        }
    }
    if !any {
        let depth = brush.undo_depth;
        history.close(depth);
    }
}

/// What the brush asks of [`RwtSavePlugin`].
#[derive(SystemParam)]
struct WorldRequests<'w> {
    saves: MessageWriter<'w, SaveWorld>,
    loads: MessageWriter<'w, LoadWorld>,
}

/// Undoes strokes, and hands saves and loads to [`RwtSavePlugin`] with the brush's
/// targets.
fn apply_commands(
    brush: Res<DensityBrush>,
    mut history: ResMut<BrushHistory>,
    mut received: MessageReader<BrushCommand>,
    mut painted: MessageWriter<DensityMapPainted>,
    mut outcomes: MessageWriter<BrushOutcome>,
    mut requests: WorldRequests,
    mut images: ResMut<Assets<Image>>,
) {
    for command in received.read() {
        history.close(brush.undo_depth);
        match command {
            BrushCommand::Undo => {
                let outcome = match undo(&mut history, &mut images, &mut painted) {
                    Ok(strokes_left) => BrushOutcome::Undone { strokes_left },
                    Err(e) => BrushOutcome::Failed(e),
                };
                outcomes.write(outcome);
            }
            BrushCommand::Save(dir) => {
                requests.saves.write(SaveWorld {
                    dir: dir.clone(),
                    maps: brush.targets.clone(),
                    layer_files: brush.layer_files,
                });
            }
            BrushCommand::Load(dir) => {
                let maps = brush.targets.iter().cloned();
                requests.loads.write(LoadWorld::from(dir).with_maps(maps));
            }
        }
    }
}

/// Strokes before a load cannot be undone over it (a failed load changed nothing: they
/// still can).
fn forget_strokes_on_load(
    mut history: ResMut<BrushHistory>,
    mut loads: MessageReader<WorldLoaded>,
) {
    if loads.read().any(|l| l.result.is_ok()) {
        history.open = None;
        history.done.clear();
    }
}

/// Undoes the last stroke; returns how many can still be undone.
fn undo(
    history: &mut BrushHistory,
    images: &mut Assets<Image>,
    painted: &mut MessageWriter<DensityMapPainted>,
) -> Result<usize, BrushError> {
    let stroke = history.done.pop_back().ok_or(BrushError::NothingToUndo)?;
    for (id, before) in &stroke.before {
        if let Some(mut image) = images.get_mut(*id) {
            restore(&mut image, before);
            if let Some(region) = stroke.regions.get(id) {
                painted.write(DensityMapPainted {
                    image: *id,
                    region: *region,
                });
            }
        }
    }
    Ok(history.done.len())
}

/// The brush circle, following the ground.
fn draw_circle(
    brush: Res<DensityBrush>,
    layers: Query<(&ScatterLayer, &LayerState)>,
    mut gizmos: Gizmos,
) {
    let Some(centre) = brush.cursor.filter(|_| brush.enabled) else {
        return;
    };
    let Some((plane, height)) = target_ground(&brush, &layers) else {
        return;
    };
    let (centre, lift) = (plane.ground_of(centre), brush.circle_lift);
    let ring = |r: f32| {
        (0..=48).map(move |i| {
            let a = i as f32 / 48.0 * std::f32::consts::TAU;
            centre + Vec2::new(a.cos(), a.sin()) * r
        })
    };
    let color = Color::srgb(1.0, 0.85, 0.2);
    for (r, alpha) in [(brush.radius, 1.0), (brush.radius * 0.5, 0.5)] {
        gizmos.linestrip(
            ring(r).map(|p| plane.point_at(p, height(p) + lift)),
            color.with_alpha(alpha),
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_cursor_ray_meets_either_plane() {
        let hills = |p: Vec2| 0.5 * (p.x * 0.3).sin();
        // A 2-D camera looks down -z onto the x-y plane, whose heights point at it.
        let down = plane_hit(
            GroundPlane::Xy,
            Vec3::new(3.0, 4.0, 1000.0),
            -Vec3::Z,
            &hills,
        )
        .unwrap();
        assert!((down - Vec3::new(3.0, 4.0, hills(Vec2::new(3.0, 4.0)))).length() < 1e-2);
        // On the ground of a 3-D world the ray meets y = height(x, z).
        let origin = Vec3::new(-5.0, 10.0, 2.0);
        let direction = Vec3::new(1.0, -1.0, 0.5);
        let hit = plane_hit(GroundPlane::Xz, origin, direction, &hills).unwrap();
        assert_eq!(Some(hit), ground_hit(origin, direction, &hills, 5000.0));
        assert!((hit.y - hills(hit.xz())).abs() < 1e-2);
        // Looking away from the plane finds nothing.
        assert_eq!(plane_hit(GroundPlane::Xy, Vec3::Z, Vec3::Z, &hills), None);
    }
}
