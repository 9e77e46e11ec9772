//! Headless fly-through over grass drawn by the instanced path and by the entity path:
//! `cargo bench -p bevy_rwt --bench instanced`. Each run fills the world around the start,
//! then flies 600 frames and prints one line, on stdout, in exactly this form:
//!
//! `instanced live=N median_ms=X p95_ms=Y max_ms=Z gpu_bytes_per_instance=B`
//! `entities live=N median_ms=X p95_ms=Y max_ms=Z`
//!
//! A frame is the whole `app.update()`: planning, collecting finished generation tasks
//! (points queried and packed on the async compute pool), buffer hand-off or spawning and
//! despawning; frames are paced at 60 per second, as in a game, so that generation runs
//! between them. `live` is the median count of live instances over the flight. Fill
//! times and what is left pending after the flight go to stderr; with `RWT_BENCH_TRACE` set,
//! so does every frame over 3 ms, with the live count before and after it.

mod common;

use bevy::prelude::*;
use bevy_rwt::instancing::GPU_BYTES_PER_INSTANCE;
use bevy_rwt::prelude::*;
use common::{headless_app, move_viewer};
use std::time::{Duration, Instant};

/// Streaming radius of the grass, world units.
const RADIUS: f64 = 160.0;
/// Chunk side, world units.
const CHUNK: f64 = 32.0;
/// Frames of flight per run.
const FRAMES: usize = 600;
/// Flight speed, world units per frame (120 units per second at 60 fps).
const SPEED: f32 = 2.0;
/// Frames are paced at 60 per second, as in a game: generation tasks run on the async
/// compute pool between frames, and a frame's time is that of its `app.update()`.
const FRAME: Duration = Duration::from_nanos(16_666_667);

/// How the grass is drawn.
#[derive(Clone, Copy, PartialEq)]
enum Path {
    Instanced,
    Entities,
}

fn main() {
    for live in [1.0e6, 5.0e6, 10.0e6] {
        run(Path::Instanced, live);
    }
    for live in [1.0e6, 2.0e6] {
        run(Path::Entities, live);
    }
}

/// Fills and flies a world holding about `live` instances, and prints its line.
fn run(path: Path, live: f64) {
    // Chunks touching the load disc stay loaded out to the unload distance: about a chunk
    // beyond the radius.
    let density = live / (std::f64::consts::PI * (RADIUS + CHUNK).powi(2));
    let (mut app, viewer) = world(path, density);
    fill(&mut app, live);
    let (times, counts) = fly(&mut app, viewer);
    let (median, p95, max) = figures(times);
    let live = median_count(counts);
    match path {
        Path::Instanced => println!(
            "instanced live={live} median_ms={median:.2} p95_ms={p95:.2} max_ms={max:.2} \
             gpu_bytes_per_instance={GPU_BYTES_PER_INSTANCE}"
        ),
        Path::Entities => {
            println!("entities live={live} median_ms={median:.2} p95_ms={p95:.2} max_ms={max:.2}")
        }
    }
}

/// A headless app with one grass layer of `density` blades per square unit within
/// [`RADIUS`] and a viewer; returns the app and the viewer.
fn world(path: Path, density: f64) -> (App, Entity) {
    let (mut app, viewer) = headless_app(
        RwtPlugins::default()
            .with_max_tasks(32)
            .with_spawn_budget(20_000)
            .with_despawn_budget(40_000),
    );
    let grass = match path {
        Path::Instanced => ScatterClass::instanced(
            LayerDensity::Constant(density),
            Handle::default(),
            InstancedShading::default(),
        ),
        Path::Entities => ScatterClass::new(
            LayerDensity::Constant(density),
            Handle::default(),
            Handle::default(),
        ),
    };
    let streaming = StreamingConfig {
        chunk_size: CHUNK,
        load_distance: RADIUS,
        unload_distance: RADIUS + 24.0,
        near_distance: 48.0,
    };
    app.world_mut().spawn(
        ScatterLayer::new(vec![grass])
            .with_tile_size(2.0)
            .with_streaming(streaming),
    );
    (app, viewer)
}

/// All live instances, entity or instanced.
fn live(app: &App) -> usize {
    let s = app.world().resource::<RwtStats>();
    s.live_entities + s.live_instanced
}

/// Runs frames until the world around the start is filled.
fn fill(app: &mut App, expected: f64) {
    let started = Instant::now();
    let mut frames = 0;
    loop {
        app.update();
        frames += 1;
        let s = app.world().resource::<RwtStats>();
        if s.settled() && live(app) > 0 {
            break;
        }
        assert!(frames < 1_000_000, "the world did not fill");
    }
    eprintln!(
        "filled {} instances (about {expected:.0} expected) in {frames} frames, {:.2} s",
        live(app),
        started.elapsed().as_secs_f64()
    );
}

/// Flies the viewer for [`FRAMES`] frames; returns the frame times (ms) and live counts.
fn fly(app: &mut App, viewer: Entity) -> (Vec<f64>, Vec<usize>) {
    let mut times = Vec::with_capacity(FRAMES);
    let mut counts = Vec::with_capacity(FRAMES);
    let start = Instant::now();
    for f in 0..FRAMES {
        let x = f as f32 * SPEED;
        let at = Vec3::new(x, 2.0, (x * 0.01).sin() * 100.0);
        move_viewer(app, viewer, at);
        let t = Instant::now();
        app.update();
        times.push(t.elapsed().as_secs_f64() * 1e3);
        counts.push(live(app));
        if std::env::var_os("RWT_BENCH_TRACE").is_some() && times[f] > 3.0 {
            let s = app.world().resource::<RwtStats>();
            eprintln!(
                "frame {f}: {:.2} ms, live {} -> {}, loaded chunks {}, pending {}",
                times[f],
                counts.get(f.wrapping_sub(1)).copied().unwrap_or(0),
                counts[f],
                s.loaded_chunks,
                s.pending_tasks
            );
        }
        let next = start + FRAME * (f as u32 + 1);
        std::thread::sleep(next.saturating_duration_since(Instant::now()));
    }
    let s = app.world().resource::<RwtStats>();
    let slowest = (0..FRAMES)
        .max_by(|&a, &b| times[a].total_cmp(&times[b]))
        .unwrap_or(0);
    eprintln!(
        "after the flight: {} live, {} pending tasks, {} queued; slowest frame {slowest}",
        live(app),
        s.pending_tasks,
        s.queued_spawns
    );
    (times, counts)
}

/// Median, 95th percentile and maximum.
fn figures(mut times: Vec<f64>) -> (f64, f64, f64) {
    times.sort_by(f64::total_cmp);
    let n = times.len();
    (times[n / 2], times[n * 95 / 100], times[n - 1])
}

fn median_count(mut counts: Vec<usize>) -> usize {
    counts.sort_unstable();
    counts[counts.len() / 2]
}
