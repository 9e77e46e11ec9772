//! The GPU benchmark: open_world-like grass rendered headless, no window and no display.
//!
//! `scripts/gpu_bench.sh` runs it (built on any machine, run on one with a GPU), or
//! `cargo run --release --example gpu_bench -- [--blades 1,5,10] [--frames 240] [--size 1920x1080]
//! [--thin 25] [--shadow-distance 0] [--far-blade 0] [--msaa 4] [--tuft 1]
//! [--shadows on|off] [--cull on|off] [--casters read|all] [--forest thinned|impostors]
//! [--latency 2] [--shots DIR] [--detail]`;
//! `--shots` saves one
//! frame of each case there as
//! `blades-M-shadows-S-cull-C.png`; `--detail` prints where each case's frame time goes
//! (`detail`).
//!
//! The scene is [`grass_field`]'s: instanced blades streamed around a camera 2 m above a
//! field, under a sun with cascaded shadow maps, drawn into an image; the grass thins out
//! from `--thin` metres (25 by default, as a game sets it; 0: never), see
//! [`InstancedThinning`]. With shadows on, every blade casts, or with `--shadow-distance`
//! those within that many metres of the camera (open_world's grass casts within 25 m,
//! [`InstancedShadows::Within`]). With `--far-blade`, chunks farther than that many metres
//! draw a blade of 6 vertices instead of 10 ([`grass_field::far_blade`]; 0, the default:
//! none). `--msaa` sets the samples per pixel (1, 2 or 4; Bevy's default 4), to tell the
//! pixels' share of a frame. `--tuft K` draws K blades a mesh ([`tuft`]) at a K-th of the
//! density: as many blades, a K-th of the instances (1, the default: one blade a mesh).
//! `--casters all` draws every blade in a cascade's box into it ([`CascadeCasters::All`];
//! `read`, the default, only those whose shadows fall where the camera reads it).
//! For each blade count
//! (millions of live blades) with the grass's shadows off, then on, each with culling per
//! instance on the GPU off, then on ([`InstanceCulling`]), it waits for streaming to settle,
//! warms up for 2 s, times `--frames` frames and prints exactly one line (`--shadows on|off`
//! and `--cull on|off` time only those cases):
//!
//! `gpu-bench: blades=B shadows=S cull=C fps_median=F frame_ms_p95=P adapter=NAME`
//!
//! `B` is the live count measured (with `--tuft`, instances times K; a first pass measures
//! the streamed area, so the densities meet the counts asked for). A frame is the time from
//! one main-world frame to the next, with Bevy's pipelined rendering on as in a game. Without
//! a window nothing paces the frames, so the render world, once it has submitted a frame,
//! waits for the GPU to finish the frame `--latency` frames before it: 2 by default, as a
//! window's swapchain allows in Bevy (`Window::desired_maximum_frame_latency`), so the CPU's
//! work on a frame overlaps the GPU's on the one before and the time is that of the slowest
//! of the main world, the render world and the GPU. With `--latency 0` each frame waits for
//! its own drawing: the time is that of the slower of the main world and the render world
//! plus the GPU.
//! `cull=off` culls whole chunks on the CPU and draws every blade of those kept; `cull=on`
//! also culls each blade on the GPU and draws indirectly.
//!
//! `--forest` adds open_world's forests around the field to 2.6 km ([`FarTrees`]: `thinned`,
//! every tree a mesh entity and a fifth of them kept from 1.4 km on; `impostors`, every tree,
//! impostors from 350 m) and prints `gpu-bench: forest=F tree_entities=E impostors=I` after
//! each case line.

use bevy::app::ScheduleRunnerPlugin;
use bevy::camera::RenderTarget;
use bevy::diagnostic::DiagnosticsStore;
use bevy::log::{Level, LogPlugin};
use bevy::prelude::*;
use bevy::render::render_resource::{PollType, TextureFormat};
use bevy::render::renderer::{RenderAdapterInfo, RenderDevice, RenderQueue};
use bevy::render::view::screenshot::{Screenshot, save_to_disk};
use bevy::render::{Render, RenderApp, RenderSystems};
use bevy::window::ExitCondition;
use bevy::winit::WinitPlugin;
use bevy_rwt::prelude::*;
use rwt_examples::forest::{FarTrees, tree_layer};
use rwt_examples::grass_field::{self, field_layer, set_instanced_shadows};
use rwt_examples::tuft::tuft;
use std::time::{Duration, Instant};

mod detail;

/// Distance from which the grass thins out by default ([`InstancedThinning`]), metres.
const THIN_FROM: f32 = 25.0;
/// Density of the pass that measures the streamed area, blades a square metre.
const CALIBRATION_DENSITY: f64 = 1.0;
/// Frames with an unchanged live count and nothing in flight before streaming counts as
/// settled.
const SETTLED_FRAMES: u32 = 10;
/// Warm-up before timing (pipelines compile in the background).
const WARM_UP: Duration = Duration::from_secs(2);
/// Longest a case is timed, whatever `--frames` asks.
const LONGEST_TIMING: Duration = Duration::from_secs(15);
/// Frames a window's swapchain lets the GPU fall behind in Bevy (its default
/// `Window::desired_maximum_frame_latency`).
const WINDOW_LATENCY: usize = 2;
/// Longest streaming may take to settle before the bench gives up.
const LONGEST_STREAMING: Duration = Duration::from_secs(180);

fn main() {
    let options = match Options::parse(std::env::args().skip(1)) {
        Ok(options) => options,
        Err(message) => {
            eprintln!("gpu_bench: {message}");
            eprintln!(
                "usage: gpu_bench [--blades M,M,..] [--frames N] [--size WIDTHxHEIGHT] [--shots DIR] [--detail] [--thin METRES] [--shadow-distance METRES] [--far-blade METRES] [--msaa 1|2|4] [--tuft K] [--shadows on|off] [--cull on|off] [--casters read|all] [--forest thinned|impostors] [--latency 0..3] (M: millions)"
            );
            std::process::exit(2);
        }
    };
    if let Some(dir) = &options.shots
        && let Err(error) = std::fs::create_dir_all(dir)
    {
        eprintln!("gpu_bench: cannot make {}: {error}", dir.display());
        std::process::exit(1);
    }
    let detailed = options.detail;
    let latency = options.latency;
    let mut app = App::new();
    app.add_plugins((
        DefaultPlugins
            .set(WindowPlugin {
                primary_window: None,
                exit_condition: ExitCondition::DontExit,
                ..default()
            })
            .set(LogPlugin {
                level: Level::WARN,
                ..default()
            })
            .disable::<WinitPlugin>(),
        ScheduleRunnerPlugin::run_loop(Duration::ZERO),
        RwtPlugins::default()
            .with_upload_budget(4_000_000)
            .with_despawn_budget(1_000_000)
            .with_max_tasks(32),
    ))
    .insert_resource(options.casters)
    .insert_resource(Bench::new(options))
    .insert_resource(InstanceCulling::PerChunk)
    .add_systems(Startup, setup)
    .add_systems(First, tick)
    .add_systems(Last, step);
    app.sub_app_mut(RenderApp)
        .insert_resource(InFlight::new(latency))
        .add_systems(
            Render,
            wait_for_gpu.in_set(GpuWait).after(RenderSystems::Render),
        );
    if detailed {
        detail::add(&mut app, GpuWait);
    }
    app.run();
}

/// What the command line asks.
struct Options {
    /// Live blades of each case, millions.
    blades: Vec<f64>,
    /// Frames timed per case.
    frames: usize,
    /// The image's size, pixels.
    size: UVec2,
    /// Where to save a frame of each case.
    shots: Option<std::path::PathBuf>,
    /// Whether to print where each case's frame time goes.
    detail: bool,
    /// Distance from which the grass thins out (metres; 0: it does not).
    thin: f32,
    /// Distance from the camera within which blades cast shadows (metres; 0: all do).
    shadow_distance: f32,
    /// Distance from which chunks draw the far blade (metres; 0: none do).
    far_blade: f32,
    /// Samples per pixel.
    msaa: Msaa,
    /// Blades a mesh, drawn once per instance.
    tuft: u32,
    /// Forests around the field, and how far trees are drawn.
    forest: Option<FarTrees>,
    /// The only shadows and culling timed (`None`: off, then on).
    shadows: Option<bool>,
    cull: Option<bool>,
    /// Which blades the shadow cascades draw.
    casters: CascadeCasters,
    /// Frames the GPU may be behind the render world.
    latency: usize,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            blades: vec![1.0, 5.0, 10.0],
            frames: 240,
            size: UVec2::new(1920, 1080),
            shots: None,
            detail: false,
            thin: THIN_FROM,
            shadow_distance: 0.0,
            far_blade: 0.0,
            msaa: Msaa::Sample4,
            tuft: 1,
            forest: None,
            shadows: None,
            cull: None,
            casters: CascadeCasters::WhereRead,
            latency: WINDOW_LATENCY,
        }
    }
}

impl Options {
    fn parse(mut args: impl Iterator<Item = String>) -> Result<Self, String> {
        let mut options = Options::default();
        while let Some(flag) = args.next() {
            if flag == "--detail" {
                options.detail = true;
                continue;
            }
            let value = args.next().ok_or(format!("{flag} needs a value"))?;
            let bad = || format!("{flag} {value:?} is not valid");
            match flag.as_str() {
                "--blades" => {
                    options.blades = value
                        .split(',')
                        .map(|m| {
                            m.trim()
                                .parse::<f64>()
                                .ok()
                                .filter(|m| *m > 0.0 && *m <= 100.0)
                        })
                        .collect::<Option<_>>()
                        .ok_or_else(bad)?;
                }
                "--frames" => options.frames = within(&value, 10..=10_000).ok_or_else(bad)?,
                "--size" => {
                    let (w, h) = value.split_once('x').ok_or_else(bad)?;
                    let side = |v: &str| within(v, 64..=8192u32);
                    options.size = UVec2::new(side(w).ok_or_else(bad)?, side(h).ok_or_else(bad)?);
                }
                "--shots" => options.shots = Some(value.into()),
                "--thin" | "--shadow-distance" | "--far-blade" => {
                    let metres = within(&value, 0.0..=1e4f32).ok_or_else(bad)?;
                    match flag.as_str() {
                        "--thin" => options.thin = metres,
                        "--shadow-distance" => options.shadow_distance = metres,
                        _ => options.far_blade = metres,
                    }
                }
                "--msaa" => {
                    options.msaa = match value.as_str() {
                        "1" => Msaa::Off,
                        "2" => Msaa::Sample2,
                        "4" => Msaa::Sample4,
                        _ => return Err(bad()),
                    };
                }
                "--tuft" => options.tuft = within(&value, 1..=64).ok_or_else(bad)?,
                "--latency" => options.latency = within(&value, 0..=3).ok_or_else(bad)?,
                "--casters" => {
                    options.casters = match value.as_str() {
                        "read" => CascadeCasters::WhereRead,
                        "all" => CascadeCasters::All,
                        _ => return Err(bad()),
                    };
                }
                "--shadows" | "--cull" => {
                    let on = match value.as_str() {
                        "on" => true,
                        "off" => false,
                        _ => return Err(bad()),
                    };
                    match flag.as_str() {
                        "--shadows" => options.shadows = Some(on),
                        _ => options.cull = Some(on),
                    }
                }
                "--forest" => {
                    options.forest = Some(match value.as_str() {
                        "thinned" => FarTrees::Thinned,
                        "impostors" => FarTrees::Impostors,
                        _ => return Err(bad()),
                    });
                }
                _ => return Err(format!("unknown option {flag:?}")),
            }
        }
        Ok(options)
    }
}

/// `value` as a number in `range`.
fn within<T: std::str::FromStr + PartialOrd>(
    value: &str,
    range: std::ops::RangeInclusive<T>,
) -> Option<T> {
    value.parse().ok().filter(|v| range.contains(v))
}

/// One timed case.
#[derive(Clone, Copy, PartialEq)]
struct Case {
    /// Live blades asked for.
    blades: f64,
    shadows: bool,
    /// Culling per instance on the GPU.
    cull: bool,
}

/// The image the camera draws into.
#[derive(Resource)]
struct Target(Handle<Image>);

/// Where the bench stands.
enum Phase {
    /// Waiting for the layer to stream in.
    Streaming {
        since: Instant,
        stable: u32,
        live: usize,
    },
    /// Warming up; a frame is saved half-way (with `--shots`).
    WarmingUp {
        since: Instant,
        shot: bool,
    },
    Timing {
        since: Instant,
    },
}

#[derive(Resource)]
struct Bench {
    options: Options,
    cases: Vec<Case>,
    /// The case streaming, warming up or timed; `None` while the area is measured.
    case: Option<usize>,
    /// Streamed area, square metres, once measured.
    area: Option<f64>,
    phase: Phase,
    /// Start of the last main-world frame.
    last_frame: Option<Instant>,
    /// Times of the frames timed so far in this case, ms.
    frame_ms: Vec<f64>,
}

impl Bench {
    fn new(options: Options) -> Self {
        let cases = options
            .blades
            .iter()
            .flat_map(|&m| {
                [(false, false), (false, true), (true, false), (true, true)].map(
                    |(shadows, cull)| Case {
                        blades: m * 1e6,
                        shadows,
                        cull,
                    },
                )
            })
            .filter(|c| options.shadows.is_none_or(|s| s == c.shadows))
            .filter(|c| options.cull.is_none_or(|on| on == c.cull))
            .collect();
        Self {
            options,
            cases,
            case: None,
            area: None,
            phase: Phase::Streaming {
                since: Instant::now(),
                stable: 0,
                live: 0,
            },
            last_frame: None,
            frame_ms: Vec::new(),
        }
    }

    /// The layer's density and shadows now: the calibration pass's, or the case's.
    fn density_and_shadows(&self) -> (f64, InstancedShadows) {
        match (self.case, self.area) {
            (Some(i), Some(area)) => {
                let case = self.cases[i];
                let within = self.options.shadow_distance;
                let shadows = match (case.shadows, within > 0.0) {
                    (false, _) => InstancedShadows::Off,
                    (true, false) => InstancedShadows::On,
                    (true, true) => InstancedShadows::Within(within),
                };
                (case.blades / area / f64::from(self.options.tuft), shadows)
            }
            _ => (CALIBRATION_DENSITY, InstancedShadows::Off),
        }
    }
}

fn setup(
    mut commands: Commands,
    bench: Res<Bench>,
    mut images: ResMut<Assets<Image>>,
    mut meshes: ResMut<Assets<Mesh>>,
    mut materials: ResMut<Assets<StandardMaterial>>,
) {
    let size = bench.options.size;
    let target = Image::new_target_texture(size.x, size.y, TextureFormat::Rgba8UnormSrgb, None);
    let target = images.add(target);
    commands.insert_resource(Target(target.clone()));
    commands.spawn((
        Camera3d::default(),
        bench.options.msaa,
        RenderTarget::Image(target.into()),
        RwtViewer::all_around(),
        grass_field::camera_transform(),
    ));
    grass_field::spawn_sun_and_ground(&mut commands, &mut meshes, &mut materials);
    let (density, shadows) = bench.density_and_shadows();
    let material = InstancedShading {
        shadows,
        thinning: (bench.options.thin > 0.0).then(|| InstancedThinning::from(bench.options.thin)),
        ..default()
    };
    let tufted = |blade: Mesh| match bench.options.tuft {
        1 => blade,
        k => tuft(&blade, k),
    };
    let blade = meshes.add(tufted(grass_field::blade()));
    let mut grass = ScatterClass::instanced(LayerDensity::Constant(density), blade, material);
    if bench.options.far_blade > 0.0 {
        let far = meshes.add(tufted(grass_field::far_blade()));
        grass = grass.with_instanced_far(far, bench.options.far_blade);
    }
    commands.spawn((Grass, field_layer(grass)));
    if let Some(far) = bench.options.forest {
        let material = materials.add(StandardMaterial {
            perceptual_roughness: 0.9,
            reflectance: 0.2,
            ..default()
        });
        let flat = HeightSource::Constant(0.0);
        commands.spawn((Forest, tree_layer(&flat, &mut meshes, &material, far)));
    }
}

/// The grass's layer, whose blades the cases count.
#[derive(Component)]
struct Grass;

/// The forests' layer (`--forest`).
#[derive(Component)]
struct Forest;

/// Times the frame that just ended, while a case is timed.
fn tick(mut bench: ResMut<Bench>) {
    let now = Instant::now();
    if let (Phase::Timing { .. }, Some(last)) = (&bench.phase, bench.last_frame) {
        bench.frame_ms.push((now - last).as_secs_f64() * 1e3);
    }
    bench.last_frame = Some(now);
}

/// Moves the bench on: streaming settles, the frame warms up, a case is timed and printed,
/// the next case streams in; after the last, the app exits.
#[allow(clippy::too_many_arguments)]
fn step(
    mut bench: ResMut<Bench>,
    stats: Res<RwtStats>,
    mut layers: Query<&mut ScatterLayer, With<Grass>>,
    grass: Single<&ScatterLayerStatus, With<Grass>>,
    forest: Option<Single<&ScatterLayerStatus, With<Forest>>>,
    mut culling: ResMut<InstanceCulling>,
    report: Report,
    mut commands: Commands,
    mut exit: MessageWriter<AppExit>,
) {
    let now = Instant::now();
    if let Some(case) = bench.case.map(|i| bench.cases[i]) {
        culling.set_if_neq(if case.cull {
            InstanceCulling::PerInstance
        } else {
            InstanceCulling::PerChunk
        });
    }
    let frames = bench.options.frames;
    // Blades: each instance draws a tuft's.
    let live = grass.live_instanced * bench.options.tuft as usize;
    match bench.phase {
        Phase::Streaming {
            since,
            stable,
            live: streamed,
        } => {
            let settled_now =
                stats.settled() && grass.live_instanced > 0 && grass.live_instanced == streamed;
            let stable = if settled_now { stable + 1 } else { 0 };
            bench.phase = Phase::Streaming {
                since,
                stable,
                live: grass.live_instanced,
            };
            if stable >= SETTLED_FRAMES {
                settled(&mut bench, grass.live_instanced, &mut layers);
            } else if since.elapsed() > LONGEST_STREAMING {
                eprintln!("gpu_bench: streaming did not settle in {LONGEST_STREAMING:?}");
                exit.write(AppExit::error());
            }
        }
        Phase::WarmingUp { since, .. } if since.elapsed() >= WARM_UP => {
            bench.frame_ms.clear();
            bench.phase = Phase::Timing { since: now };
        }
        Phase::WarmingUp { since, shot: false } if since.elapsed() >= WARM_UP / 2 => {
            bench.phase = Phase::WarmingUp { since, shot: true };
            save_shot(&bench, &report, &mut commands);
        }
        Phase::Timing { since }
            if bench.frame_ms.len() >= frames
                || (since.elapsed() >= LONGEST_TIMING && bench.frame_ms.len() >= 10) =>
        {
            print_case(&bench, live, &report);
            if let (Some(far), Some(forest)) = (bench.options.forest, &forest) {
                print_forest(far, forest);
            }
            let (this, next) = bench.case.map_or((0, 0), |i| (i, i + 1));
            let Some(&case) = bench.cases.get(next) else {
                exit.write(AppExit::Success);
                return;
            };
            let same_field = |a: Case, b: Case| a.blades == b.blades && a.shadows == b.shadows;
            bench.case = Some(next);
            if same_field(bench.cases[this], case) {
                bench.phase = Phase::WarmingUp {
                    since: now,
                    shot: false,
                };
            } else {
                restream(&mut bench, &mut layers);
            }
        }
        _ => {}
    }
}

/// Saves a frame of the case warming up (with `--shots`).
fn save_shot(bench: &Bench, report: &Report, commands: &mut Commands) {
    let (Some(dir), Some(case)) = (&bench.options.shots, bench.case) else {
        return;
    };
    let case = bench.cases[case];
    let name = format!(
        "blades-{}-shadows-{}-cull-{}.png",
        case.blades / 1e6,
        on_off(case.shadows),
        on_off(case.cull)
    );
    commands
        .spawn(Screenshot::image(report.target.0.clone()))
        .observe(save_to_disk(dir.join(name)));
}

/// A setting as the case lines and shots name it.
fn on_off(on: bool) -> &'static str {
    if on { "on" } else { "off" }
}

/// The forests' line after a case's (`--forest`).
fn print_forest(far: FarTrees, forest: &ScatterLayerStatus) {
    let far = match far {
        FarTrees::Thinned => "thinned",
        FarTrees::Impostors => "impostors",
    };
    println!(
        "gpu-bench: forest={far} tree_entities={} impostors={}",
        forest.live_entities, forest.live_instanced
    );
}

/// Streaming has settled with `live` blades: measure the area (the first time), or warm up.
fn settled(bench: &mut Bench, live: usize, layers: &mut Query<&mut ScatterLayer, With<Grass>>) {
    if bench.area.is_none() {
        bench.area = Some(live as f64 / CALIBRATION_DENSITY);
        bench.case = Some(0);
        restream(bench, layers);
    } else {
        bench.phase = Phase::WarmingUp {
            since: Instant::now(),
            shot: false,
        };
    }
}

/// Gives the layer the density and shadows of the bench's case (it streams anew).
fn restream(bench: &mut Bench, layers: &mut Query<&mut ScatterLayer, With<Grass>>) {
    let (density, shadows) = bench.density_and_shadows();
    for mut layer in layers {
        set_instanced_shadows(&mut layer, shadows);
        for class in &mut layer.classes {
            class.density = LayerDensity::Constant(density);
        }
    }
    bench.phase = Phase::Streaming {
        since: Instant::now(),
        stable: 0,
        live: 0,
    };
}

/// What the case lines read beside the bench: the adapter, the image (for `--shots`) and,
/// with `--detail`, the frame's split and the render diagnostics.
#[derive(bevy::ecs::system::SystemParam)]
struct Report<'w> {
    adapter: Res<'w, RenderAdapterInfo>,
    target: Res<'w, Target>,
    split: Option<Res<'w, detail::Split>>,
    store: Option<Res<'w, DiagnosticsStore>>,
}

fn print_case(bench: &Bench, live: usize, report: &Report) {
    let Some(case) = bench.case.map(|i| bench.cases[i]) else {
        return;
    };
    let mut ms = bench.frame_ms.clone();
    ms.sort_by(f64::total_cmp);
    let median = ms[ms.len() / 2];
    let p95 = ms[(ms.len() * 95 / 100).min(ms.len() - 1)];
    let (shadows, cull) = (on_off(case.shadows), on_off(case.cull));
    println!(
        "gpu-bench: blades={live} shadows={shadows} cull={cull} fps_median={:.1} frame_ms_p95={p95:.2} adapter={}",
        1e3 / median,
        report.adapter.name
    );
    if let (Some(split), Some(store)) = (&report.split, &report.store) {
        let case = format!("blades={live} shadows={shadows} cull={cull}");
        println!("{}", detail::line(&case, ms.len(), split, store));
    }
}

/// The render world's wait for the GPU.
#[derive(SystemSet, Clone, Debug, PartialEq, Eq, Hash)]
struct GpuWait;

/// The frames submitted that the GPU may still be drawing, oldest first, each as the wait
/// for its work.
#[derive(Resource)]
struct InFlight {
    latency: usize,
    frames: std::collections::VecDeque<PollType>,
}

impl InFlight {
    fn new(latency: usize) -> Self {
        Self {
            latency,
            frames: std::collections::VecDeque::with_capacity(latency + 1),
        }
    }
}

/// Waits for the GPU to finish the frame `latency` frames before the one just submitted, so
/// that frames are paced by the GPU as a window's swapchain paces them (without a window
/// nothing else does), and a frame's time includes its drawing.
fn wait_for_gpu(
    device: Res<RenderDevice>,
    queue: Res<RenderQueue>,
    mut in_flight: ResMut<InFlight>,
) {
    // An empty submission's index is that of all work submitted so far: this frame's.
    let submitted = queue.submit(std::iter::empty());
    in_flight.frames.push_back(PollType::Wait {
        submission_index: Some(submitted),
        timeout: None,
    });
    while in_flight.frames.len() > in_flight.latency {
        let Some(wait) = in_flight.frames.pop_front() else {
            break;
        };
        if let Err(error) = device.poll(wait) {
            error!("gpu_bench: waiting for the GPU failed: {error}");
        }
    }
}
