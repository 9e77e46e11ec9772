//! Texton painting (paper figure 10): paint a density map per texton class and watch the
//! textons appear as one blue-noise set shared by all classes, each with a rotation hashed
//! from its point's identity. The maps are Bevy images read by one `bevy_rwt` layer on the
//! 2-D plane: a stroke tells the plugin its region (`DensityMapPainted`), so only the
//! chunks under it re-scatter and textons elsewhere never move.
//!
//! `cargo run --release --example paint_density`
//! - left mouse: paint the selected class, right mouse: erase it; 1-4 select the class,
//!   E erases every class under the brush instead;
//! - `[` / `]` brush size, Up / Down strength, C clears, Space compares with random placement;
//! - S saves the maps (PNG) and the setup (RON) to `painted/` (or `RWT_PAINT_DIR`), L loads.

use bevy::asset::RenderAssetUsages;
use bevy::camera::ScalingMode;
use bevy::prelude::*;
use bevy::render::render_resource::{Extent3d, TextureDimension, TextureFormat};
use bevy_rwt::prelude::*;
use glam::DVec2;
use rwt_core::density::open_image;
use rwt_core::files::{SaveTransaction, recover};
use rwt_core::query::Rect;
use rwt_core::rng::{hash_words, unit_f64};
use rwt_examples::prelude::*;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

fn main() {
    App::new()
        .insert_resource(ClearColor(Color::srgb(0.93, 0.91, 0.85)))
        .add_plugins((
            example_plugins("rwt paint_density"),
            RwtPlugins::default().with_spawn_budget(20_000),
            SmokePlugin,
            HudPlugin,
        ))
        .add_systems(Startup, setup)
        .add_systems(
            Update,
            (
                paint_script.run_if(|s: Res<Smoke>| s.active()),
                paint_input.run_if(|s: Res<Smoke>| !s.active()),
                upload_maps,
                compare_with_random,
                show_maps,
                hud,
            )
                .chain(),
        )
        .run();
}

/// One texton class: its picture and how dense it is where its map is 1.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
struct ClassSetup {
    name: String,
    /// File in `assets/textons/`.
    texton: String,
    /// Textons per unit area where the map is white (the canvas is 1 x 1).
    max_density: f64,
    /// Texton size relative to the spacing at `max_density`.
    size: f32,
    /// Tint of the class on the map overlay.
    tint: [f32; 3],
}

/// What `S` saves next to the maps: enough to paint on where you left off.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
struct PaintSetup {
    seed: u64,
    /// Map resolution (square).
    map_size: usize,
    classes: Vec<ClassSetup>,
}

impl Default for PaintSetup {
    fn default() -> Self {
        let class = |name: &str, max_density, size, tint| ClassSetup {
            name: name.into(),
            texton: format!("{name}.png"),
            max_density,
            size,
            tint,
        };
        Self {
            seed: 10,
            map_size: 192,
            classes: vec![
                class("leaf", 1400.0, 1.5, [0.3, 0.6, 0.25]),
                class("pebble", 900.0, 1.25, [0.55, 0.55, 0.55]),
                class("flower", 700.0, 1.3, [0.85, 0.4, 0.6]),
                class("starfish", 500.0, 1.3, [0.9, 0.5, 0.2]),
            ],
        }
    }
}

#[derive(Resource)]
struct Canvas {
    setup: PaintSetup,
    /// One map per class, row 0 at the top, values in [0, 1]; uploaded to `images`.
    maps: Vec<Vec<f32>>,
    /// The Bevy images the layer reads, one per class.
    images: Vec<Handle<Image>>,
    /// World rectangle painted since the last upload.
    dirty: Option<Rect>,
    /// Show white-noise placement instead of blue noise.
    random: bool,
    textures: Vec<Handle<Image>>,
    overlay: Handle<Image>,
    /// The entity holding the texton layer.
    layer: Entity,
    random_live: Vec<Entity>,
    status: String,
}

impl Canvas {
    fn clear(&mut self) {
        let n = self.setup.map_size;
        self.maps = vec![vec![0.0; n * n]; self.setup.classes.len()];
        self.dirty = Some(whole());
    }

    /// Adds `amount` (negative erases) with a smooth fall-off inside `radius` of `centre`.
    fn brush(&mut self, class: Option<usize>, centre: DVec2, radius: f64, amount: f32) {
        let n = self.setup.map_size;
        let texel = 1.0 / n as f64;
        let (x0, x1) = (
            ((centre.x - radius) / texel).floor().max(0.0) as usize,
            (((centre.x + radius) / texel).ceil().max(0.0) as usize).min(n),
        );
        let (y0, y1) = (
            ((1.0 - centre.y - radius) / texel).floor().max(0.0) as usize,
            (((1.0 - centre.y + radius) / texel).ceil().max(0.0) as usize).min(n),
        );
        for (c, map) in self.maps.iter_mut().enumerate() {
            if class.is_some_and(|k| k != c) {
                continue;
            }
            for y in y0..y1 {
                for x in x0..x1 {
                    let p = DVec2::new((x as f64 + 0.5) * texel, 1.0 - (y as f64 + 0.5) * texel);
                    let d = p.distance(centre) / radius;
                    if d < 1.0 {
                        let w = (1.0 - d * d) as f32;
                        let v = &mut map[y * n + x];
                        *v = (*v + amount * w).clamp(0.0, 1.0);
                    }
                }
            }
        }
        let r = Rect::new(
            (centre - radius - texel).max(DVec2::ZERO),
            (centre + radius + texel).min(DVec2::ONE),
        )
        .unwrap_or(Rect::EMPTY);
        self.dirty = Some(match self.dirty {
            Some(d) => Rect::new(d.min().min(r.min()), d.max().max(r.max())).unwrap_or(d),
            None => r,
        });
    }

    /// The layer: one class per texton, each reading its map over the unit canvas on the
    /// 2-D plane, with a rotation and a size hashed from each point's identity.
    fn layer(&self) -> ScatterLayer {
        let classes = self
            .setup
            .classes
            .iter()
            .zip(&self.images)
            .zip(&self.textures)
            .map(|((c, map), texture)| {
                let density = LayerDensity::Image(GroundMap {
                    image: map.clone(),
                    min: Vec2::ZERO,
                    size: Vec2::ONE,
                    scale: c.max_density,
                });
                let sprite = Sprite {
                    image: texture.clone(),
                    custom_size: Some(Vec2::splat((c.size as f64 / c.max_density.sqrt()) as f32)),
                    ..default()
                };
                let mut class = ScatterClass::custom(density, move |e| {
                    e.insert(sprite.clone());
                });
                class.scale_variation = 0.15;
                class
            })
            .collect();
        ScatterLayer::new(classes)
            .on_plane(GroundPlane::Xy)
            .with_seed(self.setup.seed)
            .with_tile_size(1.0)
            .with_streaming(StreamingConfig {
                chunk_size: 0.125,
                load_distance: 2.0,
                unload_distance: 3.0,
                near_distance: 2.0,
            })
    }

    /// Writes the maps and the setup together, all or nothing (a failure keeps the
    /// previous save).
    fn save(&self, dir: &Path) -> Result<(), String> {
        let mut save = SaveTransaction::begin(dir).map_err(|e| e.to_string())?;
        let n = self.setup.map_size as u32;
        for (c, map) in self.setup.classes.iter().zip(&self.maps) {
            let bytes: Vec<u8> = map.iter().map(|v| (v * 255.0).round() as u8).collect();
            let img = image::GrayImage::from_raw(n, n, bytes).ok_or("map size mismatch")?;
            save.write_with(&format!("{}.png", c.name), |w| {
                img.write_with_encoder(image::codecs::png::PngEncoder::new(w))
                    .map_err(std::io::Error::other)
            })
            .map_err(|e| e.to_string())?;
        }
        let ron = ron::ser::to_string_pretty(&self.setup, ron::ser::PrettyConfig::default())
            .map_err(|e| e.to_string())?;
        save.write("layer.ron", ron.as_bytes())
            .and_then(|()| save.commit())
            .map_err(|e| e.to_string())
    }

    fn load(&mut self, dir: &Path) -> Result<(), String> {
        recover(dir).map_err(|e| e.to_string())?;
        let text = std::fs::read_to_string(dir.join("layer.ron"))
            .map_err(|e| format!("{}: {e}", dir.join("layer.ron").display()))?;
        let setup: PaintSetup = ron::from_str(&text).map_err(|e| format!("layer.ron: {e}"))?;
        if setup.classes.len() != self.setup.classes.len() || setup.map_size == 0 {
            return Err("layer.ron: class list differs from this example's textons".into());
        }
        let mut maps = Vec::new();
        for c in &setup.classes {
            let path = dir.join(format!("{}.png", c.name));
            let img = open_image(&path).map_err(|e| format!("{}: {e}", path.display()))?;
            let img = img
                .resize_exact(
                    setup.map_size as u32,
                    setup.map_size as u32,
                    image::imageops::FilterType::Triangle,
                )
                .to_luma8();
            maps.push(img.pixels().map(|p| p[0] as f32 / 255.0).collect());
        }
        self.setup = setup;
        self.maps = maps;
        self.dirty = Some(whole());
        Ok(())
    }
}

fn whole() -> Rect {
    Rect::new(DVec2::ZERO, DVec2::ONE).expect("ordered")
}

/// A brush per class (its own size and strength), one of them selected.
#[derive(Resource)]
struct Brush {
    class: usize,
    erase_all: bool,
    radius: Vec<f64>,
    strength: Vec<f32>,
}

impl Brush {
    fn radius(&mut self) -> &mut f64 {
        &mut self.radius[self.class]
    }

    fn strength(&mut self) -> &mut f32 {
        &mut self.strength[self.class]
    }
}

fn save_dir() -> PathBuf {
    std::env::var_os("RWT_PAINT_DIR").map_or_else(|| PathBuf::from("painted"), PathBuf::from)
}

/// A `n x n` single-channel image for a class map.
fn map_image(n: usize) -> Image {
    Image::new_fill(
        Extent3d {
            width: n as u32,
            height: n as u32,
            depth_or_array_layers: 1,
        },
        TextureDimension::D2,
        &[0],
        TextureFormat::R8Unorm,
        RenderAssetUsages::default(),
    )
}

fn setup(mut commands: Commands, assets: Res<AssetServer>, mut images: ResMut<Assets<Image>>) {
    let setup = PaintSetup::default();
    let n = setup.map_size;
    let textures = setup
        .classes
        .iter()
        .map(|c| assets.load(format!("textons/{}", c.texton)))
        .collect();
    let maps = setup
        .classes
        .iter()
        .map(|_| images.add(map_image(n)))
        .collect();
    let mut overlay = map_image(n);
    overlay.texture_descriptor.format = TextureFormat::Rgba8UnormSrgb;
    overlay.data = Some(vec![255; n * n * 4]);
    let overlay = images.add(overlay);
    let mut canvas = Canvas {
        maps: Vec::new(),
        images: maps,
        setup,
        dirty: None,
        random: false,
        textures,
        overlay: overlay.clone(),
        layer: Entity::PLACEHOLDER,
        random_live: Vec::new(),
        status: String::new(),
    };
    canvas.clear();
    canvas.layer = commands.spawn(canvas.layer()).id();
    let classes = canvas.setup.classes.len();
    commands.insert_resource(canvas);
    commands.insert_resource(Brush {
        class: 0,
        erase_all: false,
        radius: vec![0.06; classes],
        strength: vec![2.0; classes],
    });
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
        MapOverlay,
        Sprite {
            image: overlay,
            custom_size: Some(Vec2::ONE),
            ..default()
        },
        Transform::from_xyz(0.5, 0.5, -1.0),
    ));
}

#[derive(Component)]
struct MapOverlay;

/// The smoke session: a stroke per class, an eraser stroke, then a save, a clear and a load
/// (so that the screenshot shows the maps read back from disk, once their chunks have
/// re-scattered).
fn paint_script(
    smoke: Res<Smoke>,
    mut canvas: ResMut<Canvas>,
    mut done: Local<bool>,
    mut exit: MessageWriter<AppExit>,
    mut report: ResMut<SmokeReport>,
    stats: Res<RwtStats>,
) {
    report.hold = !*done || stats.pending_tasks > 0 || stats.queued_spawns > 0;
    let t = smoke.progress() as f64;
    let classes = canvas.setup.classes.len();
    let span = 0.7 / classes as f64;
    let class = ((t / span) as usize).min(classes);
    if class < classes {
        let s = (t - class as f64 * span) / span;
        let y = 0.16 + 0.23 * class as f64 + 0.05 * (s * 9.0).sin();
        canvas.brush(Some(class), DVec2::new(0.08 + 0.84 * s, y), 0.09, 0.35);
        // A second, fainter pass of the next class overlapping this one: mixed regions.
        canvas.brush(
            Some((class + 1) % classes),
            DVec2::new(0.9 - 0.8 * s, y + 0.1),
            0.05,
            0.15,
        );
    } else if t < 0.8 {
        let s = (t - 0.7) / 0.1;
        canvas.brush(None, DVec2::new(0.5 + 0.1 * s, 0.1 + 0.8 * s), 0.035, -1.0);
    } else if !*done {
        *done = true;
        let dir = save_dir();
        let saved = canvas.save(&dir);
        canvas.clear();
        let loaded = canvas.load(&dir);
        if let Err(e) = saved.and(loaded) {
            eprintln!("rwt-smoke: save and load in {}: {e}", dir.display());
            exit.write(AppExit::error());
            return;
        }
        println!(
            "rwt-smoke: painted maps saved to and loaded from {}",
            dir.display()
        );
    }
}

fn paint_input(
    keys: Res<ButtonInput<KeyCode>>,
    buttons: Res<ButtonInput<MouseButton>>,
    time: Res<Time>,
    windows: Query<&Window>,
    cameras: Query<(&Camera, &GlobalTransform)>,
    mut canvas: ResMut<Canvas>,
    mut brush: ResMut<Brush>,
) {
    for (i, key) in [
        KeyCode::Digit1,
        KeyCode::Digit2,
        KeyCode::Digit3,
        KeyCode::Digit4,
    ]
    .into_iter()
    .enumerate()
    {
        if keys.just_pressed(key) && i < canvas.setup.classes.len() {
            brush.class = i;
            brush.erase_all = false;
        }
    }
    if keys.just_pressed(KeyCode::KeyE) {
        brush.erase_all = !brush.erase_all;
    }
    if keys.just_pressed(KeyCode::BracketLeft) {
        *brush.radius() = (*brush.radius() / 1.25).max(0.005);
    }
    if keys.just_pressed(KeyCode::BracketRight) {
        *brush.radius() = (*brush.radius() * 1.25).min(0.5);
    }
    if keys.just_pressed(KeyCode::ArrowUp) {
        *brush.strength() = (*brush.strength() * 1.5).min(20.0);
    }
    if keys.just_pressed(KeyCode::ArrowDown) {
        *brush.strength() = (*brush.strength() / 1.5).max(0.05);
    }
    if keys.just_pressed(KeyCode::KeyC) {
        canvas.clear();
    }
    if keys.just_pressed(KeyCode::KeyS) {
        let dir = save_dir();
        canvas.status = match canvas.save(&dir) {
            Ok(()) => format!("saved to {}", dir.display()),
            Err(e) => format!("save failed: {e}"),
        };
    }
    if keys.just_pressed(KeyCode::KeyL) {
        let dir = save_dir();
        canvas.status = match canvas.load(&dir) {
            Ok(()) => format!("loaded from {}", dir.display()),
            Err(e) => format!("load failed: {e}"),
        };
    }
    let Some(p) = cursor_on_canvas(&windows, &cameras) else {
        return;
    };
    let p = p.as_dvec2();
    let amount = *brush.strength() * time.delta_secs();
    let radius = *brush.radius();
    let target = (!brush.erase_all).then_some(brush.class);
    if buttons.pressed(MouseButton::Left) {
        let sign = if brush.erase_all { -1.0 } else { 1.0 };
        canvas.brush(target, p, radius, sign * amount);
    } else if buttons.pressed(MouseButton::Right) {
        canvas.brush(target, p, radius, -amount);
    }
}

/// Where the cursor points on the canvas (world units), if it is over the window.
fn cursor_on_canvas(
    windows: &Query<&Window>,
    cameras: &Query<(&Camera, &GlobalTransform)>,
) -> Option<Vec2> {
    let cursor = windows.single().ok()?.cursor_position()?;
    let (camera, at) = cameras.single().ok()?;
    camera.viewport_to_world_2d(at, cursor).ok()
}

/// Uploads the painted maps into the images the layer reads, and tells the plugin which
/// region changed: only the chunks under it re-scatter.
fn upload_maps(
    mut canvas: ResMut<Canvas>,
    mut images: ResMut<Assets<Image>>,
    mut painted: MessageWriter<DensityMapPainted>,
) {
    let Some(region) = canvas.dirty.take() else {
        return;
    };
    for (map, handle) in canvas.maps.iter().zip(&canvas.images) {
        let Some(mut image) = images.get_mut(handle) else {
            continue;
        };
        image.data = Some(map.iter().map(|v| (v * 255.0).round() as u8).collect());
        painted.write(DensityMapPainted {
            image: handle.id(),
            region,
        });
    }
}

/// Space: white noise with the same densities (rejection sampling) instead of the layer.
fn compare_with_random(
    mut commands: Commands,
    mut canvas: ResMut<Canvas>,
    keys: Res<ButtonInput<KeyCode>>,
    mut shown: Local<bool>,
) {
    if keys.just_pressed(KeyCode::Space) {
        canvas.random = !canvas.random;
    }
    if canvas.random == *shown && !(canvas.random && canvas.is_changed()) {
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
    let total: f64 = canvas.setup.classes.iter().map(|c| c.max_density).sum();
    let n = canvas.setup.map_size;
    for k in 0..total as u64 {
        let h = |salt| unit_f64(hash_words(canvas.setup.seed, &[k, salt]));
        let p = DVec2::new(h(1), h(2));
        let texel = ((1.0 - p.y) * n as f64) as usize * n + (p.x * n as f64) as usize;
        let mut u = h(3) * total;
        for (class, c) in canvas.setup.classes.iter().enumerate() {
            let v = canvas.maps[class][texel.min(n * n - 1)] as f64 * c.max_density;
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

/// The maps, tinted by class over white, behind the textons.
fn show_maps(canvas: Res<Canvas>, mut images: ResMut<Assets<Image>>) {
    if !canvas.is_changed() {
        return;
    }
    let Some(mut image) = images.get_mut(&canvas.overlay) else {
        return;
    };
    let Some(data) = image.data.as_mut() else {
        return;
    };
    let n = canvas.setup.map_size;
    for (i, px) in data.chunks_exact_mut(4).enumerate().take(n * n) {
        let mut rgb = Vec3::splat(1.0);
        for (c, map) in canvas.setup.classes.iter().zip(&canvas.maps) {
            let w = map[i] * 0.45;
            rgb = rgb.lerp(Vec3::from_array(c.tint), w);
        }
        px.copy_from_slice(&[
            (rgb.x * 255.0) as u8,
            (rgb.y * 255.0) as u8,
            (rgb.z * 255.0) as u8,
            255,
        ]);
    }
}

fn hud(
    canvas: Res<Canvas>,
    brush: Res<Brush>,
    live: Res<LiveInstances>,
    windows: Query<&Window>,
    cameras: Query<(&Camera, &GlobalTransform)>,
    mut gizmos: Gizmos,
    mut hud: ResMut<Hud>,
) {
    let names: Vec<String> = canvas
        .setup
        .classes
        .iter()
        .enumerate()
        .map(|(i, c)| {
            let mark = if i == brush.class && !brush.erase_all {
                ">"
            } else {
                " "
            };
            format!("{mark}{} {}", i + 1, c.name)
        })
        .collect();
    hud.lines = vec![
        "rwt paint_density: left paint, right erase, 1-4 class, E erase all, [ ] size, Up/Down strength".into(),
        "Space random/blue noise, C clear, S save, L load".into(),
        format!(
            "{}   brush {:.3}, strength {:.2}{}",
            names.join("  "),
            brush.radius[brush.class],
            brush.strength[brush.class],
            if brush.erase_all { ", ERASER" } else { "" }
        ),
        format!(
            "{}: {} textons   {}",
            if canvas.random { "random (white noise)" } else { "blue noise (rwt)" },
            live.0,
            canvas.status
        ),
    ];
    if let Some(at) = cursor_on_canvas(&windows, &cameras) {
        let radius = brush.radius[brush.class] as f32;
        gizmos.circle_2d(at, radius, Color::srgb(0.2, 0.2, 0.2));
    }
}
