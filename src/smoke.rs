//! The scripted session CI runs in a real renderer.
//!
//! `RWT_SCREENSHOT=path.png` makes an example play its script (a flight, painted strokes, a
//! zoom), take a screenshot after `RWT_EXIT_AFTER_FRAMES` frames (default 150), print its
//! live instance count and exit with status 0. `RWT_EXIT_AFTER_FRAMES` alone runs the script
//! and exits without a screenshot. A screenshot that never arrives exits with an error.

use bevy::app::AppExit;
use bevy::prelude::*;
use bevy::render::view::screenshot::{Screenshot, ScreenshotCaptured};
use bevy_rwt::{RwtStats, ScatterEntity};
use std::path::PathBuf;

/// The smoke session's settings and frame counter.
#[derive(Resource, Clone, Debug, Default)]
pub struct Smoke {
    /// Where to save the screenshot.
    pub screenshot: Option<PathBuf>,
    /// Frames before the screenshot (or the exit); `None` outside a smoke session.
    pub exit_after: Option<u32>,
    /// Frames played so far.
    pub frame: u32,
}

impl Smoke {
    /// Reads `RWT_SCREENSHOT` and `RWT_EXIT_AFTER_FRAMES`.
    pub fn from_env() -> Self {
        let screenshot = std::env::var_os("RWT_SCREENSHOT").map(PathBuf::from);
        let frames = std::env::var("RWT_EXIT_AFTER_FRAMES")
            .ok()
            .and_then(|v| v.trim().parse::<u32>().ok());
        let exit_after = match (&screenshot, frames) {
            (_, Some(n)) => Some(n.max(1)),
            (Some(_), None) => Some(150),
            (None, None) => None,
        };
        Self {
            screenshot,
            exit_after,
            frame: 0,
        }
    }

    /// Whether a scripted session runs.
    pub fn active(&self) -> bool {
        self.exit_after.is_some()
    }

    /// Progress of the script in `[0, 1]` (0 outside a smoke session).
    pub fn progress(&self) -> f32 {
        self.exit_after
            .map_or(0.0, |n| (self.frame as f32 / n as f32).min(1.0))
    }
}

/// Marks an instance an example spawns itself (outside `bevy_rwt`), so that it is counted.
#[derive(Component, Default)]
pub struct CountedInstance;

/// Live instances, updated every frame: entities (`bevy_rwt` instances plus
/// [`CountedInstance`]s), and instances of `bevy_rwt`'s instanced classes.
#[derive(Resource, Default, Debug, Clone, Copy)]
pub struct LiveInstances(pub usize, pub usize);

/// What the smoke line reports besides the instances: the instances a scripted brush stroke
/// added or removed (examples that paint set it), and the most generation tasks pending in
/// any frame of the session.
#[derive(Resource, Default, Debug, Clone, Copy)]
pub struct SmokeReport {
    /// Instances the scripted stroke added or removed; `None` where nothing is painted.
    pub painted: Option<usize>,
    /// Most generation tasks pending in one frame.
    pub pending_max: usize,
    /// Generation tasks pending now.
    pub pending: usize,
    /// Set by an example whose script is not finished: the screenshot waits for it to be
    /// cleared (at most 450 frames, then it is taken anyway).
    pub hold: bool,
}

/// Runs the smoke session when the environment asks for one; counts instances always.
pub struct SmokePlugin;

impl Plugin for SmokePlugin {
    fn build(&self, app: &mut App) {
        let smoke = Smoke::from_env();
        if smoke.active() {
            // Software rendering: no multisampling, so a scripted frame stays cheap.
            app.add_observer(|add: On<Add, Camera>, mut commands: Commands| {
                commands.entity(add.entity).insert(Msaa::Off);
            });
        }
        app.insert_resource(smoke)
            .init_resource::<LiveInstances>()
            .init_resource::<SmokeReport>()
            .init_resource::<Shots>()
            .add_systems(First, count_frame)
            .add_systems(Last, (count_instances, finish).chain());
    }
}

fn count_frame(mut smoke: ResMut<Smoke>) {
    if smoke.active() {
        smoke.frame += 1;
    }
}

fn count_instances(
    mut live: ResMut<LiveInstances>,
    mut report: ResMut<SmokeReport>,
    scattered: Query<(), With<ScatterEntity>>,
    counted: Query<(), With<CountedInstance>>,
    stats: Option<Res<RwtStats>>,
) {
    live.0 = scattered.iter().len() + counted.iter().len();
    live.1 = stats.as_ref().map_or(0, |s| s.live_instanced);
    report.pending = stats.map_or(0, |s| s.pending_tasks);
    report.pending_max = report.pending_max.max(report.pending);
}

/// Frames to wait for a screenshot with something on it before giving up.
const SCREENSHOT_PATIENCE: u32 = 900;
/// Luminance variance (0..255 scale) below which a screenshot counts as blank: the first
/// frames of a software renderer show only the clear colour while pipelines compile.
pub const BLANK_VARIANCE: f64 = 20.0;

/// The screenshot in progress.
#[derive(Resource, Default)]
struct Shots {
    next: Option<u32>,
    pending: bool,
}

fn finish(
    mut commands: Commands,
    smoke: Res<Smoke>,
    live: Res<LiveInstances>,
    report: Res<SmokeReport>,
    mut shots: ResMut<Shots>,
    mut exit: MessageWriter<AppExit>,
) {
    let Some(last) = smoke.exit_after else {
        return;
    };
    let Some(path) = smoke.screenshot.clone() else {
        if smoke.frame == last {
            println!("rwt-smoke: instances {} instanced {}", live.0, live.1);
            exit.write(AppExit::Success);
        }
        return;
    };
    if smoke.frame >= last && shots.next.is_none() && !shots.pending {
        let waited = smoke.frame - last;
        if !report.hold || waited >= SCREENSHOT_PATIENCE / 2 {
            if report.hold {
                eprintln!("rwt-smoke: the script did not finish in {waited} frames");
            }
            shots.next = Some(smoke.frame);
        }
    }
    if smoke.frame > last + SCREENSHOT_PATIENCE {
        eprintln!(
            "rwt-smoke: no screenshot with content for {}",
            path.display()
        );
        exit.write(AppExit::error());
        return;
    }
    if shots.pending || shots.next != Some(smoke.frame) {
        return;
    }
    shots.pending = true;
    commands.spawn(Screenshot::primary_window()).observe(
        move |captured: On<ScreenshotCaptured>,
              smoke: Res<Smoke>,
              live: Res<LiveInstances>,
              report: Res<SmokeReport>,
              mut shots: ResMut<Shots>,
              real: Res<Time<Real>>,
              mut exit: MessageWriter<AppExit>| {
            shots.pending = false;
            let Ok(image) = captured.image.clone().try_into_dynamic() else {
                eprintln!("rwt-smoke: screenshot not convertible");
                exit.write(AppExit::error());
                return;
            };
            let rgb = image.to_rgb8();
            let variance = luminance_variance(&rgb);
            if variance < BLANK_VARIANCE {
                // Still compiling pipelines: look again a little later.
                eprintln!(
                    "rwt-smoke: frame {} blank (luminance variance {variance:.1}), again in 10",
                    smoke.frame
                );
                shots.next = Some(smoke.frame + 10);
                return;
            }
            println!(
                "rwt-smoke: screenshot taken at frame {}, {:.1} s after start",
                smoke.frame,
                real.elapsed_secs()
            );
            exit.write(save(&path, &rgb, *live, *report));
        },
    );
}

/// Variance of the luminance of every fourth pixel, 0..255 scale.
pub fn luminance_variance(rgb: &image::RgbImage) -> f64 {
    let lum: Vec<f64> = rgb
        .pixels()
        .step_by(4)
        .map(|p| 0.299 * p[0] as f64 + 0.587 * p[1] as f64 + 0.114 * p[2] as f64)
        .collect();
    let mean = lum.iter().sum::<f64>() / lum.len().max(1) as f64;
    lum.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / lum.len().max(1) as f64
}

fn save(
    path: &std::path::Path,
    rgb: &image::RgbImage,
    live: LiveInstances,
    report: SmokeReport,
) -> AppExit {
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        let _ = std::fs::create_dir_all(dir);
    }
    if let Err(e) = rgb.save(path) {
        eprintln!("rwt-smoke: cannot write {}: {e}", path.display());
        return AppExit::error();
    }
    let painted = report
        .painted
        .map_or(String::new(), |p| format!(" painted {p}"));
    println!(
        "rwt-smoke: screenshot {} ({}x{}) instances {} instanced {}{painted}",
        path.display(),
        rgb.width(),
        rgb.height(),
        live.0,
        live.1
    );
    println!(
        "rwt-smoke: pending tasks max {}, at the screenshot {}",
        report.pending_max, report.pending
    );
    AppExit::Success
}
