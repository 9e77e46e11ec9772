//! Headless fly-through over a forest of a two-primitive glTF tree (bark and masked leaves,
//! two levels of detail) drawn by the instanced path and as entities:
//! `cargo bench -p bevy_rwt --bench assets`. Each run fills the world around the start, then
//! flies 300 frames and prints one line, on stdout, in exactly this form:
//!
//! `assets: instances=N primitives=2 path=instanced frame_ms=X max_ms=M`
//! `assets: instances=N primitives=2 path=entities frame_ms=Y max_ms=M`
//!
//! then `assets: ratio instanced/entities instances=N frame_ms=R` where both paths ran.
//! A frame is the whole `app.update()` of the main world (planning, collecting finished
//! generation tasks, handing buffers over or spawning and despawning entities; no renderer),
//! paced at 60 per second as in a game; `frame_ms` is the median, `max_ms` the slowest.
//! Stderr adds the 99th percentile and how many frames took over twice the median: on a
//! machine of two cores a generation task running beside the frame preempts its systems
//! for a scheduler's time slice (about 1 ms), in whichever phase they are, so the slowest
//! frame there says more about the scheduler than about the frame's own work.
//! The entity path is the asset class with every instance promoted: an entity per tree with
//! a child per primitive of each level, as a game spawning the file's scene per tree gets.
//! It runs at 100 000 only: at 1 000 000 it would hold 5 million entities (a tree and four
//! children), more than this bench's machine keeps up with (stderr says so).

use bevy::gltf::GltfPlugin;
use bevy::prelude::*;
use bevy_rwt::look::asset::AssetLook;
use bevy_rwt::prelude::*;
use bevy_rwt::testing::glb::{Glb, GlbAlpha, GlbMaterial, GlbNode, GlbPrimitive};
use bevy_rwt::testing::{move_viewer, spawn_viewer};
use std::time::{Duration, Instant};

/// Streaming radius, world units.
const RADIUS: f64 = 400.0;
/// Chunk side, world units.
const CHUNK: f64 = 64.0;
/// Frames of flight per run.
const FRAMES: usize = 300;
/// Flight speed, world units per frame.
const SPEED: f32 = 2.0;
/// Frames are paced at 60 per second.
const FRAME: Duration = Duration::from_nanos(16_666_667);

/// How the trees are drawn.
#[derive(Clone, Copy, PartialEq, Debug)]
enum Path {
    Instanced,
    Entities,
}

impl Path {
    fn name(self) -> &'static str {
        match self {
            Path::Instanced => "instanced",
            Path::Entities => "entities",
        }
    }
}

fn main() {
    let dir = std::env::temp_dir().join(format!("rwt_bench_assets_{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("a temporary folder");
    std::fs::write(dir.join("tree.glb"), tree().to_bytes()).expect("the tree is written");
    let mut instanced = Vec::new();
    for live in [1.0e5, 1.0e6] {
        instanced.push(run(&dir, Path::Instanced, live));
    }
    let entities = run(&dir, Path::Entities, 1.0e5);
    eprintln!("the entity path is not run at 1 000 000 (5 million entities): 100 000 only");
    println!(
        "assets: ratio instanced/entities instances=100000 frame_ms={:.3}",
        instanced[0] / entities
    );
    std::fs::remove_dir_all(&dir).ok();
}

/// A tree: a trunk and a crown of masked leaves near, a box and a card far.
fn tree() -> Glb {
    let mut file = Glb::default();
    let bark = file.add_material(GlbMaterial::colored([0.3, 0.2, 0.1, 1.0]));
    let leaves = file.add_material(GlbMaterial {
        alpha: GlbAlpha::Mask(0.5),
        double_sided: true,
        ..GlbMaterial::colored([0.2, 0.5, 0.1, 1.0])
    });
    let primitive = |shape: Mesh, material| GlbPrimitive::from_mesh(&shape, material).unwrap();
    let up = |mesh: Mesh, y: f32| mesh.translated_by(Vec3::Y * y);
    let near = file.add_mesh(vec![
        primitive(up(Cylinder::new(0.3, 4.0).mesh().build(), 2.0), bark),
        primitive(up(Sphere::new(1.8).mesh().ico(2).unwrap(), 5.0), leaves),
    ]);
    let far = file.add_mesh(vec![
        primitive(up(Cuboid::new(0.5, 4.0, 0.5).mesh().build(), 2.0), bark),
        primitive(up(Cuboid::new(3.0, 3.0, 0.1).mesh().build(), 5.0), leaves),
    ]);
    let lod0 = file.add_node(GlbNode::named("tree_LOD0").with_mesh(near));
    let lod1 = file.add_node(GlbNode::named("tree_LOD1").with_mesh(far));
    let root = file.add_node(GlbNode::named("tree").with_children([lod0, lod1]));
    file.add_root(root);
    file
}

/// Fills and flies a forest of about `live` trees; prints its line and returns its median
/// frame time.
fn run(dir: &std::path::Path, path: Path, live: f64) -> f64 {
    let density = live / (std::f64::consts::PI * (RADIUS + CHUNK).powi(2));
    let (mut app, viewer) = world(dir, path, density);
    let filled = fill(&mut app, path);
    let times = fly(&mut app, viewer);
    let f = Figures::of(times);
    println!(
        "assets: instances={filled} primitives=2 path={} frame_ms={:.3} max_ms={:.3}",
        path.name(),
        f.median,
        f.max
    );
    eprintln!(
        "{} {filled}: slowest/median {:.1}, 99th percentile {:.3} ms, {} of {FRAMES} frames \
         over twice the median",
        path.name(),
        f.max / f.median,
        f.p99,
        f.over_twice
    );
    f.median
}

/// A headless app reading `dir`, with Bevy's glTF loader and one forest layer of `density`
/// trees per square unit; returns it and its viewer.
fn world(dir: &std::path::Path, path: Path, density: f64) -> (App, Entity) {
    let mut app = App::new();
    app.add_plugins((
        MinimalPlugins,
        AssetPlugin {
            file_path: dir.to_string_lossy().into_owned(),
            ..default()
        },
        RwtPlugins::default()
            .with_max_tasks(32)
            .with_spawn_budget(20_000)
            .with_despawn_budget(40_000),
        GltfPlugin::default(),
    ))
    .init_asset::<Mesh>()
    .init_asset::<StandardMaterial>()
    .init_asset::<Image>()
    .init_asset::<bevy::world_serialization::WorldAsset>();
    app.finish();
    app.cleanup();
    let viewer = spawn_viewer(&mut app, Vec3::ZERO);
    let look = AssetLook::new(app.world().resource::<AssetServer>().load("tree.glb"));
    let mut class = ScatterClass::asset(LayerDensity::Constant(density), look);
    if path == Path::Entities {
        // Every tree an entity, with a child per primitive of each level.
        class = class.with_promotion(f32::MAX, |_| {});
    }
    let streaming = StreamingConfig {
        chunk_size: CHUNK,
        load_distance: RADIUS,
        unload_distance: RADIUS + 48.0,
        near_distance: 96.0,
    };
    app.world_mut().spawn(
        ScatterLayer::new(vec![class])
            .with_tile_size(16.0)
            .with_streaming(streaming),
    );
    (app, viewer)
}

/// Trees streamed (in chunk buffers, promoted or not).
fn live(app: &App) -> usize {
    app.world().resource::<RwtStats>().live_instanced
}

/// Trees that are entities.
fn promoted(app: &mut App) -> usize {
    let mut q = app
        .world_mut()
        .query_filtered::<(), With<bevy_rwt::instancing::PromotedInstance>>();
    q.iter(app.world()).count()
}

/// Runs frames until the world around the start is filled (on the entity path, every tree
/// an entity); returns the trees streamed.
fn fill(app: &mut App, path: Path) -> usize {
    let started = Instant::now();
    let mut frames = 0;
    loop {
        app.update();
        frames += 1;
        let s = app.world().resource::<RwtStats>();
        let settled = s.settled() && live(app) > 0;
        if settled && (path == Path::Instanced || promoted(app) >= live(app)) {
            break;
        }
        assert!(frames < 200_000, "the forest did not fill");
    }
    eprintln!(
        "{}: filled {} trees ({} entities) in {frames} frames, {:.2} s",
        path.name(),
        live(app),
        promoted(app),
        started.elapsed().as_secs_f64()
    );
    live(app)
}

/// Flies the viewer for [`FRAMES`] frames; returns the frame times (ms).
fn fly(app: &mut App, viewer: Entity) -> Vec<f64> {
    let mut times = Vec::with_capacity(FRAMES);
    let start = Instant::now();
    for f in 0..FRAMES {
        let x = f as f32 * SPEED;
        move_viewer(app, viewer, Vec3::new(x, 2.0, (x * 0.01).sin() * 100.0));
        let t = Instant::now();
        app.update();
        times.push(t.elapsed().as_secs_f64() * 1e3);
        let next = start + FRAME * (f as u32 + 1);
        std::thread::sleep(next.saturating_duration_since(Instant::now()));
    }
    times
}

/// What a run's frame times say.
struct Figures {
    median: f64,
    max: f64,
    p99: f64,
    /// Frames slower than twice the median.
    over_twice: usize,
}

impl Figures {
    fn of(mut times: Vec<f64>) -> Self {
        times.sort_by(f64::total_cmp);
        let n = times.len();
        let median = times[n / 2];
        Self {
            median,
            max: times[n - 1],
            p99: times[(n * 99 / 100).min(n - 1)],
            over_twice: times.iter().filter(|t| **t > 2.0 * median).count(),
        }
    }
}
