//! Per-instance edits: an edited instance (entity or instanced) stays edited through
//! unloading, level-of-detail changes, repainting and a reloaded layer, and exactly the
//! edited points differ from the same world without edits.

use crate::common::forest::*;
use crate::common::*;
use bevy::prelude::*;
use bevy_rwt::edits::{
    ConfirmedEdit, Edit, EditAuthority, EditError, EditInstance, EditOutcome, ScatterEdits,
};
use bevy_rwt::prelude::*;
use bevy_rwt::rwt_core::query::PointId;
use std::collections::HashMap;

/// The unedited world with `edits` applied.
fn edited(world: &HashMap<PointId, Placed>, edits: &ScatterEdits) -> HashMap<PointId, Placed> {
    let mut out = HashMap::new();
    for (id, p) in world {
        match edits.get(id) {
            None => {
                out.insert(*id, *p);
            }
            Some(Edit::Remove) => {}
            Some(Edit::Reclass(class)) => {
                out.insert(*id, Placed { class, ..*p });
            }
        }
    }
    out
}

/// Identities of the first `n` instances of `class` nearest to the origin.
fn nearest(world: &HashMap<PointId, Placed>, class: u16, n: usize) -> Vec<PointId> {
    let mut of_class: Vec<_> = world.iter().filter(|(_, p)| p.class == class).collect();
    of_class.sort_by(|a, b| {
        let key = |p: &Placed| (p.position.length(), p.position.x);
        key(a.1).partial_cmp(&key(b.1)).unwrap()
    });
    of_class.into_iter().take(n).map(|(id, _)| *id).collect()
}

fn layer_edits(app: &App, layer: Entity) -> ScatterEdits {
    app.world().get::<ScatterEdits>(layer).unwrap().clone()
}

#[test]
fn edited_instances_stay_edited_and_nothing_else_changes() {
    let mut plain = instanced_app();
    let mut app = instanced_app();
    let (_, plain_map) = forest(&mut plain);
    let (layer, map) = forest(&mut app);
    let viewers = [
        spawn_viewer(&mut plain, Vec3::ZERO),
        spawn_viewer(&mut app, Vec3::ZERO),
    ];
    tick_app(&mut plain, 4_000);
    tick_app(&mut app, 4_000);
    let start = placed(&mut app);
    assert_eq!(start, placed(&mut plain));

    // Chop trees (entities), turn one into a stump, pull grass (instanced), turn grass
    // into clover (instanced to instanced) and one blade into a stump (instanced to entity).
    let trees = nearest(&start, TREE, 4);
    let grass = nearest(&start, GRASS, 40);
    let mut messages = vec![EditInstance::reclass(layer, trees[0], STUMP)];
    messages.extend(trees[1..].iter().map(|id| EditInstance::remove(layer, *id)));
    messages.extend(
        grass[..30]
            .iter()
            .map(|id| EditInstance::remove(layer, *id)),
    );
    messages.extend(
        grass[30..39]
            .iter()
            .map(|id| EditInstance::reclass(layer, *id, CLOVER)),
    );
    messages.push(EditInstance::reclass(layer, grass[39], STUMP));
    app.world_mut().write_message_batch(messages);
    app.update();
    // Entity instances change at once: the chopped trees are gone, the stump stands.
    let now = placed(&mut app);
    for id in &trees[1..] {
        assert!(!now.contains_key(id), "{id:?} still stands");
    }
    assert_eq!(now[&trees[0]].class, STUMP);

    let edits = layer_edits(&app, layer);
    assert_eq!(edits.len(), 44);
    let check = |plain: &mut App, app: &mut App| {
        tick_app(plain, 4_000);
        tick_app(app, 4_000);
        let expected = edited(&placed(plain), &edits);
        let found = placed(app);
        assert_same(&expected, &found);
    };
    check(&mut plain, &mut app);

    // Far away (every edited chunk unloads), halfway back (other levels of detail), home.
    for at in [
        Vec3::new(400.0, 0.0, 0.0),
        Vec3::new(45.0, 0.0, 30.0),
        Vec3::ZERO,
    ] {
        move_viewer(&mut plain, viewers[0], at);
        move_viewer(&mut app, viewers[1], at);
        check(&mut plain, &mut app);
    }
    // A repaint of the grass map over the edits.
    paint_square(&mut plain, &plain_map, 28, 28, Color::WHITE);
    paint_square(&mut app, &map, 28, 28, Color::WHITE);
    check(&mut plain, &mut app);
    // The layer replaced (as a reloaded layer file replaces it): the edits stay.
    for app in [&mut plain, &mut app] {
        let l = app
            .world_mut()
            .query::<(Entity, &ScatterLayer)>()
            .single(app.world())
            .map(|(e, l)| (e, l.clone()))
            .unwrap();
        app.world_mut().entity_mut(l.0).insert(l.1);
    }
    check(&mut plain, &mut app);
    assert_eq!(layer_edits(&app, layer), edits);

    // Restored, every point is back as it was.
    let all: Vec<PointId> = edits.edits().iter().map(|(id, _)| *id).collect();
    let restore = all.iter().map(|id| EditInstance::restore(layer, *id));
    app.world_mut().write_message_batch(restore);
    tick_app(&mut app, 4_000);
    assert!(layer_edits(&app, layer).is_empty());
    assert!(
        placed(&mut app) == placed(&mut plain),
        "restored world differs"
    );
}

#[test]
fn refused_edits_change_nothing() {
    let mut app = instanced_app();
    let (layer, _) = forest(&mut app);
    spawn_viewer(&mut app, Vec3::ZERO);
    tick_app(&mut app, 4_000);
    let before = placed(&mut app);
    let tree = nearest(&before, TREE, 1)[0];
    let nowhere = PointId {
        index: u16::MAX,
        ..tree
    };
    let not_a_layer = app.world_mut().spawn_empty().id();
    app.world_mut().write_message_batch([
        EditInstance::reclass(layer, tree, 9),
        EditInstance::remove(layer, nowhere),
        EditInstance::remove(not_a_layer, tree),
    ]);
    app.update();
    // Each is answered, in order, with why.
    let outcomes: Vec<_> = app
        .world_mut()
        .resource_mut::<Messages<EditOutcome>>()
        .drain()
        .map(|o| o.result)
        .collect();
    assert_eq!(
        outcomes,
        [
            Err(EditError::NoSuchClass {
                class: 9,
                classes: 4
            }),
            Err(EditError::NoSuchPoint(nowhere)),
            Err(EditError::NoLayer(not_a_layer)),
        ]
    );
    tick_app(&mut app, 4_000);
    assert!(layer_edits(&app, layer).is_empty());
    assert!(placed(&mut app) == before);
}

#[test]
fn under_a_remote_authority_only_confirmed_edits_apply() {
    let mut app = instanced_app();
    let (layer, _) = forest(&mut app);
    spawn_viewer(&mut app, Vec3::ZERO);
    tick_app(&mut app, 4_000);
    let before = placed(&mut app);
    let trees = nearest(&before, TREE, 2);
    *app.world_mut().resource_mut::<EditAuthority>() = EditAuthority::Remote;
    // The game's edit is a request for someone else: nothing changes here.
    app.world_mut()
        .write_message(EditInstance::remove(layer, trees[0]));
    tick_app(&mut app, 4_000);
    assert!(layer_edits(&app, layer).is_empty());
    assert!(placed(&mut app) == before);
    // The authority's confirmation applies, and is answered.
    let chop = EditInstance::remove(layer, trees[1]);
    app.world_mut().write_message(ConfirmedEdit(chop));
    app.update();
    let outcomes: Vec<_> = app
        .world_mut()
        .resource_mut::<Messages<EditOutcome>>()
        .drain()
        .collect();
    assert_eq!(
        outcomes,
        [EditOutcome {
            edit: chop,
            result: Ok(())
        }]
    );
    tick_app(&mut app, 4_000);
    assert_eq!(layer_edits(&app, layer).len(), 1);
    assert!(!placed(&mut app).contains_key(&trees[1]));
    assert!(placed(&mut app).contains_key(&trees[0]));
}

#[test]
fn replacing_the_edit_set_regenerates_what_it_touches() {
    let mut app = instanced_app();
    let (layer, _) = forest(&mut app);
    spawn_viewer(&mut app, Vec3::ZERO);
    tick_app(&mut app, 4_000);
    let before = placed(&mut app);
    let mut set = bevy_rwt::edits::EditSet::default();
    for id in nearest(&before, GRASS, 25)
        .into_iter()
        .chain(nearest(&before, TREE, 3))
    {
        set.set(id, Edit::Remove).unwrap();
    }
    let edits = ScatterEdits::new(set);
    app.world_mut().entity_mut(layer).insert(edits.clone());
    tick_app(&mut app, 4_000);
    assert_same(&edited(&before, &edits), &placed(&mut app));
    // An empty set brings everything back.
    app.world_mut()
        .entity_mut(layer)
        .insert(ScatterEdits::default());
    tick_app(&mut app, 4_000);
    assert!(placed(&mut app) == before);
}
