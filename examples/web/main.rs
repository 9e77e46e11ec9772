//! open_world's world in a browser: grass, flowers, ferns, bushes, rocks and forests from
//! the asset pack, streamed by `bevy_rwt` around a fly camera, with the density brush.
//!
//! `scripts/web.sh` builds it for WebGL2 and for WebGPU into `target/web` (serve that folder
//! and open `index.html`; `?backend=webgl2` or `?backend=webgpu` chooses, else WebGPU where
//! the browser has it). On WebGL2 each kept chunk is drawn whole, directly (no compute
//! shaders); on WebGPU a compute pass culls each instance. The page's console gets one line
//! once streaming has settled and 120 frames were timed:
//! `rwt-web: backend=B instances=N frames=F frame_ms=T` (`scripts/web_test.sh` reads it).
//!
//! `?detail=D` (0 < D <= 1) grows that share of the vegetation, in the same places: for weak
//! devices and the browser test (SwiftShader pays for every instance drawn). `?frames=F`
//! times F frames instead of 120 (for pictures on slow renderers).
//!
//! It also runs natively: `cargo run --release --example web`.
//! - WASD / arrows fly, Q / E down and up, Shift boosts, hold the right mouse button to
//!   look, the wheel sets the speed;
//! - B toggles the brush: left mouse paints, right erases, 1-4 choose the map (saving, F5,
//!   is a typed error on the web: a page has no files).

mod report;

use bevy::asset::AssetMetaCheck;
use bevy::prelude::*;
use bevy_rwt::brush::DensityBrush;
use bevy_rwt::prelude::*;
use rwt_examples::prelude::*;
use rwt_examples::terrain::Terrain;
use rwt_examples::world::layers::Detail;
use rwt_examples::world::{WorldScenePlugin, forest_edge_camera, layers};

fn main() {
    // The browser's page is served the pack that `scripts/web.sh` writes natively.
    #[cfg(not(target_arch = "wasm32"))]
    rwt_examples::pack::write_pack();
    let window = Window {
        title: "rwt in the browser".into(),
        canvas: Some("#rwt".into()),
        fit_canvas_to_parent: true,
        // Keys and the wheel fly the camera, not the page.
        prevent_default_event_handling: true,
        ..default()
    };
    let plugins = DefaultPlugins
        .set(WindowPlugin {
            primary_window: Some(window),
            ..default()
        })
        // A static site has no `.meta` files: asking for them logs a 404 per asset.
        .set(AssetPlugin {
            meta_check: AssetMetaCheck::Never,
            ..default()
        });
    App::new()
        .insert_resource(detail())
        .add_plugins((plugins, WorldScenePlugin, FlyCameraPlugin))
        .add_plugins((
            RwtPlugins::default()
                .with_max_tasks(32)
                .build()
                .enable::<RwtBrushPlugin>(),
            report(),
        ))
        .add_systems(Startup, (setup_camera, layers::setup_layers))
        .add_systems(Update, share_mouse)
        .run();
}

/// The camera: in a meadow, looking over grass and flowers at a forest's edge.
fn setup_camera(mut commands: Commands, terrain: Res<Terrain>) {
    commands.spawn(forest_edge_camera(&terrain, Vec2::new(-443.0, -1433.0)));
}

/// The page's setting `?key=value` (natively the environment variable `env`).
fn setting(key: &str, env: &str) -> Option<String> {
    #[cfg(target_arch = "wasm32")]
    {
        let _ = env;
        let get = |v: &_, name: &str| js_sys::Reflect::get(v, &name.into()).ok();
        let search = get(&js_sys::global(), "location").and_then(|l| get(&l, "search"))?;
        let query = search.as_string()?;
        let prefix = format!("{key}=");
        query
            .trim_start_matches('?')
            .split('&')
            .find_map(|kv| kv.strip_prefix(prefix.as_str()).map(str::to_owned))
    }
    #[cfg(not(target_arch = "wasm32"))]
    {
        let _ = key;
        std::env::var(env).ok()
    }
}

/// The share of the vegetation to grow: `?detail=D` (natively `RWT_DETAIL`), over 0 and at
/// most 1, else all of it.
fn detail() -> Detail {
    setting("detail", "RWT_DETAIL")
        .and_then(|d| d.parse::<f64>().ok())
        .filter(|d| *d > 0.0 && *d <= 1.0)
        .map_or(Detail::default(), Detail)
}

/// The report, timing `?frames=F` frames (natively `RWT_FRAMES`; at least 1) once settled,
/// else [`report::TIMED`].
fn report() -> report::ReportPlugin {
    let frames = setting("frames", "RWT_FRAMES").and_then(|f| f.parse::<usize>().ok());
    report::ReportPlugin {
        frames: frames.filter(|f| *f > 0).unwrap_or(report::TIMED),
    }
}

/// The mouse is the brush's while it is on, the camera's otherwise.
fn share_mouse(brush: Res<DensityBrush>, mut cameras: Query<&mut FlyCamera>) {
    for mut cam in &mut cameras {
        if cam.mouse == brush.enabled {
            cam.mouse = !brush.enabled;
        }
    }
}
