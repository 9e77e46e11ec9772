//! Impostors: a mesh class drawn far as impostors spawns entities only in chunks within
//! reach of its crossfade, and every instance of the class, near or far, is in an impostor
//! chunk's buffer, where the entity path puts it; chopping a far tree takes its impostor
//! away. An instanced class draws its meshes and its impostors from one buffer, the meshes
//! fading out over the band the cards fade in over.

use crate::common::*;
use bevy::prelude::*;
use bevy_rwt::edits::EditInstance;
use bevy_rwt::prelude::*;
use bevy_rwt::rwt_core::query::PointId;
use std::collections::HashMap;

/// The crossfade: impostors from 20 m, over 18 to 22 m.
fn impostor() -> Impostor {
    Impostor {
        crossfade: 4.0,
        texels: 32,
        ..Impostor::at(20.0)
    }
}

/// A headless app whose classes have real meshes and materials to bake, and a forest of
/// boxes (class 0, with impostors) and stumps (class 1).
fn forest() -> (App, Entity) {
    let mut app = create_app_with(|app| {
        app.init_asset::<Mesh>()
            .init_asset::<StandardMaterial>()
            .init_asset::<Image>();
    });
    app.world_mut()
        .resource_mut::<RwtSettings>()
        .keep_instance_ids = true;
    let mesh = app.world_mut().resource_mut::<Assets<Mesh>>().add(
        Cuboid::new(1.0, 4.0, 1.0)
            .mesh()
            .build()
            .translated_by(Vec3::Y * 2.0),
    );
    let material = app
        .world_mut()
        .resource_mut::<Assets<StandardMaterial>>()
        .add(StandardMaterial::default());
    let tree = ScatterClass::new(LayerDensity::Constant(0.05), mesh.clone(), material.clone())
        .with_impostor(impostor());
    let stump = ScatterClass::new(LayerDensity::Constant(0.0), mesh, material);
    let mut l = layer(LayerDensity::Constant(0.0));
    l.classes = vec![tree, stump];
    let layer = app.world_mut().spawn(l).id();
    (app, layer)
}

/// The instances every impostor chunk draws, by identity: where, and which class.
fn impostors(app: &mut App) -> HashMap<PointId, (Vec3, u16)> {
    let mut q = app.world_mut().query::<(&InstancedChunk, &Transform)>();
    let mut out = HashMap::new();
    for (c, t) in q.iter(app.world()) {
        assert!(c.impostor.is_some(), "only impostor chunks here");
        for (id, g) in c.buffer.ids.iter().zip(&c.buffer.instances) {
            let at = t.translation + Vec3::from_array(g.offset);
            assert!(
                out.insert(*id, (at, c.class)).is_none(),
                "{id:?} drawn twice"
            );
        }
    }
    out
}

/// Runs frames until streaming settles and the atlas is baked (impostor chunks exist).
fn settle(app: &mut App) {
    tick_app(app, 4_000);
    assert!(
        run_until(app, 2_000, |app| {
            let mut app_world = app.world().try_query::<&InstancedChunk>().unwrap();
            app_world.iter(app.world()).next().is_some()
        }),
        "no impostor chunk"
    );
    tick_app(app, 4_000);
}

/// The reach within which chunks spawn entities, with its hysteresis and a chunk's
/// diagonal (the chunk is near when any of it is).
const REACH: f32 = 22.0 * 1.1 + 16.0 * std::f32::consts::SQRT_2;

#[test]
fn entities_stay_near_and_impostors_draw_every_tree_where_its_entity_stands() {
    let (mut app, _) = forest();
    let viewer = spawn_viewer(&mut app, Vec3::ZERO);
    settle(&mut app);
    for at in [Vec3::ZERO, Vec3::new(30.0, 0.0, 10.0)] {
        move_viewer(&mut app, viewer, at);
        settle(&mut app);
        let entities = instances(&mut app);
        let cards = impostors(&mut app);
        assert!(entities.len() > 20, "{} entities", entities.len());
        assert!(cards.len() > 2 * entities.len(), "{} cards", cards.len());
        for (id, p) in &entities {
            let ground = (p.xz() - at.xz()).length();
            assert!(ground <= REACH, "an entity {ground} m away");
            let (card, class) = cards.get(id).expect("every tree has an impostor");
            assert_eq!(*class, 0);
            assert!(card.distance(*p) < 1e-3, "{card} vs {p}");
        }
        // Every tree near the viewer is an entity (its chunk is within reach).
        let near = cards
            .iter()
            .filter(|(_, (c, _))| (c.xz() - at.xz()).length() < 22.0);
        for (id, _) in near {
            assert!(entities.contains_key(id), "a near tree without its entity");
        }
    }
}

#[test]
fn a_tree_chopped_far_away_loses_its_impostor() {
    let (mut app, layer) = forest();
    spawn_viewer(&mut app, Vec3::ZERO);
    settle(&mut app);
    let cards = impostors(&mut app);
    let (far, _) = cards
        .iter()
        .find(|(_, (at, _))| at.xz().length() > 35.0)
        .map(|(id, c)| (*id, *c))
        .expect("a far tree");
    assert!(!instances(&mut app).contains_key(&far));
    app.world_mut()
        .write_message(EditInstance::reclass(layer, far, 1));
    settle(&mut app);
    let cards = impostors(&mut app);
    assert!(
        !cards.contains_key(&far),
        "the chopped tree's impostor stays"
    );
    assert!(cards.len() > 10);
}

#[test]
fn an_instanced_class_draws_meshes_and_impostors_from_one_buffer() {
    let mut app = create_app_with(|app| {
        app.init_asset::<Mesh>()
            .init_asset::<StandardMaterial>()
            .init_asset::<Image>();
    });
    let mesh = app.world_mut().resource_mut::<Assets<Mesh>>().add(
        Cuboid::new(1.0, 4.0, 1.0)
            .mesh()
            .build()
            .translated_by(Vec3::Y * 2.0),
    );
    let trees = ScatterClass::instanced(LayerDensity::Constant(0.05), mesh, default())
        .with_impostor(impostor());
    let mut l = layer(LayerDensity::Constant(0.0));
    l.classes = vec![trees];
    app.world_mut().spawn(l);
    spawn_viewer(&mut app, Vec3::ZERO);
    settle(&mut app);
    let mut q = app.world_mut().query::<&InstancedChunk>();
    let chunks: Vec<&InstancedChunk> = q.iter(app.world()).collect();
    let (cards, meshes): (Vec<&InstancedChunk>, Vec<&InstancedChunk>) =
        chunks.into_iter().partition(|c| c.impostor.is_some());
    assert!(
        !meshes.is_empty() && cards.len() == meshes.len(),
        "{} {}",
        meshes.len(),
        cards.len()
    );
    for m in &meshes {
        assert_eq!(m.fade_out, Some(impostor().band()));
        let card = cards
            .iter()
            .find(|c| c.chunk == m.chunk)
            .expect("each chunk has its impostors");
        assert!(std::sync::Arc::ptr_eq(&card.buffer, &m.buffer));
        assert_eq!(card.impostor.unwrap().band, impostor().band());
        assert_eq!(card.fade_out, None);
    }
    assert!(
        instances(&mut app).is_empty(),
        "no entity for an instanced class"
    );
}
