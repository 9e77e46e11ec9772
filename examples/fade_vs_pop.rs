//! Fade-in by rank against popping, drawn from the plugin's own instance buffers:
//! `cargo run --release --example fade_vs_pop` writes `docs/images/fade_vs_pop.png`.
//!
//! A headless app streams instanced grass with a level-of-detail fall-off (full density
//! within 20 m of the viewer, none beyond 100 m) while the viewer walks 3 m at a time. Each
//! row of the image is one step, seen from above over 30-110 m ahead; each blade is a disc
//! as large as the vertex shader draws it. Left: with the fade band (the default), a blade
//! grows in as the factor rises past the one at which its point appears. Right: without
//! it, the same blades are either absent or full size. Red marks the blades absent or not
//! yet drawn one step before: on the right they pop in at full size, on the left they are
//! specks.

use bevy::prelude::*;
use bevy_rwt::instancing::InstancedChunk;
use bevy_rwt::prelude::*;
use image::{Rgb, RgbImage};
use std::collections::HashMap;

/// Level-of-detail fall-off (near, far), metres.
const FALLOFF: (f32, f32) = (20.0, 100.0);
/// Ground shown: x in `VIEW.0..VIEW.1`, z in `-DEPTH..DEPTH`, metres.
const VIEW: (f32, f32) = (30.0, 110.0);
const DEPTH: f32 = 8.0;
/// Pixels per metre.
const PX: f32 = 6.0;
/// Viewer steps along x, metres.
const STEPS: [f32; 3] = [0.0, 3.0, 6.0];

fn main() {
    let mut app = headless_app();
    let viewer = app
        .world_mut()
        .spawn((
            RwtViewer::all_around(),
            Transform::default(),
            GlobalTransform::default(),
        ))
        .id();
    let band = InstancedShading::default().fade_band;
    let (w, h) = (((VIEW.1 - VIEW.0) * PX) as u32, (2.0 * DEPTH * PX) as u32);
    let gap = 6;
    let mut out = RgbImage::from_pixel(2 * w + gap, STEPS.len() as u32 * (h + gap), Rgb([255; 3]));
    let mut before: HashMap<(u32, u32), [f32; 2]> = HashMap::new();
    for (row, &x) in STEPS.iter().enumerate() {
        let at = Vec3::new(x, 0.0, 0.0);
        let mut e = app.world_mut().entity_mut(viewer);
        *e.get_mut::<Transform>().unwrap() = Transform::from_translation(at);
        *e.get_mut::<GlobalTransform>().unwrap() = GlobalTransform::from_translation(at);
        settle(&mut app);
        let blades = blades(&mut app, at, band);
        let top = row as u32 * (h + gap);
        for (column, pop) in [false, true].into_iter().enumerate() {
            let left = column as u32 * (w + gap);
            for (key, &[size_fade, size_pop]) in &blades {
                let size = if pop { size_pop } else { size_fade };
                let was = before
                    .get(key)
                    .map_or(0.0, |s| if pop { s[1] } else { s[0] });
                let new = row > 0 && was == 0.0 && size > 0.0;
                let color = if new {
                    Rgb([220, 30, 30])
                } else {
                    Rgb([40, 110, 30])
                };
                let (px, pz) = (key.0 as f32 / 100.0, key.1 as f32 / 100.0);
                disc(&mut out, left, top, (w, h), (px, pz), size, color);
            }
        }
        before = blades;
    }
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/images/fade_vs_pop.png");
    std::fs::create_dir_all(path.parent().unwrap()).unwrap();
    out.save(&path).unwrap();
    println!(
        "fade-vs-pop: wrote {} ({}x{})",
        path.display(),
        out.width(),
        out.height()
    );
}

/// A headless app with one instanced grass layer.
fn headless_app() -> App {
    let mut app = bevy_rwt::testing::headless_app(RwtPlugins::default());
    let grass = ScatterClass::instanced(
        LayerDensity::Constant(3.0),
        Handle::default(),
        InstancedShading::default(),
    );
    app.world_mut().spawn(
        ScatterLayer::new(vec![grass])
            .with_tile_size(2.0)
            .with_seed(5)
            .with_falloff(FALLOFF.0 as f64, FALLOFF.1 as f64)
            .with_streaming(StreamingConfig {
                chunk_size: 16.0,
                load_distance: 115.0,
                unload_distance: 130.0,
                near_distance: 24.0,
            }),
    );
    app
}

/// Runs frames until nothing is pending.
fn settle(app: &mut App) {
    assert!(
        bevy_rwt::testing::settle(app, 100_000),
        "streaming did not settle"
    );
}

/// Blades in view, by position in centimetres: their drawn size with and without the fade
/// band (0 when not drawn).
fn blades(app: &mut App, viewer: Vec3, band: f32) -> HashMap<(u32, u32), [f32; 2]> {
    let mut chunks = app.world_mut().query::<(&InstancedChunk, &Transform)>();
    let mut out = HashMap::new();
    for (c, t) in chunks.iter(app.world()) {
        for g in &c.buffer.instances {
            let p = t.translation + Vec3::from_array(g.offset);
            if p.x < VIEW.0 || p.x >= VIEW.1 || p.z.abs() >= DEPTH {
                continue;
            }
            let distance = Vec2::new(p.x - viewer.x, p.z - viewer.z).length();
            let (fade, pop) = (
                growth(distance, g.appear_factor(), band),
                growth(distance, g.appear_factor(), 1e-3),
            );
            let key = ((p.x * 100.0) as u32, ((p.z + DEPTH) * 100.0) as u32);
            out.insert(key, [fade * g.scale, pop.ceil() * g.scale]);
        }
    }
    out
}

/// The vertex shader's growth (`instanced.wgsl`): 0 until the level-of-detail factor at
/// the blade's place reaches the one at which its point appears, then up to 1 over `band`.
fn growth(distance: f32, appear: f32, band: f32) -> f32 {
    let factor = (1.0 - (distance - FALLOFF.0) / (FALLOFF.1 - FALLOFF.0)).clamp(0.0, 1.0);
    ((factor - appear) / band).clamp(0.0, 1.0)
}

/// A disc of radius `size` (metres, at least a pixel when drawn) at ground position
/// `(x, z + DEPTH)` inside the panel at `left, top`.
fn disc(
    out: &mut RgbImage,
    left: u32,
    top: u32,
    (w, h): (u32, u32),
    (x, z): (f32, f32),
    size: f32,
    color: Rgb<u8>,
) {
    if size <= 0.0 {
        return;
    }
    let r = (0.35 * size * PX).max(0.5);
    let (cx, cy) = ((x - VIEW.0) * PX, z * PX);
    let (x0, x1) = (
        (cx - r).floor().max(0.0) as u32,
        ((cx + r).ceil() as u32).min(w),
    );
    let (y0, y1) = (
        (cy - r).floor().max(0.0) as u32,
        ((cy + r).ceil() as u32).min(h),
    );
    for py in y0..y1 {
        for px in x0..x1 {
            let (dx, dy) = (px as f32 + 0.5 - cx, py as f32 + 0.5 - cy);
            if dx * dx + dy * dy <= r * r {
                out.put_pixel(left + px, top + py, color);
            }
        }
    }
}
