//! Layers that keep out of each other: grass never grows within a tree's radius, whatever
//! order chunks finish in, and an edit that removes a tree gives the grass back.

use crate::common::*;
use bevy::prelude::*;
use bevy_rwt::prelude::*;
use bevy_rwt::rwt_core::query::PointId;

const RADIUS: f32 = 1.5;

/// A world of trees (class 0, cleared around) and stumps (class 1, never cleared around)
/// and a grass layer that keeps out of them; `tasks` generation tasks at once per layer.
fn world(seed: u64, tasks: usize) -> (App, Entity, Entity) {
    world_with(seed, tasks, false)
}

/// [`world`], the grass naming the trees by their entity's `Name` when `by_name`.
fn world_with(seed: u64, tasks: usize, by_name: bool) -> (App, Entity, Entity) {
    let mut app = bevy_rwt::testing::headless_app(
        RwtPlugins::default()
            .with_spawn_budget(50_000)
            .with_max_tasks(tasks),
    );
    let tree = ScatterClass::new(
        LayerDensity::Constant(0.06),
        Handle::default(),
        Handle::default(),
    );
    let stump = ScatterClass::new(
        LayerDensity::Constant(0.04),
        Handle::default(),
        Handle::default(),
    );
    let trees = ScatterLayer::new(vec![tree, stump])
        .with_tile_size(32.0)
        .with_seed(seed)
        .with_streaming(StreamingConfig {
            chunk_size: 24.0,
            ..streaming()
        });
    let trees = app.world_mut().spawn((trees, Name::new("trees"))).id();
    let grass = layer(LayerDensity::Constant(1.0)).with_seed(seed + 100);
    let grass = match by_name {
        true => grass.with_keep_out("trees", [RADIUS, 0.0]),
        false => grass.with_keep_out(trees, [RADIUS, 0.0]),
    };
    let grass = app.world_mut().spawn(grass).id();
    spawn_viewer(&mut app, Vec3::ZERO);
    tick_app(&mut app, 10_000);
    (app, trees, grass)
}

/// Live instances of `layer`: identity, class, ground position.
fn of_layer(app: &mut App, layer: Entity) -> Vec<(PointId, u16, Vec2)> {
    let mut q = app.world_mut().query::<(&ScatterEntity, &Transform)>();
    let mut out: Vec<_> = q
        .iter(app.world())
        .filter(|(i, _)| i.layer == layer)
        .map(|(i, t)| (i.id, i.class, t.translation.xz()))
        .collect();
    out.sort_by_key(|(id, ..)| *id);
    out
}

/// Grass instances within the radius of `at`.
fn grass_near(app: &mut App, grass: Entity, at: Vec2) -> usize {
    of_layer(app, grass)
        .iter()
        .filter(|(.., p)| p.distance(at) < RADIUS)
        .count()
}

#[test]
fn no_grass_within_a_trees_radius_in_any_completion_order() {
    for seed in 0..20 {
        let tasks = [1, 3, 8, 64][seed as usize % 4];
        let (mut app, trees, grass) = world(seed, tasks);
        let trees = of_layer(&mut app, trees);
        let grass = of_layer(&mut app, grass);
        assert!(
            trees.len() > 50 && grass.len() > 3_000,
            "{} {}",
            trees.len(),
            grass.len()
        );
        let mut near_stumps = 0;
        for (_, class, t) in &trees {
            let near = grass
                .iter()
                .filter(|(.., g)| g.distance(*t) < RADIUS)
                .count();
            match class {
                0 => assert_eq!(
                    near, 0,
                    "seed {seed}: grass within {RADIUS} of a tree at {t}"
                ),
                _ => near_stumps += near,
            }
        }
        // Stumps clear nothing: grass grows around them as anywhere.
        assert!(near_stumps > 0, "seed {seed}");
    }
}

#[test]
fn the_same_world_whichever_chunk_finishes_first() {
    let (mut a, _, grass_a) = world(7, 1);
    let (mut b, _, grass_b) = world(7, 64);
    assert_eq!(of_layer(&mut a, grass_a), of_layer(&mut b, grass_b));
}

#[test]
fn a_layer_named_keeps_the_same_grass_out() {
    let (mut a, _, grass_a) = world_with(5, 8, false);
    let (mut b, _, grass_b) = world_with(5, 8, true);
    assert_eq!(of_layer(&mut a, grass_a), of_layer(&mut b, grass_b));
}

#[test]
fn removing_a_tree_gives_its_grass_back() {
    let (mut app, trees, grass) = world(3, 8);
    let (id, _, at) = *of_layer(&mut app, trees)
        .iter()
        .find(|(_, class, p)| *class == 0 && p.length() < 20.0)
        .expect("a tree near the viewer");
    assert_eq!(grass_near(&mut app, grass, at), 0);
    app.world_mut()
        .write_message(EditInstance::remove(trees, id));
    tick_app(&mut app, 10_000);
    let back = grass_near(&mut app, grass, at);
    assert!(back > 0, "no grass came back around {at}");
    app.world_mut()
        .write_message(EditInstance::restore(trees, id));
    tick_app(&mut app, 10_000);
    assert_eq!(grass_near(&mut app, grass, at), 0);
}
