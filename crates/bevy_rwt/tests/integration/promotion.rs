//! Promotion: instanced trees near the viewer become entities with the class's components,
//! exactly where and as the buffer drew them, and go back beyond the distance; chopping a
//! promoted tree removes it at once and for good.

use crate::common::*;
use bevy::prelude::*;
use bevy_rwt::edits::EditInstance;
use bevy_rwt::instancing::PromotedInstance;
use bevy_rwt::prelude::*;
use bevy_rwt::rwt_core::query::PointId;
use std::collections::HashMap;

/// What a promoted tree gets: a collider, in a game.
#[derive(Component)]
struct Trunk;

const DISTANCE: f32 = 10.0;

/// A layer of instanced trees promoted within [`DISTANCE`] of the viewer.
fn orchard(app: &mut App) -> Entity {
    let trees = ScatterClass::instanced(
        LayerDensity::Constant(0.08),
        default(),
        InstancedShading::default(),
    )
    .with_promotion(DISTANCE, |e| {
        e.insert(Trunk);
    });
    let mut l = layer(LayerDensity::Constant(0.0));
    l.classes = vec![trees];
    app.world_mut().spawn(l).id()
}

/// The promoted trees: point, transform, and whether they carry the class's component.
fn promoted(app: &mut App) -> HashMap<PointId, (Transform, bool)> {
    let mut q = app
        .world_mut()
        .query_filtered::<(&ScatterEntity, &Transform, Has<Trunk>), With<PromotedInstance>>();
    q.iter(app.world())
        .map(|(i, t, trunk)| (i.id, (*t, trunk)))
        .collect()
}

#[test]
fn near_trees_become_entities_where_they_were_drawn() {
    let mut app = instanced_app();
    orchard(&mut app);
    let viewer = spawn_viewer(&mut app, Vec3::ZERO);
    tick_app(&mut app, 4_000);
    let mut before = placed(&mut app);
    let mut ever = 0;
    // Walk 60 units, a frame per step, without waiting.
    for step in 1..=120 {
        let at = Vec3::new(step as f32 * 0.5, 0.0, step as f32 * 0.2);
        move_viewer(&mut app, viewer, at);
        app.update();
        let now = placed(&mut app); // panics if a point is live twice
        let near = promoted(&mut app);
        ever += near.len();
        for (id, (t, trunk)) in &near {
            assert!(*trunk, "{id:?} lacks the class's component");
            let ground = Vec2::new(t.translation.x - at.x, t.translation.z - at.z).length();
            assert!(
                ground <= DISTANCE * 1.1 + 1e-3,
                "{id:?} promoted at {ground}"
            );
        }
        for (id, p) in &now {
            // Every instance near the viewer is an entity; none moves or turns when it
            // changes hands.
            let ground = Vec2::new(p.position.x - at.x, p.position.z - at.z).length();
            assert!(
                ground > DISTANCE || near.contains_key(id),
                "{id:?} at {ground}"
            );
            if let Some(was) = before.get(id) {
                assert_eq!(was.position, p.position, "{id:?} moved");
                assert_eq!(was.scale, p.scale, "{id:?} scaled");
                assert!((was.yaw - p.yaw).abs() < 1e-5, "{id:?} turned");
            }
        }
        // Near the viewer nothing goes missing while instances change hands.
        for (id, p) in &before {
            let ground = Vec2::new(p.position.x - at.x, p.position.z - at.z).length();
            if ground < 30.0 {
                assert!(now.contains_key(id), "{id:?} went missing");
            }
        }
        before = now;
    }
    assert!(ever > 50, "{ever} promotions seen");
    // Beyond the distance, every tree is back in a buffer.
    move_viewer(&mut app, viewer, Vec3::new(500.0, 0.0, 0.0));
    tick_app(&mut app, 4_000);
    move_viewer(&mut app, viewer, Vec3::new(0.0, 0.0, 200.0));
    tick_app(&mut app, 4_000);
    let far: Vec<_> = promoted(&mut app)
        .into_values()
        .filter(|(t, _)| t.translation.distance(Vec3::new(0.0, 0.0, 200.0)) > 12.0)
        .collect();
    assert!(far.is_empty(), "{} promoted far away", far.len());
}

#[test]
fn a_chopped_promoted_tree_goes_at_once_and_for_good() {
    let mut app = instanced_app();
    let layer = orchard(&mut app);
    let viewer = spawn_viewer(&mut app, Vec3::ZERO);
    tick_app(&mut app, 4_000);
    let near = promoted(&mut app);
    assert!(near.len() > 3, "{} promoted", near.len());
    let (&id, _) = near.iter().min_by_key(|(id, _)| **id).unwrap();
    app.world_mut()
        .write_message(EditInstance::remove(layer, id));
    app.update();
    assert!(!promoted(&mut app).contains_key(&id));
    assert!(!placed(&mut app).contains_key(&id));
    // Away, and back: still chopped.
    move_viewer(&mut app, viewer, Vec3::new(400.0, 0.0, 0.0));
    tick_app(&mut app, 4_000);
    move_viewer(&mut app, viewer, Vec3::ZERO);
    tick_app(&mut app, 4_000);
    assert!(!placed(&mut app).contains_key(&id));
    assert_eq!(promoted(&mut app).len(), near.len() - 1);
}
