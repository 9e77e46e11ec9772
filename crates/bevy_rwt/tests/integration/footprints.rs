//! Footprints clear exactly the instances under them (compared with the same world without
//! them, by a containment test of the test's own), and moving or removing one brings back
//! exactly what it cleared.

use crate::common::forest::*;
use crate::common::*;
use bevy::prelude::*;
use bevy_rwt::prelude::*;
use bevy_rwt::rwt_core::query::PointId;
use std::collections::HashMap;

/// A rectangle of `half` turned by `yaw` about y at `centre`, with `margin`: whether it
/// covers ground point `p` (distance from the box in its own frame).
fn in_box(p: Vec2, centre: Vec2, yaw: f32, half: Vec2, margin: f32) -> bool {
    // The footprint's local x axis lies along the world direction of +x turned by yaw.
    let d = p - centre;
    let (s, c) = yaw.sin_cos();
    // Inverse of a turn by yaw about y: x' = c x - s z, z' = s x + c z.
    let local = Vec2::new(c * d.x - s * d.y, s * d.x + c * d.y);
    let outside = (local.abs() - half).max(Vec2::ZERO);
    outside.length() <= margin
}

/// The world without the points `cleared` says.
fn without(
    world: &HashMap<PointId, Placed>,
    cleared: impl Fn(&Placed) -> bool,
) -> HashMap<PointId, Placed> {
    world
        .iter()
        .filter(|(_, p)| !cleared(p))
        .map(|(id, p)| (*id, *p))
        .collect()
}

fn ground(p: &Placed) -> Vec2 {
    Vec2::new(p.position.x, p.position.z)
}

#[test]
fn footprints_clear_exactly_what_lies_under_them() {
    let mut app = instanced_app();
    let (layer, _) = forest(&mut app);
    spawn_viewer(&mut app, Vec3::ZERO);
    tick_app(&mut app, 4_000);
    let plain = placed(&mut app);

    // A cabin turned 0.6 rad, across a chunk border (chunks are 16 wide), with a margin.
    let (centre, yaw, half, margin) = (Vec2::new(15.0, -6.0), 0.6, Vec2::new(6.0, 3.5), 1.0);
    let cabin = app
        .world_mut()
        .spawn((
            Transform::from_xyz(centre.x, 2.0, centre.y).with_rotation(Quat::from_rotation_y(yaw)),
            Footprint::rectangle(half).with_margin(margin),
        ))
        .id();
    tick_app(&mut app, 4_000);
    let cleared = without(&plain, |p| in_box(ground(p), centre, yaw, half, margin));
    let trees = plain.len() - cleared.len();
    assert!(trees > 20, "the cabin clears {trees}");
    assert_same(&cleared, &placed(&mut app));

    // Moved 30 units: the old ground comes back exactly, the new one clears.
    let moved = centre + Vec2::new(-30.0, 10.0);
    app.world_mut().entity_mut(cabin).insert(
        Transform::from_xyz(moved.x, 0.0, moved.y).with_rotation(Quat::from_rotation_y(yaw)),
    );
    tick_app(&mut app, 4_000);
    let expected = without(&plain, |p| in_box(ground(p), moved, yaw, half, margin));
    assert_same(&expected, &placed(&mut app));

    // A camp fire ring that clears grass only, on this layer only.
    let ring = app
        .world_mut()
        .spawn((
            Transform::from_xyz(-5.0, 0.0, 5.0),
            Footprint::circle(4.0)
                .on_layers([layer])
                .on_classes([GRASS]),
        ))
        .id();
    tick_app(&mut app, 4_000);
    let in_ring = |p: &Placed| ground(p).distance(Vec2::new(-5.0, 5.0)) <= 4.0 && p.class == GRASS;
    let both = without(&plain, |p| {
        in_box(ground(p), moved, yaw, half, margin) || in_ring(p)
    });
    assert!(without(&plain, in_ring).len() < plain.len());
    assert_same(&both, &placed(&mut app));

    // Both gone: the world is whole again.
    app.world_mut().despawn(cabin);
    app.world_mut().entity_mut(ring).remove::<Footprint>();
    tick_app(&mut app, 4_000);
    assert_same(&plain, &placed(&mut app));
}

#[test]
fn a_footprint_on_other_layers_clears_nothing_here() {
    let mut app = instanced_app();
    forest(&mut app);
    spawn_viewer(&mut app, Vec3::ZERO);
    tick_app(&mut app, 4_000);
    let plain = placed(&mut app);
    let elsewhere = app.world_mut().spawn_empty().id();
    app.world_mut().spawn((
        Transform::default(),
        Footprint::circle(30.0).on_layers([elsewhere]),
    ));
    tick_app(&mut app, 4_000);
    assert_same(&plain, &placed(&mut app));
}
