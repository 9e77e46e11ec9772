//! Texton painting (paper figure 10): paint a density map per texton class and watch the
//! textons appear as one blue-noise set shared by all classes, each with a rotation hashed
//! from its point's identity. The maps are `GroundMap`s read by one `bevy_rwt` layer on the
//! 2-D plane and painted by the library's brush (`RwtBrushPlugin`, the one open_world uses):
//! a stroke re-scatters only the chunks under it, so textons elsewhere never move, and the
//! maps save in the brush's format (`painted.ron` and a PNG per class).
//!
//! `cargo run --release --example paint_density`
//! - left mouse: paint the selected class, right mouse: erase it; 1-4 select the class;
//! - wheel or `[` / `]` brush size, Up / Down strength, Z undo, C clears, Space compares with
//!   random placement;
//! - S saves the maps to `painted/` (or `RWT_PAINT_DIR`), L loads them.

use bevy::camera::ScalingMode;
use bevy::prelude::*;
use bevy_rwt::brush::BrushKeys;
use bevy_rwt::prelude::*;
use glam::DVec2;
use rwt_core::rng::{hash_words, unit_f64};
use rwt_examples::prelude::*;
use std::path::PathBuf;

fn main() {
    App::new()
        .insert_resource(ClearColor(Color::srgb(0.93, 0.91, 0.85)))
        .add_plugins((
            example_plugins("rwt paint_density"),
            RwtPlugins::default()
                .with_spawn_budget(20_000)
                .build()
                .enable::<RwtBrushPlugin>(),
            SmokePlugin,
            HudPlugin,
            BrushStatusPlugin,
        ))
        .add_systems(Startup, setup)
        .add_systems(
            Update,
            (
                paint_script.run_if(|s: Res<Smoke>| s.active()),
                paint_keys.run_if(|s: Res<Smoke>| !s.active()),
                compare_with_random,
                show_maps,
                hud,
            )
                .chain()
                .before(BrushSystems),
        )
        .run();
}

/// One texton class: its picture and how dense it is where its map is 1.
struct TextonClass {
    name: &'static str,
    /// Textons per unit area where the map is white (the canvas is 1 x 1).
    max_density: f64,
    /// Texton size relative to the spacing at `max_density`.
    size: f32,
    /// Tint of the class on the map overlay.
    tint: [f32; 3],
}

const CLASSES: [TextonClass; 4] = [
    TextonClass {
        name: "leaf",
        max_density: 1400.0,
        size: 1.5,
        tint: [0.3, 0.6, 0.25],
    },
    TextonClass {
        name: "pebble",
        max_density: 900.0,
        size: 1.25,
        tint: [0.55, 0.55, 0.55],
    },
    TextonClass {
        name: "flower",
        max_density: 700.0,
        size: 1.3,
        tint: [0.85, 0.4, 0.6],
    },
    TextonClass {
        name: "starfish",
        max_density: 500.0,
        size: 1.3,
        tint: [0.9, 0.5, 0.2],
    },
];

/// Texels along each side of a class map.
const MAP_TEXELS: u32 = 192;
/// The tiling seed.
const SEED: u64 = 10;

#[derive(Resource)]
struct Canvas {
    /// One map per class, over the unit square.
    maps: Vec<GroundMap>,
    textures: Vec<Handle<Image>>,
    overlay: Handle<Image>,
    /// The entity holding the texton layer.
    layer: Entity,
    /// Show white-noise placement instead of blue noise.
    random: bool,
    random_live: Vec<Entity>,
}

impl Canvas {
    /// The layer: one class per texton, each reading its map over the unit canvas on the
    /// 2-D plane, with a rotation and a size hashed from each point's identity.
    fn layer(&self) -> ScatterLayer {
        let classes = CLASSES
            .iter()
            .zip(&self.maps)
            .zip(&self.textures)
            .map(|((c, map), texture)| {
                let sprite = Sprite {
                    image: texture.clone(),
                    custom_size: Some(Vec2::splat((c.size as f64 / c.max_density.sqrt()) as f32)),
                    ..default()
                };
                let mut class = ScatterClass::custom(LayerDensity::Image(map.clone()), move |e| {
                    e.insert(sprite.clone());
                });
                class.scale_variation = 0.15;
                class
            })
            .collect();
        ScatterLayer::new(classes)
            .on_plane(GroundPlane::Xy)
            .with_seed(SEED)
            .with_tile_size(1.0)
            .with_streaming(StreamingConfig {
                chunk_size: 0.125,
                load_distance: 2.0,
                unload_distance: 3.0,
                near_distance: 2.0,
            })
    }
}

impl Canvas {
    /// Each class map's texel values (linear grey, as the brush paints them; row 0 at the
    /// top), empty for a map not loaded.
    fn values(&self, images: &Assets<Image>) -> Vec<Vec<f32>> {
        let values = |image: &Image| -> Option<Vec<f32>> {
            let data = image.data.as_ref()?;
            Some(data.chunks_exact(4).map(|p| p[0] as f32 / 255.0).collect())
        };
        let map = |m: &GroundMap| images.get(&m.image).and_then(values).unwrap_or_default();
        self.maps.iter().map(map).collect()
    }
}

fn save_dir() -> PathBuf {
    std::env::var_os("RWT_PAINT_DIR").map_or_else(|| PathBuf::from("painted"), PathBuf::from)
}

fn setup(
    mut commands: Commands,
    assets: Res<AssetServer>,
    mut images: ResMut<Assets<Image>>,
    mut brush: ResMut<DensityBrush>,
) {
    let canvas_rect = Rect::new(0.0, 0.0, 1.0, 1.0);
    let maps: Vec<GroundMap> = CLASSES
        .iter()
        .map(|c| bevy_rwt::brush::blank_map(&mut images, MAP_TEXELS, canvas_rect, c.max_density))
        .collect();
    let textures = CLASSES
        .iter()
        .map(|c| assets.load(format!("textons/{}.png", c.name)))
        .collect();
    let overlay = bevy_rwt::brush::blank_map(&mut images, MAP_TEXELS, canvas_rect, 1.0).image;
    let mut canvas = Canvas {
        maps,
        textures,
        overlay: overlay.clone(),
        layer: Entity::PLACEHOLDER,
        random: false,
        random_live: Vec::new(),
    };
    canvas.layer = commands.spawn((Name::new("textons"), canvas.layer())).id();
    *brush = DensityBrush {
        enabled: true,
        targets: (0..CLASSES.len())
            .map(|i| NamedMap::new(canvas.layer, i, CLASSES[i].name))
            .collect(),
        radius: 0.06,
        radius_range: (0.005, 0.5),
        strength: 2.0,
        save_dir: save_dir(),
        // Sprites made in code have no layer file: the maps and the index are saved.
        layer_files: false,
        keys: BrushKeys {
            toggle: None,
            strength: None,
            save: Some(KeyCode::KeyS),
            load: Some(KeyCode::KeyL),
            ..default()
        },
        circle_lift: 1.0,
        ..default()
    };
    commands.insert_resource(canvas);
    // The unit canvas fills 92 % of the window's height; the layer streams around the
    // camera, which sees all of it.
    commands.spawn((
        Camera2d,
        Projection::Orthographic(OrthographicProjection {
            scaling_mode: ScalingMode::FixedVertical {
                viewport_height: 1.0 / 0.92,
            },
            ..OrthographicProjection::default_2d()
        }),
        Transform::from_xyz(0.5, 0.5, 10.0),
        RwtViewer::all_around(),
    ));
    commands.spawn((
        Sprite {
            image: overlay,
            custom_size: Some(Vec2::ONE),
            ..default()
        },
        Transform::from_xyz(0.5, 0.5, -1.0),
    ));
}

/// A dab for every class at once that empties the canvas (one stroke: Z undoes it).
fn clear_all(dabs: &mut MessageWriter<PaintDab>) {
    for target in 0..CLASSES.len() {
        dabs.write(PaintDab {
            target,
            centre: Vec2::splat(0.5),
            radius: 10.0,
            amount: -10.0,
        });
    }
}

/// The smoke session: a stroke per class, an eraser stroke, then a save, a clear and a load
/// (so that the screenshot shows the maps read back from disk, once their chunks have
/// re-scattered).
#[allow(clippy::too_many_arguments)] // one system a script: its messages and its report
fn paint_script(
    smoke: Res<Smoke>,
    mut step: Local<u8>,
    status: Res<BrushStatus>,
    mut dabs: MessageWriter<PaintDab>,
    mut commands: MessageWriter<BrushCommand>,
    mut exit: MessageWriter<AppExit>,
    mut report: ResMut<SmokeReport>,
    stats: Res<RwtStats>,
) {
    report.hold = *step < 4 || stats.pending_tasks > 0 || stats.queued_spawns > 0;
    let t = smoke.progress();
    let classes = CLASSES.len();
    let span = 0.7 / classes as f32;
    let class = ((t / span) as usize).min(classes);
    let mut dab = |target, centre, radius, amount| {
        dabs.write(PaintDab {
            target,
            centre,
            radius,
            amount,
        });
    };
    if class < classes {
        let s = (t - class as f32 * span) / span;
        let y = 0.16 + 0.23 * class as f32 + 0.05 * (s * 9.0).sin();
        dab(class, Vec2::new(0.08 + 0.84 * s, y), 0.09, 0.5);
        // A second, fainter pass of the next class overlapping this one: mixed regions.
        let next = Vec2::new(0.9 - 0.8 * s, y + 0.1);
        dab((class + 1) % classes, next, 0.05, 0.22);
        return;
    }
    if t < 0.8 {
        let s = (t - 0.7) / 0.1;
        for target in 0..classes {
            dab(target, Vec2::new(0.5 + 0.1 * s, 0.1 + 0.8 * s), 0.035, -1.0);
        }
        return;
    }
    // Save, clear, load: a step a frame, the brush's outcome checked before the next.
    if *step > 0 && *step < 4 && !matches!(status.last, Some(Ok(_))) {
        eprintln!("rwt-smoke: painted maps, step {}: {:?}", *step, status.last);
        exit.write(AppExit::error());
        return;
    }
    let dir = save_dir();
    match *step {
        0 => {
            commands.write(BrushCommand::Save(dir));
        }
        1 => clear_all(&mut dabs),
        2 => {
            commands.write(BrushCommand::Load(dir));
        }
        3 => println!(
            "rwt-smoke: painted maps saved to and loaded from {}",
            dir.display()
        ),
        _ => return,
    }
    *step += 1;
}

/// The example's own keys: size, strength, clearing (the brush reads the mouse, the class
/// digits, undo, save and load).
fn paint_keys(
    keys: Res<ButtonInput<KeyCode>>,
    mut brush: ResMut<DensityBrush>,
    mut dabs: MessageWriter<PaintDab>,
    mut canvas: ResMut<Canvas>,
) {
    let (lo, hi) = brush.radius_range;
    if keys.just_pressed(KeyCode::BracketLeft) {
        brush.radius = (brush.radius / 1.25).max(lo);
    }
    if keys.just_pressed(KeyCode::BracketRight) {
        brush.radius = (brush.radius * 1.25).min(hi);
    }
    if keys.just_pressed(KeyCode::ArrowUp) {
        brush.strength = (brush.strength * 1.5).min(20.0);
    }
    if keys.just_pressed(KeyCode::ArrowDown) {
        brush.strength = (brush.strength / 1.5).max(0.05);
    }
    if keys.just_pressed(KeyCode::KeyC) {
        clear_all(&mut dabs);
    }
    if keys.just_pressed(KeyCode::Space) {
        canvas.random = !canvas.random;
    }
}

/// Space: white noise with the same densities (rejection sampling) instead of the layer.
fn compare_with_random(
    mut commands: Commands,
    mut canvas: ResMut<Canvas>,
    images: Res<Assets<Image>>,
    mut events: MessageReader<AssetEvent<Image>>,
    mut shown: Local<bool>,
) {
    let repainted = maps_changed(&canvas, &mut events);
    if canvas.random == *shown && !(canvas.random && repainted) {
        return;
    }
    *shown = canvas.random;
    let canvas = &mut *canvas;
    for e in canvas.random_live.drain(..) {
        commands.entity(e).despawn();
    }
    if !canvas.random {
        commands.entity(canvas.layer).insert(canvas.layer());
        return;
    }
    commands.entity(canvas.layer).remove::<ScatterLayer>();
    let maps = canvas.values(&images);
    let total: f64 = CLASSES.iter().map(|c| c.max_density).sum();
    let n = MAP_TEXELS as usize;
    for k in 0..total as u64 {
        let h = |salt| unit_f64(hash_words(SEED, &[k, salt]));
        let p = DVec2::new(h(1), h(2));
        let texel =
            (((1.0 - p.y) * n as f64) as usize * n + (p.x * n as f64) as usize).min(n * n - 1);
        let mut u = h(3) * total;
        for (class, c) in CLASSES.iter().enumerate() {
            let v = maps[class].get(texel).copied().unwrap_or(0.0) as f64 * c.max_density;
            if u < v {
                let size = (c.size as f64 / c.max_density.sqrt()) as f32;
                let e = commands.spawn((
                    CountedInstance,
                    Sprite {
                        image: canvas.textures[class].clone(),
                        custom_size: Some(Vec2::splat(size)),
                        ..default()
                    },
                    Transform::from_xyz(p.x as f32, p.y as f32, 0.0)
                        .with_rotation(Quat::from_rotation_z(h(4) as f32 * std::f32::consts::TAU)),
                ));
                canvas.random_live.push(e.id());
                break;
            }
            u -= v;
        }
    }
}

/// Whether a class map changed (a dab, an undo, a load) since the system last looked.
fn maps_changed(canvas: &Canvas, events: &mut MessageReader<AssetEvent<Image>>) -> bool {
    let maps: Vec<AssetId<Image>> = canvas.maps.iter().map(|m| m.image.id()).collect();
    events
        .read()
        .filter(|e| maps.iter().any(|id| e.is_modified(*id) || e.is_added(*id)))
        .count()
        > 0
}

/// The maps, tinted by class over white, behind the textons.
fn show_maps(
    canvas: Res<Canvas>,
    mut events: MessageReader<AssetEvent<Image>>,
    mut images: ResMut<Assets<Image>>,
) {
    if !maps_changed(&canvas, &mut events) {
        return;
    }
    let maps = canvas.values(&images);
    let Some(mut overlay) = images.get_mut(&canvas.overlay) else {
        return;
    };
    let Some(data) = overlay.data.as_mut() else {
        return;
    };
    for (i, px) in data.chunks_exact_mut(4).enumerate() {
        let mut rgb = Vec3::splat(1.0);
        for (c, map) in CLASSES.iter().zip(&maps) {
            let w = map.get(i).copied().unwrap_or(0.0) * 0.45;
            rgb = rgb.lerp(Vec3::from_array(c.tint), w);
        }
        // The overlay's texels are linear: the tints are given in sRGB.
        let linear = Color::srgb(rgb.x, rgb.y, rgb.z).to_linear();
        px.copy_from_slice(&[
            (linear.red * 255.0) as u8,
            (linear.green * 255.0) as u8,
            (linear.blue * 255.0) as u8,
            255,
        ]);
    }
}

fn hud(
    canvas: Res<Canvas>,
    brush: Res<DensityBrush>,
    status: Res<BrushStatus>,
    live: Res<LiveInstances>,
    mut hud: ResMut<Hud>,
) {
    let names: Vec<String> = brush
        .targets
        .iter()
        .enumerate()
        .map(|(i, t)| {
            let mark = if i == brush.selected { ">" } else { " " };
            format!("{mark}{} {}", i + 1, t.name)
        })
        .collect();
    let last = status.line();
    hud.lines = vec![
        "rwt paint_density: left paint, right erase, 1-4 class, wheel or [ ] size, Up/Down strength".into(),
        "Z undo, C clear, Space random/blue noise, S save, L load".into(),
        format!(
            "{}   brush {:.3}, strength {:.2}",
            names.join("  "),
            brush.radius,
            brush.strength,
        ),
        format!(
            "{}: {} textons   {last}",
            if canvas.random { "random (white noise)" } else { "blue noise (rwt)" },
            live.0,
        ),
    ];
}
