//! What per-instance edits cost a streamed world: `cargo bench -p bevy_rwt --bench edits`.
//! A headless fly-through of 600 frames over trees (entities) and grass (instanced) with 0,
//! 10 000 and 100 000 instances removed along the flight, in one run; prints per count
//! the frame times, the unedited run's median (the baseline), the edits file's size and the
//! time to read and check it.

mod common;

use bevy::prelude::*;
use bevy_rwt::edits::{Edit, EditSet, EditStamp, ScatterEdits};
use bevy_rwt::prelude::*;
use bevy_rwt::rwt_core::query::{Rect, Sampler};
use bevy_rwt::rwt_core::streaming::ChunkCoord;
use bevy_rwt::rwt_core::{Constant, TileSet};
use common::{headless_app, move_viewer};
use glam::DVec2;
use std::collections::HashMap;
use std::time::Instant;

const SEED: u64 = 17;
const TILE: f64 = 16.0;
const DENSITIES: [f64; 2] = [0.02, 0.5];
/// Units flown per frame, and frames.
const SPEED: f32 = 4.0;
const FRAMES: usize = 600;

fn main() {
    let set = TileSet::embedded();
    let stamp = EditStamp {
        seed: SEED,
        lattice: Lattice::Seeded,
        tile_set: set.fingerprint(),
    };
    let corridor = corridor_points(&set);
    let mut baseline = None;
    for removed in [0usize, 10_000, 100_000] {
        let edits = every_nth(&corridor, removed);
        let bytes = edits.to_bytes(&stamp);
        let load_ms = load(&bytes, &stamp, &edits);
        let (median, max) = fly(edits.clone());
        let base = *baseline.get_or_insert(median);
        println!(
            "edits removed={removed} median_ms={median:.2} max_ms={max:.2} baseline_median_ms={base:.2} file_bytes={} load_ms={load_ms:.2}",
            bytes.len()
        );
        if removed > 0 {
            let (edited, plain) = generation(&set, &edits);
            println!(
                "  ratio to the unedited median {:.3}, {:.2} bytes per edit; generating the \
                 corridor's chunks with their edits {edited:.1} ms, without {plain:.1} ms \
                 (ratio {:.3})",
                median / base,
                bytes.len() as f64 / removed as f64,
                edited / plain
            );
        }
    }
}

/// Every point of both classes along the flight (x in 0..2 400, z within 200 of it).
fn corridor_points(set: &TileSet) -> Vec<bevy_rwt::rwt_core::Point> {
    let sampler = Sampler::new(set, SEED).with_tile_size(TILE);
    let rect = Rect::new(DVec2::new(0.0, -200.0), DVec2::new(2_400.0, 200.0)).unwrap();
    let mut points = Vec::new();
    sampler
        .query_classes(rect, &DENSITIES.map(Constant), |p| points.push(p))
        .unwrap();
    points
}

/// `count` of `points`, spread evenly, removed.
fn every_nth(points: &[bevy_rwt::rwt_core::Point], count: usize) -> EditSet {
    let mut set = EditSet::default();
    if count > 0 {
        let step = points.len() as f64 / count as f64;
        for k in 0..count {
            set.set(points[(k as f64 * step) as usize].id, Edit::Remove)
                .unwrap();
        }
    }
    set
}

/// Milliseconds to generate every chunk of the corridor and apply its edits (split by
/// chunk as streaming splits them), with the edits and without, best of three.
fn generation(set: &TileSet, edits: &EditSet) -> (f64, f64) {
    let sampler = Sampler::new(set, SEED).with_tile_size(TILE);
    let size = 32.0;
    let located = edits.iter().map(|(id, e)| {
        let p = sampler.locate(id).unwrap();
        (ChunkCoord::containing(p, size), *id, *e)
    });
    let mut by_chunk: HashMap<ChunkCoord, EditSet> = HashMap::new();
    for (chunk, id, e) in located {
        by_chunk.entry(chunk).or_default().set(id, e).unwrap();
    }
    let time = |with: bool| {
        let mut best = f64::INFINITY;
        for _ in 0..3 {
            let started = Instant::now();
            for x in 0..75 {
                for y in -7..7 {
                    let chunk = ChunkCoord { x, y };
                    let mut points = Vec::new();
                    let densities = DENSITIES.map(Constant);
                    sampler
                        .query_classes(chunk.rect(size), &densities, |p| points.push(p))
                        .unwrap();
                    if let Some(e) = by_chunk.get(&chunk).filter(|_| with) {
                        e.apply(&mut points, 2);
                    }
                    std::hint::black_box(points);
                }
            }
            best = best.min(started.elapsed().as_secs_f64() * 1e3);
        }
        best
    };
    (time(true), time(false))
}

/// Writes the edits file, then reads and checks it back as a load does; milliseconds.
fn load(bytes: &[u8], stamp: &EditStamp, expected: &EditSet) -> f64 {
    let path = std::env::temp_dir().join(format!("rwt-bench-{}.edits", std::process::id()));
    std::fs::write(&path, bytes).unwrap();
    let started = Instant::now();
    let read = std::fs::read(&path).unwrap();
    let set = EditSet::from_bytes(&read, stamp).unwrap();
    let ms = started.elapsed().as_secs_f64() * 1e3;
    assert_eq!(&set, expected);
    std::fs::remove_file(&path).ok();
    ms
}

/// Fills the world around the start with `edits` in place, flies, and returns the median
/// and largest frame time (ms).
fn fly(edits: EditSet) -> (f64, f64) {
    let (mut app, viewer) = headless_app(RwtPlugins::default().with_max_tasks(32));
    let trees = ScatterClass::new(LayerDensity::Constant(DENSITIES[0]), default(), default());
    let grass = ScatterClass::instanced(
        LayerDensity::Constant(DENSITIES[1]),
        default(),
        InstancedShading::default(),
    );
    let streaming = StreamingConfig {
        chunk_size: 32.0,
        load_distance: 300.0,
        unload_distance: 340.0,
        near_distance: 64.0,
    };
    let layer = ScatterLayer::new(vec![trees, grass])
        .with_tile_size(TILE)
        .with_seed(SEED)
        .with_streaming(streaming);
    app.world_mut().spawn((layer, ScatterEdits::new(edits)));
    settle(&mut app);
    let mut times = Vec::with_capacity(FRAMES);
    for f in 0..FRAMES {
        move_viewer(&mut app, viewer, Vec3::new(f as f32 * SPEED, 2.0, 0.0));
        let t = Instant::now();
        app.update();
        times.push(t.elapsed().as_secs_f64() * 1e3);
    }
    times.sort_by(f64::total_cmp);
    (times[times.len() / 2], times[times.len() - 1])
}

/// Runs frames until nothing is pending.
fn settle(app: &mut App) {
    assert!(
        bevy_rwt::testing::settle(app, 100_000),
        "the world did not fill"
    );
}
