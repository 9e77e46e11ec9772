//! Frame timing for the cost benchmarks (`grass_cost`, open_world's `RWT_COST`): per frame,
//! the main world's schedules, the render world's work (extraction, preparation and
//! queueing: from the end of the main world's frame to the start of the render graph) and
//! the whole frame, including the render graph and, with a software driver such as
//! lavapipe, the drawing itself.
//!
//! The render world's time is only its own with pipelined rendering off (the two worlds
//! then run one after the other): the app disables `PipelinedRenderingPlugin`.

use bevy::prelude::*;
use bevy::render::{Render, RenderApp, RenderSystems};
use std::fmt;
use std::sync::{Arc, Mutex};
use std::time::Instant;

/// Adds the clock's systems to both worlds and the [`FrameClock`] resource.
pub struct FrameClockPlugin;

impl Plugin for FrameClockPlugin {
    fn build(&self, app: &mut App) {
        let clock = FrameClock::default();
        app.insert_resource(clock.clone())
            .add_systems(First, start_frame)
            .add_systems(Last, end_main_world);
        if let Some(render) = app.get_sub_app_mut(RenderApp) {
            render.insert_resource(clock).add_systems(
                Render,
                end_render_world
                    .after(RenderSystems::PrepareBindGroups)
                    .before(RenderSystems::Render),
            );
        }
    }
}

/// Timestamps shared by the main and render worlds, and the frames recorded so far.
#[derive(Resource, Clone, Default)]
pub struct FrameClock(Arc<Mutex<Timing>>);

#[derive(Default)]
struct Timing {
    frame_start: Option<Instant>,
    main_end: Option<Instant>,
    /// Whether the current frame is recorded.
    recording: bool,
    /// Per frame: main world, render world, whole frame (ms).
    samples: Vec<[f64; 3]>,
    /// Render-world time of the frame in progress.
    render_ms: f64,
}

impl FrameClock {
    /// Records the frames from the next one on (`true`), or stops recording.
    pub fn record(&self, on: bool) {
        self.0.lock().unwrap().recording = on;
    }

    /// Frames recorded since the last [`FrameClock::take`].
    pub fn recorded(&self) -> usize {
        self.0.lock().unwrap().samples.len()
    }

    /// The recorded frames' times, summarised; stops recording and forgets them.
    pub fn take(&self) -> FrameTimes {
        FrameTimes::of(&self.take_frames())
    }

    /// The recorded frames' times one by one (main world, render world, whole frame, in
    /// ms), for timings that pool several runs of a setting; stops recording and forgets
    /// them.
    pub fn take_frames(&self) -> Vec<[f64; 3]> {
        let mut t = self.0.lock().unwrap();
        t.recording = false;
        std::mem::take(&mut t.samples)
    }
}

/// The median and 95th percentile of a set of times (ms).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Spread {
    /// The median.
    pub median: f64,
    /// The 95th percentile.
    pub p95: f64,
}

impl Spread {
    fn of(mut v: Vec<f64>) -> Self {
        if v.is_empty() {
            return Self::default();
        }
        v.sort_by(f64::total_cmp);
        Self {
            median: v[v.len() / 2],
            p95: v[v.len() * 95 / 100],
        }
    }
}

/// As the benchmarks' result lines show it: `median/p95`.
impl fmt::Display for Spread {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{:.2}/{:.2}", self.median, self.p95)
    }
}

/// One set of recorded frames: main world, render world, whole frame.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FrameTimes {
    /// The main world's schedules.
    pub main: Spread,
    /// The render world's extraction, preparation and queueing.
    pub render_world: Spread,
    /// The whole frame.
    pub frame: Spread,
}

impl FrameTimes {
    /// The times of `frames` (main world, render world, whole frame, in ms), summarised.
    pub fn of(frames: &[[f64; 3]]) -> Self {
        let column = |i: usize| Spread::of(frames.iter().map(|s| s[i]).collect());
        Self {
            main: column(0),
            render_world: column(1),
            frame: column(2),
        }
    }
}

/// As the benchmarks' result lines show it.
impl fmt::Display for FrameTimes {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "main_ms={} render_world_ms={} frame_ms={}",
            self.main, self.render_world, self.frame
        )
    }
}

fn start_frame(clock: Res<FrameClock>) {
    let mut t = clock.0.lock().unwrap();
    let now = Instant::now();
    if t.recording
        && let (Some(start), Some(end)) = (t.frame_start, t.main_end)
    {
        let sample = [
            (end - start).as_secs_f64() * 1e3,
            t.render_ms,
            (now - start).as_secs_f64() * 1e3,
        ];
        t.samples.push(sample);
    }
    t.frame_start = Some(now);
}

fn end_main_world(clock: Res<FrameClock>) {
    clock.0.lock().unwrap().main_end = Some(Instant::now());
}

fn end_render_world(clock: Res<FrameClock>) {
    let mut t = clock.0.lock().unwrap();
    if let Some(end) = t.main_end {
        t.render_ms = end.elapsed().as_secs_f64() * 1e3;
    }
}
