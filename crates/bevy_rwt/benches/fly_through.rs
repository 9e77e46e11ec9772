//! Headless fly-through over a world of about a million live instances:
//! `cargo bench -p bevy_rwt`. Prints the median and maximum time of a whole frame (the
//! plugin's systems and the spawning and despawning they command) and instance churn.

mod common;

use bevy::prelude::*;
use bevy_rwt::prelude::*;
use common::{headless_app, move_viewer};
use std::time::Instant;

fn main() {
    for speed in [2.0f32, 8.0] {
        run(speed);
    }
}

fn run(speed: f32) {
    println!(
        "== flying at {speed} units per frame ({} units/s at 60 fps)",
        speed * 60.0
    );
    let (mut app, viewer) = world();
    fill(&mut app);
    fly(&mut app, viewer, speed);
}

/// A headless app with one grass layer of 0.5 instances per square unit and a viewer;
/// returns the app and the viewer.
fn world() -> (App, Entity) {
    let (mut app, viewer) = headless_app(RwtPlugins::default().with_max_tasks(32));
    let grass = ScatterClass::new(
        LayerDensity::Constant(0.5),
        Handle::default(),
        Handle::default(),
    );
    let streaming = StreamingConfig {
        chunk_size: 32.0,
        load_distance: 800.0,
        unload_distance: 880.0,
        near_distance: 64.0,
    };
    app.world_mut().spawn(
        ScatterLayer::new(vec![grass])
            .with_tile_size(16.0)
            .with_streaming(streaming),
    );
    (app, viewer)
}

/// Runs frames until the world around the start is filled.
fn fill(app: &mut App) {
    let started = Instant::now();
    let mut frames = 0;
    loop {
        app.update();
        frames += 1;
        let s = app.world().resource::<RwtStats>();
        if s.settled() && s.live_entities > 0 {
            break;
        }
        if frames > 100_000 {
            panic!("the world did not fill");
        }
    }
    let live = app.world().resource::<RwtStats>().live_entities;
    println!(
        "filled {live} instances in {frames} frames, {:.2} s",
        started.elapsed().as_secs_f64()
    );
}

/// Flies the viewer for 600 frames and prints frame times and churn.
fn fly(app: &mut App, viewer: Entity, speed: f32) {
    let mut times = Vec::with_capacity(600);
    let (mut most, mut least) = (0, usize::MAX);
    let (mut spawned, mut despawned) = (0usize, 0usize);
    let mut previous: std::collections::HashSet<Entity> = std::collections::HashSet::new();
    let mut q = app
        .world_mut()
        .query_filtered::<Entity, With<ScatterEntity>>();
    previous.extend(q.iter(app.world()));
    let fly = Instant::now();
    for f in 0..600 {
        let x = f as f32 * speed;
        let at = Vec3::new(x, 2.0, (x * 0.01).sin() * 200.0);
        move_viewer(app, viewer, at);
        let t = Instant::now();
        app.update();
        times.push(t.elapsed().as_secs_f64() * 1e3);
        let now: std::collections::HashSet<Entity> = q.iter(app.world()).collect();
        spawned += now.difference(&previous).count();
        despawned += previous.difference(&now).count();
        most = most.max(now.len());
        least = least.min(now.len());
        previous = now;
    }
    let seconds = fly.elapsed().as_secs_f64();
    times.sort_by(f64::total_cmp);
    let stats = app.world().resource::<RwtStats>().clone();
    println!(
        "fly-through: 600 frames, live instances between {least} and {most} (now {})",
        stats.live_entities
    );
    println!(
        "frame time: median {:.2} ms, 95th percentile {:.2} ms, max {:.2} ms",
        times[times.len() / 2],
        times[times.len() * 95 / 100],
        times[times.len() - 1]
    );
    println!(
        "churn: {spawned} spawned, {despawned} despawned ({:.0} and {:.0} per second of frames)",
        spawned as f64 / seconds,
        despawned as f64 / seconds
    );
}
