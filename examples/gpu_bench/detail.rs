//! `--detail`: where a case's frame time goes. After each case's line it prints
//!
//! `gpu-bench-detail: blades=B shadows=S cull=C main_ms=M render_cpu_ms=R gpu_wait_ms=W PASS_ms=G ..`
//!
//! (medians over the frames timed): the main world's schedules, the render world's from
//! its start to the GPU wait, the wait for the GPU to finish the frame `--latency` frames
//! before (the frame itself with `--latency 0`), and each render
//! pass's GPU time where the adapter has timestamp queries (Bevy's
//! `RenderDiagnosticsPlugin`, averaged over its recent frames).

use bevy::diagnostic::DiagnosticsStore;
use bevy::prelude::*;
use bevy::render::diagnostic::RenderDiagnosticsPlugin;
use bevy::render::{Render, RenderApp, RenderSystems};
use std::sync::{Arc, Mutex};
use std::time::Instant;

/// Frames whose split is kept (the most a case times).
const KEPT: usize = 10_000;

/// Timestamps shared by the main and render worlds, and each frame's split.
#[derive(Resource, Clone, Default)]
pub struct Split(Arc<Mutex<Times>>);

#[derive(Default)]
struct Times {
    main_start: Option<Instant>,
    render_start: Option<Instant>,
    wait_start: Option<Instant>,
    /// Main world, render world until the wait, the wait (ms) of the frame in progress.
    main_ms: f64,
    render_ms: f64,
    /// Per frame: main, render, wait (ms).
    frames: Vec<[f64; 3]>,
}

/// Adds the split's timing systems around the render world's wait for the GPU (`wait`),
/// and Bevy's render diagnostics.
pub fn add(app: &mut App, wait: impl SystemSet + Clone) {
    let split = Split::default();
    app.add_plugins(RenderDiagnosticsPlugin)
        .insert_resource(split.clone())
        .add_systems(First, main_start)
        .add_systems(Last, main_end);
    app.sub_app_mut(RenderApp)
        .insert_resource(split)
        .add_systems(Render, render_start.in_set(RenderSystems::ExtractCommands))
        .add_systems(
            Render,
            (
                wait_start.after(RenderSystems::Render).before(wait.clone()),
                wait_end.after(wait),
            ),
        );
}

fn main_start(split: Res<Split>) {
    split.0.lock().unwrap().main_start = Some(Instant::now());
}

fn main_end(split: Res<Split>) {
    let mut t = split.0.lock().unwrap();
    if let Some(start) = t.main_start {
        t.main_ms = start.elapsed().as_secs_f64() * 1e3;
    }
}

fn render_start(split: Res<Split>) {
    split.0.lock().unwrap().render_start = Some(Instant::now());
}

fn wait_start(split: Res<Split>) {
    let mut t = split.0.lock().unwrap();
    let now = Instant::now();
    if let Some(start) = t.render_start {
        t.render_ms = (now - start).as_secs_f64() * 1e3;
    }
    t.wait_start = Some(now);
}

fn wait_end(split: Res<Split>) {
    let mut t = split.0.lock().unwrap();
    let Some(start) = t.wait_start else { return };
    let frame = [t.main_ms, t.render_ms, start.elapsed().as_secs_f64() * 1e3];
    if t.frames.len() == KEPT {
        t.frames.remove(0);
    }
    t.frames.push(frame);
}

/// The detail line of the last `frames` frames, after `case` (the case line's fields).
pub fn line(case: &str, frames: usize, split: &Split, store: &DiagnosticsStore) -> String {
    let t = split.0.lock().unwrap();
    let recent = &t.frames[t.frames.len().saturating_sub(frames)..];
    let median = |i: usize| {
        let mut v: Vec<f64> = recent.iter().map(|f| f[i]).collect();
        v.sort_by(f64::total_cmp);
        v.get(v.len() / 2).copied().unwrap_or(f64::NAN)
    };
    let mut text = format!(
        "gpu-bench-detail: {case} main_ms={:.2} render_cpu_ms={:.2} gpu_wait_ms={:.2}",
        median(0),
        median(1),
        median(2)
    );
    let mut passes: Vec<(String, f64)> = store
        .iter()
        .filter(|d| d.path().as_str().ends_with("/elapsed_gpu"))
        .filter_map(|d| {
            let name = d.path().as_str().trim_start_matches("render/");
            let name = name.trim_end_matches("/elapsed_gpu").replace('/', ".");
            Some((name, d.average()?))
        })
        .collect();
    passes.sort_by(|a, b| a.0.cmp(&b.0));
    for (name, ms) in passes {
        text += &format!(" {name}_ms={ms:.2}");
    }
    text
}
