//! Zoom from 1x to 1000x into a stippled image (paper figure 1): the density grows with the
//! square of the zoom, so the dots on screen stay equally dense, and since a higher density
//! only ever adds points, no dot moves or flickers as you zoom; new ones appear between them.
//!
//! `cargo run --release --example stipple_zoom`: wheel or +/- to zoom (towards the cursor),
//! drag with the left button to pan, R to reset.

use bevy::asset::RenderAssetUsages;
use bevy::input::mouse::{AccumulatedMouseMotion, AccumulatedMouseScroll};
use bevy::prelude::*;
use bevy::render::render_resource::{Extent3d, TextureDimension, TextureFormat};
use bevy::render::view::screenshot::{Screenshot, ScreenshotCaptured};
use glam::DVec2;
use rwt_core::density::Placement;
use rwt_core::density::{ImageDensity, Scale};
use rwt_core::query::{PointId, Rect, Sampler};
use rwt_core::tileset::TileSet;
use rwt_examples::prelude::*;
use rwt_examples::smoke::{BLANK_VARIANCE, luminance_variance};
use std::collections::HashMap;
use std::time::Instant;

/// The image spans `[0, SIDE)^2` world units.
const SIDE: f64 = 1.0;
/// Dots on screen at any zoom (where the image is black everywhere in view).
const DOTS_IN_VIEW: f64 = 16_000.0;
/// Dot diameter in pixels.
const DOT_PIXELS: f32 = 3.2;
/// The smoke session zooms towards this point: the sphere's shadowed edge, where its dark
/// side meets the light background between texels 327 and 328 of row 200 of the image. At
/// 1000x the view spans less than a texel and still shows the edge, as a gradient.
const FOCUS: DVec2 = DVec2::new(328.0 / 384.0, 1.0 - 200.5 / 384.0);
/// The zooms the smoke session photographs (the last one is the harness's screenshot).
const SHOTS: [(f64, &str); 3] = [(1.0, "1x"), (30.0, "30x"), (1000.0, "1000x")];

fn main() {
    App::new()
        .insert_resource(ClearColor(Color::WHITE))
        .add_plugins((example_plugins("rwt stipple_zoom"), SmokePlugin, HudPlugin))
        .init_resource::<ZoomScript>()
        .add_systems(Startup, setup)
        .add_systems(
            Update,
            (
                zoom_script.run_if(|s: Res<Smoke>| s.active()),
                navigate.run_if(|s: Res<Smoke>| !s.active()),
                place,
                hud,
            )
                .chain(),
        )
        .run();
}

/// Where the view is: centre in world units, zoom relative to the whole image in view.
#[derive(Resource)]
struct View {
    centre: DVec2,
    zoom: f64,
}

#[derive(Resource)]
struct Stipple {
    sampler: Sampler,
    /// Darkness of the image, scaled so that black gives `DOTS_IN_VIEW` dots over the image.
    darkness: ImageDensity,
    dot: Handle<Image>,
    live: HashMap<PointId, Entity>,
    /// Points produced by the last query and its duration.
    last_query: (usize, f64),
    /// Dots that left while their point was still in view: none, since a higher density
    /// only ever adds points (the smoke session reports it).
    lost_in_view: usize,
}

fn setup(mut commands: Commands, mut images: ResMut<Assets<Image>>) {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/images/sphere.png");
    let picture = image::open(&path).expect("assets/images/sphere.png (scripts/make_images.py)");
    let area = SIDE * SIDE;
    let darkness = ImageDensity::from_image(
        &picture,
        None,
        true,
        Placement {
            min: DVec2::ZERO,
            size: DVec2::splat(SIDE),
            scale: DOTS_IN_VIEW / area,
        },
    )
    .expect("a valid image");
    let set = TileSet::embedded();
    // Base tiles sized so that black at zoom 1 fills a tile's base points.
    let tile = (set.points_per_tile as f64 * area / DOTS_IN_VIEW).sqrt();
    commands.insert_resource(Stipple {
        sampler: Sampler::new(&set, 7).with_tile_size(tile),
        darkness,
        dot: images.add(disk(32)),
        live: HashMap::new(),
        last_query: (0, 0.0),
        lost_in_view: 0,
    });
    commands.insert_resource(View {
        centre: DVec2::splat(SIDE / 2.0),
        zoom: 1.0,
    });
    commands.spawn(Camera2d);
}

/// A white disk with a soft edge, tinted black per sprite.
fn disk(size: u32) -> Image {
    let mut data = Vec::with_capacity((size * size * 4) as usize);
    let r = size as f32 / 2.0;
    for y in 0..size {
        for x in 0..size {
            let d = Vec2::new(x as f32 + 0.5 - r, y as f32 + 0.5 - r).length();
            let alpha = ((r - d) / 1.5).clamp(0.0, 1.0);
            data.extend_from_slice(&[255, 255, 255, (alpha * 255.0) as u8]);
        }
    }
    Image::new(
        Extent3d {
            width: size,
            height: size,
            depth_or_array_layers: 1,
        },
        TextureDimension::D2,
        data,
        TextureFormat::Rgba8UnormSrgb,
        RenderAssetUsages::RENDER_WORLD,
    )
}

/// The smoke session: the whole image at 1x, then towards `FOCUS` to 30x and on to 1000x,
/// each zoom of [`SHOTS`] held until its screenshot has dots on it (`<screenshot>_1x.png`,
/// `_30x.png`; the harness takes the 1000x one).
fn zoom_script(
    smoke: Res<Smoke>,
    mut view: ResMut<View>,
    stipple: Res<Stipple>,
    live: Res<LiveInstances>,
    mut script: ResMut<ZoomScript>,
    mut report: ResMut<SmokeReport>,
    mut commands: Commands,
) {
    let shot = script.captured.min(SHOTS.len() - 1);
    let (to, label) = SHOTS[shot];
    let from = if shot == 0 { 1.0 } else { SHOTS[shot - 1].0 };
    let s = ((smoke.frame - script.phase_start) as f64 / ZOOM_FRAMES as f64).min(1.0);
    view.zoom = from * (to / from).powf(s);
    // The centre reaches the focus at 30x and stays on it.
    let toward = (view.zoom.ln() / 30f64.ln()).min(1.0);
    view.centre = DVec2::splat(SIDE / 2.0).lerp(FOCUS, toward);
    let last = script.captured == SHOTS.len() - 1;
    // The harness takes the last screenshot once the zoom has reached it.
    report.hold = !last || s < 1.0;
    if s < 1.0 || script.requested {
        return;
    }
    println!(
        "rwt-smoke: zoom {label}: {} dots in view, {} left while in view",
        live.0, stipple.lost_in_view
    );
    if last {
        script.requested = true;
        return;
    }
    let Some(path) = &smoke.screenshot else {
        return;
    };
    let file = path.with_file_name(format!(
        "{}_{label}.png",
        path.file_stem().unwrap_or_default().to_string_lossy()
    ));
    script.requested = true;
    commands.spawn(Screenshot::primary_window()).observe(
        move |captured: On<ScreenshotCaptured>,
              smoke: Res<Smoke>,
              mut script: ResMut<ZoomScript>| {
            script.requested = false;
            let Ok(image) = captured.image.clone().try_into_dynamic() else {
                return;
            };
            let rgb = image.to_rgb8();
            // A software renderer shows nothing while it compiles pipelines: look again.
            if luminance_variance(&rgb) < BLANK_VARIANCE {
                return;
            }
            if let Err(e) = rgb.save(&file) {
                eprintln!("rwt-smoke: cannot write {}: {e}", file.display());
            }
            script.captured += 1;
            script.phase_start = smoke.frame;
        },
    );
}

/// Frames the smoke session takes from one photographed zoom to the next.
const ZOOM_FRAMES: u32 = 40;

/// Where the smoke session is: the zooms photographed so far, whether a screenshot is on its
/// way, and the frame the current zoom began.
#[derive(Resource, Default)]
struct ZoomScript {
    captured: usize,
    requested: bool,
    phase_start: u32,
}

fn navigate(
    keys: Res<ButtonInput<KeyCode>>,
    buttons: Res<ButtonInput<MouseButton>>,
    motion: Res<AccumulatedMouseMotion>,
    scroll: Res<AccumulatedMouseScroll>,
    windows: Query<&Window>,
    mut view: ResMut<View>,
) {
    let Ok(window) = windows.single() else {
        return;
    };
    let px = world_per_pixel(&view, window);
    let mut steps = scroll.delta.y as f64;
    if keys.just_pressed(KeyCode::Equal) || keys.just_pressed(KeyCode::NumpadAdd) {
        steps += 1.0;
    }
    if keys.just_pressed(KeyCode::Minus) || keys.just_pressed(KeyCode::NumpadSubtract) {
        steps -= 1.0;
    }
    if steps != 0.0 {
        // Keep the world point under the cursor in place.
        let cursor = window.cursor_position().unwrap_or(window.size() / 2.0);
        let offset = DVec2::new(
            (cursor.x - window.width() / 2.0) as f64,
            (window.height() / 2.0 - cursor.y) as f64,
        );
        let anchor = view.centre + offset * px;
        view.zoom = (view.zoom * 1.25f64.powf(steps)).clamp(0.5, 5000.0);
        view.centre = anchor - offset * world_per_pixel(&view, window);
    }
    if buttons.pressed(MouseButton::Left) {
        let d = motion.delta;
        view.centre -= DVec2::new(d.x as f64, -d.y as f64) * px;
    }
    if keys.just_pressed(KeyCode::KeyR) {
        *view = View {
            centre: DVec2::splat(SIDE / 2.0),
            zoom: 1.0,
        };
    }
}

/// World units per pixel: at zoom 1 the image fits the window's height.
fn world_per_pixel(view: &View, window: &Window) -> f64 {
    SIDE / view.zoom / window.height().max(1.0) as f64
}

/// Queries the view at the zoom's density and spawns or despawns only the difference. Dots
/// are placed in pixels relative to the view's centre, computed in f64, so the view stays
/// exact at any zoom.
fn place(
    mut commands: Commands,
    view: Res<View>,
    windows: Query<&Window>,
    mut stipple: ResMut<Stipple>,
    mut dots: Query<(&PointPos, &mut Transform)>,
    mut last_zoom: Local<f64>,
) {
    let Ok(window) = windows.single() else {
        return;
    };
    let px = world_per_pixel(&view, window);
    let half = DVec2::new(window.width() as f64, window.height() as f64) * 0.5 * px;
    let Ok(rect) = Rect::new(view.centre - half, view.centre + half) else {
        return;
    };
    // Dots per screen stay constant: the density grows with the zoom's square.
    let density = Scale(&stipple.darkness, view.zoom * view.zoom);
    let started = Instant::now();
    let mut points = Vec::new();
    if stipple.sampler.query(rect, &density, &mut points).is_err() {
        return;
    }
    stipple.last_query = (points.len(), started.elapsed().as_secs_f64());
    let wanted: HashMap<PointId, DVec2> = points.iter().map(|p| (p.id, p.position)).collect();
    let stipple = &mut *stipple;
    // Zooming in only ever adds points: a dot whose point is still in view stays (zooming
    // out thins the view, and dots go).
    let zooming_in = view.zoom >= *last_zoom;
    *last_zoom = view.zoom;
    let mut lost = 0;
    stipple.live.retain(|id, entity| {
        let keep = wanted.contains_key(id);
        if !keep {
            let in_view = dots.get(*entity).is_ok_and(|(p, _)| rect.contains(p.0));
            lost += usize::from(zooming_in && in_view);
            commands.entity(*entity).despawn();
        }
        keep
    });
    stipple.lost_in_view += lost;
    for (id, pos) in wanted {
        stipple.live.entry(id).or_insert_with(|| {
            commands
                .spawn((
                    CountedInstance,
                    PointPos(pos),
                    Sprite {
                        image: stipple.dot.clone(),
                        color: Color::BLACK,
                        custom_size: Some(Vec2::splat(DOT_PIXELS)),
                        ..default()
                    },
                    Transform::from_translation(screen(pos, &view, px)),
                ))
                .id()
        });
    }
    if view.is_changed() {
        for (pos, mut t) in &mut dots {
            t.translation = screen(pos.0, &view, px);
        }
    }
}

/// A dot's world position (f64, never changes).
#[derive(Component)]
struct PointPos(DVec2);

fn screen(p: DVec2, view: &View, px: f64) -> Vec3 {
    let s = (p - view.centre) / px;
    Vec3::new(s.x as f32, s.y as f32, 0.0)
}

fn hud(view: Res<View>, stipple: Res<Stipple>, live: Res<LiveInstances>, mut hud: ResMut<Hud>) {
    let (n, secs) = stipple.last_query;
    hud.lines = vec![
        "rwt stipple_zoom: wheel or +/- zoom, drag to pan, R reset".into(),
        format!("zoom {:.1}x", view.zoom),
        format!("points on screen {}", live.0),
        format!(
            "query {:.2} ms, {:.1} M points/s",
            secs * 1e3,
            n as f64 / secs.max(1e-9) / 1e6
        ),
    ];
}
