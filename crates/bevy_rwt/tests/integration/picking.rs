//! Picking agrees with a brute-force test of every live instance (entities and instanced
//! buffers) for random rays, and with a brute-force search near ground points.

use crate::common::forest::*;
use crate::common::*;
use bevy::ecs::system::SystemState;
use bevy::prelude::*;
use bevy_rwt::prelude::*;
use bevy_rwt::rwt_core::query::PointId;

/// Pick bounds of every class: trunks and crowns of 3 units, tufts of half a unit.
fn bounds(class: u16) -> (Vec3, Vec3) {
    match class {
        TREE | STUMP => (Vec3::new(-0.6, 0.0, -0.6), Vec3::new(0.6, 3.0, 0.6)),
        _ => (Vec3::new(-0.2, 0.0, -0.2), Vec3::new(0.2, 0.5, 0.2)),
    }
}

/// The forest with pick bounds on every class.
fn pickable_forest(app: &mut App) -> Entity {
    let (layer, _) = forest(app);
    let mut l = app.world().get::<ScatterLayer>(layer).unwrap().clone();
    for (i, class) in l.classes.iter_mut().enumerate() {
        let (lo, hi) = bounds(i as u16);
        *class = class.clone().with_pick_bounds(lo, hi);
    }
    app.world_mut().entity_mut(layer).insert(l);
    layer
}

/// Where `ray` enters the box `lo..hi` placed by `t` (slabs in the box's frame).
fn enter(ray: Ray3d, t: &Transform, (lo, hi): (Vec3, Vec3)) -> Option<f32> {
    let inv = t.to_matrix().inverse();
    let o = inv.transform_point3(ray.origin);
    let d = inv.transform_vector3(*ray.direction);
    let mut range = (0.0f32, 1000.0f32);
    for k in 0..3 {
        if d[k] == 0.0 {
            if o[k] < lo[k] || o[k] > hi[k] {
                return None;
            }
            continue;
        }
        let (a, b) = ((lo[k] - o[k]) / d[k], (hi[k] - o[k]) / d[k]);
        range = (range.0.max(a.min(b)), range.1.min(a.max(b)));
    }
    (range.0 <= range.1).then_some(range.0)
}

/// Every live instance as drawn: (point, class, transform).
fn live(app: &mut App) -> Vec<(PointId, u16, Transform)> {
    let mut out = Vec::new();
    let mut entities = app.world_mut().query::<(&ScatterEntity, &Transform)>();
    out.extend(entities.iter(app.world()).map(|(i, t)| (i.id, i.class, *t)));
    let mut chunks = app
        .world_mut()
        .query::<(&bevy_rwt::instancing::InstancedChunk, &Transform)>();
    for (c, t) in chunks.iter(app.world()) {
        for (id, g) in c.buffer.ids.iter().zip(&c.buffer.instances) {
            let place = Transform::from_translation(t.translation + Vec3::from_array(g.offset))
                .with_rotation(Quat::from_rotation_y(g.yaw_radians()))
                .with_scale(Vec3::splat(g.scale));
            out.push((*id, c.class, place));
        }
    }
    out
}

/// A small random generator (xorshift), for reproducible rays.
struct Rng(u64);

impl Rng {
    fn unit(&mut self) -> f32 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 40) as f32 / (1u64 << 24) as f32
    }
}

#[test]
fn rays_hit_what_a_brute_force_test_finds() {
    let mut app = instanced_app();
    let layer = pickable_forest(&mut app);
    spawn_viewer(&mut app, Vec3::ZERO);
    tick_app(&mut app, 4_000);
    // A few edits and a footprint: picking sees the world as shown.
    let all = live(&mut app);
    let edits = all
        .iter()
        .step_by(9)
        .map(|(id, _, _)| EditInstance::remove(layer, *id));
    app.world_mut()
        .write_message_batch(edits.collect::<Vec<_>>());
    app.world_mut()
        .spawn((Transform::from_xyz(8.0, 0.0, 8.0), Footprint::circle(6.0)));
    tick_app(&mut app, 4_000);
    let all = live(&mut app);
    let mut state = SystemState::<ScatterPicking>::new(app.world_mut());
    let picking = state.get(app.world()).unwrap();
    let mut rng = Rng(0x5eed);
    let (mut hits, mut tried) = (0, 0);
    for filter in [
        PickFilter::default(),
        PickFilter::default().classes([TREE, STUMP]),
    ] {
        for _ in 0..150 {
            let origin = Vec3::new(
                rng.unit() * 80.0 - 40.0,
                0.5 + rng.unit() * 6.0,
                rng.unit() * 80.0 - 40.0,
            );
            let target = Vec3::new(rng.unit() * 80.0 - 40.0, 0.0, rng.unit() * 80.0 - 40.0);
            let ray = Ray3d::new(origin, Dir3::new(target - origin).unwrap());
            let brute = all
                .iter()
                .filter(|(_, class, _)| filter.classes.as_ref().is_none_or(|c| c.contains(class)))
                .filter_map(|(id, class, t)| Some((enter(ray, t, bounds(*class))?, *id)))
                .filter(|(d, _)| *d <= filter.max_distance)
                .min_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
            let picked = picking.cast_ray(ray, &filter);
            tried += 1;
            match (brute, picked) {
                (None, None) => {}
                (Some((d, id)), Some(hit)) => {
                    hits += 1;
                    // The instanced path keeps 16-bit turns: near-ties may swap.
                    assert!(
                        hit.id == id || (hit.distance - d).abs() < 1e-3,
                        "{ray:?}: picked {hit:?}, brute force {id:?} at {d}"
                    );
                    assert!((hit.distance - d).abs() < 1e-3, "{hit:?} vs {d}");
                }
                (b, p) => panic!("{ray:?}: brute force {b:?}, picked {p:?}"),
            }
        }
    }
    assert!(hits > tried / 3, "{hits} of {tried} rays hit");
}

#[test]
fn near_finds_every_point_within_the_radius() {
    let mut app = instanced_app();
    pickable_forest(&mut app);
    spawn_viewer(&mut app, Vec3::ZERO);
    tick_app(&mut app, 4_000);
    let all = live(&mut app);
    let mut state = SystemState::<ScatterPicking>::new(app.world_mut());
    let picking = state.get(app.world()).unwrap();
    for (centre, radius) in [(Vec2::new(3.0, -2.0), 5.0), (Vec2::new(-20.0, 31.0), 9.0)] {
        let mut brute: Vec<PointId> = all
            .iter()
            .filter(|(_, _, t)| {
                Vec2::new(t.translation.x, t.translation.z).distance(centre) <= radius
            })
            .map(|(id, _, _)| *id)
            .collect();
        let mut found: Vec<PointId> = picking
            .near(centre, radius, &PickFilter::default())
            .iter()
            .map(|h| h.id)
            .collect();
        brute.sort();
        found.sort();
        assert!(found.len() > 10, "{}", found.len());
        assert_eq!(found, brute);
    }
}
