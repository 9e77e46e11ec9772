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
use glam::DVec2;
use rwt_core::density::Placement;
use rwt_core::density::{ImageDensity, Scale};
use rwt_core::query::{PointId, Rect, Sampler};
use rwt_core::tileset::TileSet;
use rwt_examples::prelude::*;
use std::collections::HashMap;
use std::time::Instant;

/// The image spans `[0, SIDE)^2` world units.
const SIDE: f64 = 1.0;
/// Dots on screen at any zoom (where the image is black everywhere in view).
const DOTS_IN_VIEW: f64 = 16_000.0;
/// Dot diameter in pixels.
const DOT_PIXELS: f32 = 3.2;
/// The smoke session zooms towards this point (mid-grey, near the highlight).
const FOCUS: DVec2 = DVec2::new(0.52, 0.53);

fn main() {
    App::new()
        .insert_resource(ClearColor(Color::WHITE))
        .add_plugins((example_plugins("rwt stipple_zoom"), SmokePlugin, HudPlugin))
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

/// The smoke session: 1x to 1000x towards `FOCUS`.
fn zoom_script(smoke: Res<Smoke>, mut view: ResMut<View>) {
    let t = smoke.progress() as f64;
    view.zoom = 1000f64.powf(t);
    view.centre = DVec2::splat(SIDE / 2.0).lerp(FOCUS, (t * 4.0).min(1.0));
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
    stipple.live.retain(|id, entity| {
        let keep = wanted.contains_key(id);
        if !keep {
            commands.entity(*entity).despawn();
        }
        keep
    });
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
