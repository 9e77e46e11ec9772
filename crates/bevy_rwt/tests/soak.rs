//! The streaming soak test: a long random walk with painting and layer changes, checked
//! every frame for duplicate identities, instances that move (none may: promotion to
//! entities near the viewer and back included) and every few hundred frames for bounded
//! entity, task and memory counts; back at the start, the world is as it was.

#[path = "integration/common/mod.rs"]
mod common;

use bevy::asset::AssetPlugin;
use bevy::prelude::*;
use bevy_rwt::instancing::{GpuInstance, InstancedChunk};
use bevy_rwt::prelude::*;
use bevy_rwt::rwt_core::query::PointId;
use bevy_rwt::rwt_core::rng::Rng;
use common::{layer, move_viewer, paint_square, solid_image, spawn_viewer, tick_app};
use std::collections::HashMap;

/// Frames of the walk (each one `app.update()`, without waiting for streaming to settle).
const FRAMES: usize = 10_000;

/// Live instances, entity or instanced, by (layer seed, identity); panics when one layer
/// has two instances with the same identity.
fn instances(app: &mut App) -> HashMap<(u64, PointId), Vec3> {
    let mut layers = app.world_mut().query::<(Entity, &ScatterLayer)>();
    let seeds: HashMap<Entity, u64> = layers.iter(app.world()).map(|(e, l)| (e, l.seed)).collect();
    let mut out = HashMap::new();
    let mut insert = |seed: u64, id: PointId, at: Vec3| {
        assert!(
            out.insert((seed, id), at).is_none(),
            "two live instances of layer {seed} share {id:?}"
        );
    };
    let mut q = app.world_mut().query::<(&ScatterEntity, &Transform)>();
    for (i, t) in q.iter(app.world()) {
        insert(seeds[&i.layer], i.id, t.translation);
    }
    // Chunk entities (promoted instances draw with a child, counted by their parent).
    let mut chunks = app
        .world_mut()
        .query_filtered::<(&InstancedChunk, &Transform), Without<ChildOf>>();
    for (c, t) in chunks.iter(app.world()) {
        for (id, g) in c.buffer.ids.iter().zip(&c.buffer.instances) {
            insert(
                seeds[&c.layer],
                *id,
                t.translation + Vec3::from_array(g.offset),
            );
        }
    }
    out
}

/// Bytes held by instanced chunk buffers (instances and the identities kept for the test).
fn buffer_bytes(app: &mut App) -> usize {
    let mut chunks = app.world_mut().query::<&InstancedChunk>();
    chunks
        .iter(app.world())
        .map(|c| {
            c.buffer.instances.capacity() * size_of::<GpuInstance>()
                + c.buffer.ids.capacity() * size_of::<PointId>()
        })
        .sum()
}

/// Entities in the world.
fn entity_count(app: &mut App) -> usize {
    app.world_mut().query::<Entity>().iter(app.world()).count()
}

/// Resident memory of this process in bytes (Linux), or 0 where unknown.
fn resident_bytes() -> u64 {
    std::fs::read_to_string("/proc/self/statm")
        .ok()
        .and_then(|s| s.split_whitespace().nth(1)?.parse::<u64>().ok())
        .map_or(0, |pages| pages * 4096)
}

/// The soak world: a viewer, a painted layer and a constant layer that the walk replaces.
struct Soak {
    app: App,
    viewer: Entity,
    map: Handle<Image>,
    /// The map as it was before any painting.
    original: Image,
    /// The constant layer as it was at the start.
    constant: ScatterLayer,
    /// The entity holding the current constant layer.
    second: Entity,
}

/// What a promoted bush gets (a collider, in a game).
#[derive(Component)]
struct Solid;

/// The most of each figure over the walk.
#[derive(Default)]
struct Peaks {
    promoted: usize,
    live: usize,
    live_instanced: usize,
    buffer_bytes: usize,
    entities: usize,
    queued: usize,
    rss_after_warm_up: u64,
}

impl Soak {
    /// Small per-frame budgets so that queues, in-flight tasks and cancelled chunks are
    /// exercised on every step of the walk.
    fn new() -> Self {
        let mut app = App::new();
        app.add_plugins((
            MinimalPlugins,
            AssetPlugin::default(),
            RwtPlugins::default()
                .with_spawn_budget(400)
                .with_despawn_budget(400)
                .with_upload_budget(3_000)
                .with_max_tasks(6),
        ));
        app.world_mut()
            .resource_mut::<RwtSettings>()
            .keep_instance_ids = true;
        app.finish();
        app.cleanup();
        let viewer = spawn_viewer(&mut app, Vec3::ZERO);
        let original = solid_image(64, [90, 90, 90, 255]);
        let map = app
            .world_mut()
            .resource_mut::<Assets<Image>>()
            .add(original.clone());
        let painted = layer(LayerDensity::Image(GroundMap {
            image: map.clone(),
            min: Vec2::splat(-200.0),
            size: Vec2::splat(400.0),
            scale: 0.6,
        }))
        .with_seed(5)
        .with_falloff(20.0, 48.0);
        app.world_mut().spawn(painted);
        // Instanced grass, with a fall-off so that chunks change band as the walk goes, and
        // instanced bushes that become solid entities near the viewer.
        let grass = ScatterClass::instanced(LayerDensity::Constant(0.5), default(), default());
        let bushes = ScatterClass::instanced(LayerDensity::Constant(0.04), default(), default())
            .with_promotion(12.0, |e| {
                e.insert(Solid);
            });
        let mut instanced = layer(LayerDensity::Constant(0.0))
            .with_seed(11)
            .with_falloff(20.0, 56.0);
        instanced.classes = vec![grass, bushes];
        app.world_mut().spawn(instanced);
        let constant = layer(LayerDensity::Constant(0.2));
        let second = app.world_mut().spawn(constant.clone()).id();
        Self {
            app,
            viewer,
            map,
            original,
            constant,
            second,
        }
    }

    /// One frame of the walk: move, sometimes paint or replace the constant layer, update,
    /// and check that no identity is live twice and the figures agree.
    fn step(
        &mut self,
        frame: usize,
        at: Vec2,
        rng: &mut Rng,
        peaks: &mut Peaks,
        before: &mut HashMap<(u64, PointId), Vec3>,
    ) {
        let app = &mut self.app;
        move_viewer(app, self.viewer, Vec3::new(at.x, 0.0, at.y));
        if frame % 250 == 125 {
            // Paint a random square white or black.
            let (x0, y0) = (rng.below(56) as u32, rng.below(56) as u32);
            let color = if rng.below(2) == 0 {
                Color::WHITE
            } else {
                Color::BLACK
            };
            paint_square(app, &self.map, x0, y0, color);
        }
        if frame % 1_000 == 500 {
            // Replace the constant layer by a denser or sparser one, or by itself.
            app.world_mut().entity_mut(self.second).despawn();
            let density = 0.1 + 0.2 * rng.next_f64();
            self.second = app
                .world_mut()
                .spawn(layer(LayerDensity::Constant(density)))
                .id();
        }
        app.update();
        let now = instances(app); // panics on a duplicate PointId
        // An instance never moves: not when its chunk is generated again, not when it is
        // promoted to an entity or handed back.
        for (key, at) in &now {
            if let Some(was) = before.get(key) {
                assert_eq!(was, at, "{key:?} moved in frame {frame}");
            }
        }
        let live = now.len();
        *before = now;
        let stats = app.world().resource::<RwtStats>().clone();
        assert_eq!(live, stats.live_entities + stats.live_instanced);
        let mut solid = app.world_mut().query_filtered::<(), With<Solid>>();
        let promoted: usize = app
            .world_mut()
            .query::<&ScatterLayerStatus>()
            .iter(app.world())
            .map(|s| s.promoted_instances)
            .sum();
        assert_eq!(solid.iter(app.world()).count(), promoted);
        peaks.promoted = peaks.promoted.max(promoted);
        peaks.live = peaks.live.max(stats.live_entities);
        peaks.live_instanced = peaks.live_instanced.max(stats.live_instanced);
        peaks.buffer_bytes = peaks.buffer_bytes.max(buffer_bytes(app));
        peaks.entities = peaks.entities.max(entity_count(app));
        // Waiting work never outgrows the loaded chunks it belongs to.
        assert!(stats.pending_tasks <= stats.loaded_chunks, "{stats:?}");
        peaks.queued = peaks.queued.max(stats.queued_spawns);
        if frame == 500 {
            peaks.rss_after_warm_up = resident_bytes();
        }
    }

    /// A wandering walk (0.5 to 4 units a frame) that stays within 250 units of the start;
    /// returns where it ends.
    fn walk(&mut self, peaks: &mut Peaks) -> Vec2 {
        let mut rng = Rng::new(2006, 1);
        let mut at = Vec2::ZERO;
        let mut heading = 0.0f32;
        let mut before = HashMap::new();
        for frame in 0..FRAMES {
            heading += (rng.next_f64() as f32 - 0.5) * 0.6;
            if at.length() > 250.0 {
                heading = (-at.y).atan2(-at.x);
            }
            let step = 0.5 + 3.5 * rng.next_f64() as f32;
            at += Vec2::new(heading.cos(), heading.sin()) * step;
            self.step(frame, at, &mut rng, peaks, &mut before);
        }
        at
    }

    /// Undoes the changes and walks back to the start from `from`, then lets streaming
    /// settle.
    fn undo_and_return(&mut self, from: Vec2) {
        let app = &mut self.app;
        *app.world_mut()
            .resource_mut::<Assets<Image>>()
            .get_mut(&self.map)
            .unwrap() = self.original.clone();
        app.world_mut().entity_mut(self.second).despawn();
        app.world_mut().spawn(self.constant.clone());
        let steps = (from.length() / 3.0).ceil() as usize;
        for i in 1..=steps {
            let p = from * (1.0 - i as f32 / steps as f32);
            move_viewer(app, self.viewer, Vec3::new(p.x, 0.0, p.y));
            app.update();
        }
        tick_app(app, 3_000);
    }
}

/// Bounded: entity layers of at most 0.6 and 0.3 per square unit and an instanced one of
/// 0.5 over the unload disc, instance buffers that hold no more than their instances, and
/// resident memory that stops growing after the warm-up.
fn assert_bounded(peaks: &Peaks) {
    let disc = std::f64::consts::PI * (64.0f64 + 23.0).powi(2);
    let (most_live, most_entities) = (peaks.live, peaks.entities);
    assert!(
        (most_live as f64) < 0.9 * disc,
        "{most_live} live instances"
    );
    assert!(
        (most_entities as f64) < 0.9 * disc + 1_000.0,
        "{most_entities} entities"
    );
    let most_instanced = peaks.live_instanced;
    assert!(peaks.promoted > 5, "{} promoted at most", peaks.promoted);
    assert!(
        most_instanced > 1_000 && (most_instanced as f64) < 0.5 * disc,
        "{most_instanced} live instanced"
    );
    // Buffers are packed to size: no more than their instances and identities, plus slack
    // for the chunks being swapped this frame.
    let per_instance = size_of::<GpuInstance>() + size_of::<PointId>();
    assert!(
        peaks.buffer_bytes <= 2 * most_instanced * per_instance,
        "{} bytes of instance buffers for {most_instanced} instances",
        peaks.buffer_bytes
    );
    let grown = resident_bytes().saturating_sub(peaks.rss_after_warm_up);
    eprintln!(
        "soak: {FRAMES} frames, at most {most_live} live instances, {most_entities} entities, \
         {most_instanced} instanced in {} KiB of buffers ({} promoted), {} queued spawns; \
         resident memory grew {} KiB after frame 500",
        peaks.buffer_bytes >> 10,
        peaks.promoted,
        peaks.queued,
        grown >> 10
    );
    assert!(
        grown < 64 << 20,
        "resident memory grew by {} MiB",
        grown >> 20
    );
}

#[test]
fn a_long_random_walk_with_painting_and_layer_changes() {
    let mut soak = Soak::new();
    tick_app(&mut soak.app, 3_000);
    let start = instances(&mut soak.app);
    let start_entities = other_entities(&mut soak.app);
    assert!(start.len() > 500, "{} instances at the start", start.len());
    let mut peaks = Peaks::default();
    let at = soak.walk(&mut peaks);
    assert_bounded(&peaks);

    // Undo the changes and walk back: the world near the start is exactly as it was.
    soak.undo_and_return(at);
    let end = instances(&mut soak.app);
    let within = |p: &Vec3, d: f32| Vec2::new(p.x, p.z).length() < d;
    for (id, p) in &start {
        if within(p, 48.0 - 23.0) {
            assert_eq!(end.get(id), Some(p), "{id:?} moved or vanished");
        }
    }
    for (id, p) in &end {
        if within(p, 48.0 - 23.0) {
            assert_eq!(start.get(id), Some(p), "{id:?} appeared");
        }
    }
    // Nothing leaked: apart from instances and chunk entities, as many entities as before
    // (the viewer, the layers), and one chunk entity per loaded chunk of the instanced layer.
    assert_eq!(other_entities(&mut soak.app), start_entities);
    let mut statuses = soak
        .app
        .world_mut()
        .query::<(&ScatterLayer, &ScatterLayerStatus)>();
    let instanced_chunks = statuses
        .iter(soak.app.world())
        .find(|(l, _)| l.seed == 11)
        .map(|(_, s)| s.loaded_chunks.len())
        .unwrap();
    let mut chunks = soak
        .app
        .world_mut()
        .query_filtered::<&InstancedChunk, Without<ChildOf>>();
    assert!(chunks.iter(soak.app.world()).count() <= 2 * instanced_chunks);
}

/// Entities that are neither instances nor instanced chunks.
fn other_entities(app: &mut App) -> usize {
    let mut instances = app.world_mut().query::<&ScatterEntity>();
    let mut chunks = app.world_mut().query::<&InstancedChunk>();
    entity_count(app) - instances.iter(app.world()).count() - chunks.iter(app.world()).count()
}
