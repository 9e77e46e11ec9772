//! The page's report: once streaming has settled (no generation task pending, the live
//! instances unchanged for [`STEADY`] frames), [`TIMED`] frames (or as many as the page
//! asks) are timed and one line goes to the console,
//! `rwt-web: backend=B instances=N frames=F frame_ms=T`, then a second,
//! `rwt-web: culling=C slowest_ms=S`: per instance on the GPU, or per chunk where the
//! adapter has no compute shaders (WebGL2).

use bevy::prelude::*;
use bevy::render::renderer::{RenderAdapter, RenderAdapterInfo, RenderDevice};
use bevy_rwt::RwtStats;
use bevy_rwt::instancing::gpu_culling_supported;

/// Frames the live instances stay unchanged, with no task pending, to count as settled.
const STEADY: u32 = 30;
/// Frames timed once settled, unless the page asks for another number.
pub const TIMED: usize = 120;
/// Frames after which the report is written even if streaming never settled (it then says
/// so, as an error the browser test fails on).
const GIVE_UP: u32 = 3000;
/// Seconds between the progress lines written while streaming settles.
const PROGRESS_S: f32 = 10.0;

/// Writes the report after timing `frames` frames.
pub struct ReportPlugin {
    pub frames: usize,
}

impl Plugin for ReportPlugin {
    fn build(&self, app: &mut App) {
        app.insert_resource(Report {
            frames: self.frames,
            ..default()
        })
        .add_systems(Last, report);
    }
}

#[derive(Resource, Default)]
struct Report {
    frames: usize,
    frame: u32,
    steady: u32,
    instances: usize,
    timed: Vec<f32>,
    done: bool,
    next_progress: f32,
}

impl Report {
    /// Counts a frame with `instances` live and `pending` tasks; whether it is settled.
    fn settle(&mut self, instances: usize, pending: usize) -> bool {
        self.frame += 1;
        let unchanged = instances == self.instances && instances > 0 && pending == 0;
        self.steady = if unchanged { self.steady + 1 } else { 0 };
        self.instances = instances;
        self.steady >= STEADY || self.frame >= GIVE_UP
    }
}

fn report(
    // Wall-clock time: the game's clock clamps a frame to 250 ms.
    real: Res<Time<Real>>,
    stats: Res<RwtStats>,
    info: Option<Res<RenderAdapterInfo>>,
    device: Option<Res<RenderDevice>>,
    adapter: Option<Res<RenderAdapter>>,
    mut state: ResMut<Report>,
) {
    if state.done {
        return;
    }
    let instances = stats.live_instanced + stats.live_entities;
    if state.timed.is_empty() && !state.settle(instances, stats.pending_tasks) {
        if real.elapsed_secs() >= state.next_progress {
            state.next_progress = real.elapsed_secs() + PROGRESS_S;
            info!(
                "rwt-web: streaming: frame {} instances {instances} tasks {} frame_ms {:.0}",
                state.frame,
                stats.pending_tasks,
                real.delta_secs() * 1000.0
            );
        }
        return;
    }
    state.timed.push(real.delta_secs() * 1000.0);
    if state.timed.len() <= state.frames {
        return;
    }
    state.done = true;
    let timed = &state.timed[1..];
    let mean = timed.iter().sum::<f32>() / timed.len() as f32;
    let slowest = timed.iter().copied().fold(0.0, f32::max);
    let backend = info.map_or("none", |i| backend_name(i.backend.to_str()));
    let culls = match (device, adapter) {
        (Some(d), Some(a)) => gpu_culling_supported(&d, &a),
        _ => false,
    };
    let culling = if culls { "per-instance" } else { "per-chunk" };
    print(&format!(
        "rwt-web: backend={backend} instances={instances} frames={} frame_ms={mean:.1}",
        timed.len()
    ));
    print(&format!(
        "rwt-web: culling={culling} slowest_ms={slowest:.1}"
    ));
    if state.frame >= GIVE_UP {
        error!("rwt-web: streaming did not settle in {GIVE_UP} frames");
    }
}

/// The backend as a page names it: wgpu's GL backend in a browser is WebGL2.
fn backend_name(wgpu: &'static str) -> &'static str {
    match wgpu {
        "gl" if cfg!(target_arch = "wasm32") => "webgl2",
        other => other,
    }
}

/// One line to the browser's console as it is (no level or module prefix), or to stdout.
fn print(line: &str) {
    #[cfg(target_arch = "wasm32")]
    web_sys::console::log_1(&line.into());
    #[cfg(not(target_arch = "wasm32"))]
    println!("{line}");
}
