//! Instanced grass inside Bevy's renderer, checked on screen (`scripts/smoke.sh` runs it
//! under Xvfb and lavapipe): `cargo run --example instanced_passes`.
//!
//! A field of tall instanced grass, a box beside it, a few stiff textured cards lying on
//! the ground (`bend_response` 0) and a low sun, drawn without multisampling (lavapipe shades
//! every sample on the CPU) but in step 4. Six screenshots of the same scene, each compared
//! region by region:
//! 1. shadows on: the reference; each card (found by picking) shows its texture's red disc
//!    at its centre and the ground at its corners, where the texture's alpha cuts it out;
//! 2. the sun's shadows off: the grass the box shades must be brighter there, so the
//!    grass receives shadows;
//! 3. the grass class's shadows off ([`InstancedShadows::Off`]): the bare ground just
//!    behind the field (away from the sun) must be brighter there, so the grass casts;
//! 4. 4x MSAA with depth, normal and motion-vector prepasses: the grass must still be drawn
//!    (its region unlike the bare ground), its pipelines made for four samples;
//! 5. the same prepasses with TAA and SSAO (and MSAA off, as they need): the grass must
//!    still be drawn and the image not blank;
//! 6. a [`Bender`] standing in the grass and another on the cards: the blades around the
//!    first must lie down (the pixels around it change much more than pixels of grass far
//!    from it), and the cards must not move (their class does not respond: its pipelines
//!    compile without the bend field).
//!
//! It prints `rwt-passes: cards C cut out K, receive lit L shadowed S, cast off L on S,
//! multisampled grass G ground B, prepass grass G ground B, bent near N far F stiff T`
//! (cards drawn and cut out as their texture says; mean luminances, 0..255; mean pixel
//! changes for the benders) and exits with an error when a check fails. Screenshots go to
//! `RWT_PASSES_DIR` (default `target/passes`).

use bevy::anti_alias::taa::TemporalAntiAliasing;
use bevy::app::AppExit;
use bevy::core_pipeline::prepass::{DepthPrepass, MotionVectorPrepass, NormalPrepass};
use bevy::light::CascadeShadowConfigBuilder;
use bevy::pbr::ScreenSpaceAmbientOcclusion;
use bevy::prelude::*;
use bevy::render::view::screenshot::{Screenshot, ScreenshotCaptured};
use bevy_rwt::look::blade_mesh;
use bevy_rwt::prelude::*;
use bevy_rwt::rwt_core::density::Density;
use glam::DVec2;
use rwt_examples::prelude::*;
use rwt_examples::smoke::{BLANK_VARIANCE, luminance_variance};
use std::path::PathBuf;
use std::sync::Arc;

/// The grass field: x in 0..6, z in -6..6 (metres), under a sun from +x.
const FIELD: (DVec2, DVec2) = (DVec2::new(0.0, -6.0), DVec2::new(6.0, 6.0));
/// Ground points compared: grass the box shades, and bare ground the grass shades.
const UNDER_BOX: Vec3 = Vec3::new(4.3, 0.35, 0.0);
const BEHIND_GRASS: Vec3 = Vec3::new(-0.45, 0.0, 2.5);
/// Where the textured cards lie (a few in a small square, a bender at its centre), their
/// side and height.
const CARDS: (DVec2, DVec2) = (DVec2::new(-3.6, -1.6), DVec2::new(-2.4, -0.4));
const ON_CARDS: Vec3 = Vec3::new(
    ((CARDS.0.x + CARDS.1.x) / 2.0) as f32,
    CARD_HEIGHT,
    ((CARDS.0.y + CARDS.1.y) / 2.0) as f32,
);
const CARD: f32 = 0.8;
const CARD_HEIGHT: f32 = 0.05;
/// Where the bender stands, and grass far from it.
const BENDER: Vec3 = Vec3::new(2.0, 0.0, 2.0);
const FAR_GRASS: Vec3 = Vec3::new(3.5, 0.6, -3.5);
/// Half-size of each compared region, pixels of a 1280-pixel-wide window.
const REGION: i32 = 5;
/// Streaming that covers the scene (everything lies within 20 m of the camera) and no more:
/// a handful of chunks, so that a replaced layer settles in a few frames.
const NEAR_SCENE: StreamingConfig = StreamingConfig {
    chunk_size: 8.0,
    load_distance: 30.0,
    unload_distance: 40.0,
    near_distance: 30.0,
};
/// Frames each step waits once streaming has settled (pipelines compile on the CPU).
const WAIT: u32 = 12;
/// Frames the first step with TAA waits: its history converges over tens of frames, and the
/// next step's comparison must see the bender, not the convergence.
const TAA_WAIT: u32 = 40;

fn frames_to_wait(step: Step) -> u32 {
    if step == Step::Prepasses {
        TAA_WAIT
    } else {
        WAIT
    }
}

fn main() -> AppExit {
    App::new()
        .add_plugins(example_plugins("rwt instanced_passes"))
        .add_plugins(RwtPlugins::default())
        .init_resource::<Check>()
        .add_systems(Startup, setup)
        .add_systems(Update, run_check)
        .run()
}

/// A constant density over a rectangle, none outside.
struct Rectangle {
    min: DVec2,
    max: DVec2,
    density: f64,
}

impl Density for Rectangle {
    fn density(&self, p: DVec2) -> f64 {
        let inside = p.cmpge(self.min).all() && p.cmplt(self.max).all();
        if inside { self.density } else { 0.0 }
    }

    fn max_over(&self, min: DVec2, max: DVec2) -> f64 {
        let meets = max.cmpge(self.min).all() && min.cmplt(self.max).all();
        if meets { self.density } else { 0.0 }
    }
}

fn setup(
    mut commands: Commands,
    mut meshes: ResMut<Assets<Mesh>>,
    mut materials: ResMut<Assets<StandardMaterial>>,
    mut images: ResMut<Assets<Image>>,
) {
    commands.spawn((
        Camera3d::default(),
        Msaa::Off,
        RwtViewer::all_around(),
        Transform::from_xyz(-5.0, 6.0, 9.0).looking_at(Vec3::new(2.0, 0.0, 0.5), Vec3::Y),
    ));
    commands.spawn((
        DirectionalLight {
            shadow_maps_enabled: true,
            illuminance: 12_000.0,
            ..default()
        },
        Transform::from_xyz(10.0, 7.0, 1.0).looking_at(Vec3::ZERO, Vec3::Y),
        // One cascade over the scene: a software driver draws every cascade on the CPU.
        CascadeShadowConfigBuilder {
            num_cascades: 1,
            maximum_distance: 40.0,
            ..default()
        }
        .build(),
    ));
    commands.spawn((
        Mesh3d(meshes.add(Plane3d::default().mesh().size(60.0, 60.0))),
        MeshMaterial3d(materials.add(Color::srgb(0.75, 0.72, 0.65))),
    ));
    commands.spawn((
        Mesh3d(meshes.add(Cuboid::new(1.5, 3.0, 1.5))),
        MeshMaterial3d(materials.add(Color::srgb(0.6, 0.3, 0.2))),
        Transform::from_xyz(7.2, 1.5, 0.0),
    ));
    let field = Rectangle {
        min: FIELD.0,
        max: FIELD.1,
        density: 300.0,
    };
    let mut grass = ScatterClass::instanced(
        LayerDensity::Custom(Arc::new(field)),
        meshes.add(blade_mesh(0.1, 0.72, 0.1)),
        InstancedShading {
            base_color: Color::srgb(0.12, 0.3, 0.05),
            tip_color: Color::srgb(0.5, 0.75, 0.2),
            ..default()
        },
    );
    grass.scale = 1.6;
    commands.insert_resource(RwtWind {
        strength: 0.0,
        ..default()
    });
    commands.spawn((
        Name::new("grass"),
        ScatterLayer::new(vec![grass])
            .with_seed(7)
            .with_streaming(NEAR_SCENE),
    ));
    let cards = ScatterClass::instanced(
        LayerDensity::Custom(Arc::new(Rectangle {
            min: CARDS.0,
            max: CARDS.1,
            density: 3.0,
        })),
        meshes.add(card_mesh()),
        InstancedShading {
            base_color: Color::WHITE,
            tip_color: Color::WHITE,
            color_variation: 0.0,
            texture: Some(images.add(disc_texture())),
            bend_response: 0.0,
            ..default()
        },
    );
    commands.spawn((
        Name::new("cards"),
        ScatterLayer::new(vec![cards])
            .with_seed(2)
            .with_streaming(NEAR_SCENE),
    ));
}

/// A square card lying flat just above the ground, with UVs.
fn card_mesh() -> Mesh {
    let h = CARD / 2.0;
    Mesh::new(
        bevy::mesh::PrimitiveTopology::TriangleList,
        bevy::asset::RenderAssetUsages::default(),
    )
    .with_inserted_attribute(
        Mesh::ATTRIBUTE_POSITION,
        vec![
            [-h, CARD_HEIGHT, -h],
            [h, CARD_HEIGHT, -h],
            [h, CARD_HEIGHT, h],
            [-h, CARD_HEIGHT, h],
        ],
    )
    .with_inserted_attribute(Mesh::ATTRIBUTE_NORMAL, vec![[0.0, 1.0, 0.0]; 4])
    .with_inserted_attribute(
        Mesh::ATTRIBUTE_UV_0,
        vec![[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]],
    )
    .with_inserted_indices(bevy::mesh::Indices::U16(vec![0, 2, 1, 0, 3, 2]))
}

/// A red disc on a transparent square.
fn disc_texture() -> Image {
    let n = 64u32;
    let mut data = Vec::with_capacity((n * n * 4) as usize);
    for y in 0..n {
        for x in 0..n {
            let d = Vec2::new(x as f32 + 0.5, y as f32 + 0.5).distance(Vec2::splat(n as f32 / 2.0));
            let inside = d < 0.35 * n as f32;
            data.extend_from_slice(&[220, 30, 30, if inside { 255 } else { 0 }]);
        }
    }
    rwt_examples::foliage::srgba_image(n, n, data)
}

/// Where the check stands.
#[derive(Resource)]
struct Check {
    step: Step,
    /// Frames since the step began.
    waited: u32,
    /// Mean luminances of the regions (under the box, behind the grass, grass) per
    /// screenshot.
    shots: Vec<[f32; 3]>,
    /// The screenshots before and with the bender, and where their regions are seen.
    bent: Vec<Image>,
    bent_regions: Vec<Vec2>,
    /// Cards seen, and those whose centre showed the texture and corners the ground.
    cards: (usize, usize),
    pending: Option<Arc<std::sync::Mutex<Option<Image>>>>,
    /// Frames and time since the first (for the log's step lines).
    frames: u32,
    started: std::time::Instant,
}

impl Default for Check {
    fn default() -> Self {
        Self {
            step: Step::default(),
            waited: 0,
            shots: Vec::new(),
            bent: Vec::new(),
            bent_regions: Vec::new(),
            cards: (0, 0),
            pending: None,
            frames: 0,
            started: std::time::Instant::now(),
        }
    }
}

#[derive(Clone, Copy, Debug, Default, PartialEq)]
enum Step {
    #[default]
    Reference,
    SunShadowsOff,
    GrassShadowsOff,
    Multisampled,
    Prepasses,
    Bent,
    Done,
}

/// What the check changes and reads.
#[derive(bevy::ecs::system::SystemParam)]
struct Scene<'w, 's> {
    stats: Res<'w, RwtStats>,
    camera: Query<'w, 's, (Entity, &'static Camera, &'static GlobalTransform)>,
    suns: Query<'w, 's, &'static mut DirectionalLight>,
    layers: Query<'w, 's, (Entity, &'static ScatterLayer)>,
    exit: MessageWriter<'w, AppExit>,
    picking: ScatterPicking<'w, 's>,
}

fn run_check(mut check: ResMut<Check>, mut scene: Scene, mut commands: Commands) {
    let settled = scene.stats.settled();
    check.waited += 1;
    check.frames += 1;
    if let Some(pending) = check.pending.clone() {
        let Some(image) = pending.lock().unwrap().take() else {
            return;
        };
        let Ok((_, camera, at)) = scene.camera.single() else {
            return;
        };
        let luminance = |p: Vec3| region_luminance(&image, camera, at, p);
        let grass = Vec3::new(3.0, 0.6, 3.0);
        check.shots.push([
            luminance(UNDER_BOX),
            luminance(BEHIND_GRASS),
            luminance(grass),
        ]);
        if matches!(check.step, Step::Prepasses | Step::Bent) {
            check.bent.push(image.clone());
            check.bent_regions = [BENDER + Vec3::Y * 0.3, FAR_GRASS, ON_CARDS]
                .iter()
                .filter_map(|p| camera.world_to_viewport(at, *p).ok())
                .collect();
        }
        if check.step == Step::Reference {
            check.cards = cards_cut_out(&image, camera, at, &scene.picking);
        }
        save(&image, check.step);
        check.pending = None;
        eprintln!(
            "rwt-passes: {:?} taken at frame {}, {:.1} s",
            check.step,
            check.frames,
            check.started.elapsed().as_secs_f32()
        );
        check.step = next(check.step, &mut scene, &mut commands);
        check.waited = 0;
        if check.step == Step::Done {
            let ok = report(&check);
            scene.exit.write(if ok {
                AppExit::Success
            } else {
                AppExit::error()
            });
        }
        return;
    }
    if settled && check.waited >= frames_to_wait(check.step) && check.step != Step::Done {
        let slot = Arc::new(std::sync::Mutex::new(None));
        let target = slot.clone();
        commands.spawn(Screenshot::primary_window()).observe(
            move |captured: On<ScreenshotCaptured>| {
                *target.lock().unwrap() = Some(captured.image.clone());
            },
        );
        check.pending = Some(slot);
    }
}

/// Every card (found by picking), and how many show the texture's red disc at their centre
/// and the ground at their four corners (cut out).
fn cards_cut_out(
    image: &Image,
    camera: &Camera,
    at: &GlobalTransform,
    picking: &ScatterPicking,
) -> (usize, usize) {
    let centre = ((CARDS.0 + CARDS.1) / 2.0).as_vec2();
    let cards = picking.near(centre, 2.0, &PickFilter::default().classes([0]));
    let red = |p: Vec3| {
        let Ok(c) = camera.world_to_viewport(at, p) else {
            return None;
        };
        let c = image.get_color_at(c.x as u32, c.y as u32).ok()?.to_srgba();
        Some(c.red > c.green + 0.2 && c.red > c.blue + 0.2)
    };
    // A corner over another card's disc shows red rightly: such corners are not judged.
    let disc = 0.35 * CARD;
    let over_a_disc = |p: Vec3, own: usize| {
        cards.iter().enumerate().any(|(i, other)| {
            let local = other
                .transform
                .compute_affine()
                .inverse()
                .transform_point3(p);
            i != own && local.xz().length() < disc * 1.2
        })
    };
    let cut = cards
        .iter()
        .enumerate()
        .filter(|(own, hit)| {
            let t = hit.transform;
            let on_card = |u: f32, v: f32| t.transform_point(Vec3::new(u, CARD_HEIGHT, v));
            let corner = 0.45 * CARD;
            let corners = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)]
                .map(|(u, v)| on_card(u * corner, v * corner))
                .map(|p| (over_a_disc(p, *own), red(p)));
            red(on_card(0.0, 0.0)) == Some(true)
                && corners
                    .iter()
                    .all(|(over, red)| *over || *red == Some(false))
        })
        .count();
    (cards.len(), cut)
}

/// Makes the change of the step after `step`, and returns it.
fn next(step: Step, scene: &mut Scene, commands: &mut Commands) -> Step {
    match step {
        Step::Reference => {
            for mut sun in &mut scene.suns {
                sun.shadow_maps_enabled = false;
            }
            Step::SunShadowsOff
        }
        Step::SunShadowsOff => {
            for mut sun in &mut scene.suns {
                sun.shadow_maps_enabled = true;
            }
            set_grass_shadows(scene, commands, InstancedShadows::Off);
            Step::GrassShadowsOff
        }
        Step::GrassShadowsOff => {
            set_grass_shadows(scene, commands, InstancedShadows::On);
            if let Ok((camera, ..)) = scene.camera.single() {
                commands.entity(camera).insert((
                    Msaa::Sample4,
                    DepthPrepass,
                    NormalPrepass,
                    MotionVectorPrepass,
                ));
            }
            Step::Multisampled
        }
        Step::Multisampled => {
            if let Ok((camera, ..)) = scene.camera.single() {
                commands.entity(camera).insert((
                    Msaa::Off,
                    TemporalAntiAliasing::default(),
                    ScreenSpaceAmbientOcclusion::default(),
                ));
            }
            Step::Prepasses
        }
        Step::Prepasses => {
            for at in [BENDER, ON_CARDS] {
                commands.spawn((
                    Transform::from_translation(at),
                    Bender {
                        radius: 1.5,
                        strength: 1.0,
                    },
                ));
            }
            Step::Bent
        }
        Step::Bent | Step::Done => Step::Done,
    }
}

/// Replaces the grass layer by one whose class casts as `shadows` says (a replaced layer
/// streams anew).
fn set_grass_shadows(scene: &mut Scene, commands: &mut Commands, shadows: InstancedShadows) {
    for (entity, layer) in &scene.layers {
        let mut layer = layer.clone();
        for class in &mut layer.classes {
            if let ClassLook::Instanced(look) = &mut class.look {
                look.material.shadows = shadows;
            }
        }
        commands.entity(entity).insert(layer);
    }
}

/// Half-size of a compared region in `image`: the same share of the view at any window size
/// (smoke runs render smaller windows).
fn region(image: &Image) -> i32 {
    (REGION * image.width() as i32 / 1280).max(2)
}

/// Mean luminance (0..255) of the pixels around where `p` is seen.
fn region_luminance(image: &Image, camera: &Camera, at: &GlobalTransform, p: Vec3) -> f32 {
    let Ok(centre) = camera.world_to_viewport(at, p) else {
        return f32::NAN;
    };
    let (w, h) = (image.width() as i32, image.height() as i32);
    let (cx, cy) = (centre.x as i32, centre.y as i32);
    let r = region(image);
    let mut sum = 0.0;
    let mut n = 0.0;
    for y in (cy - r).max(0)..(cy + r).min(h) {
        for x in (cx - r).max(0)..(cx + r).min(w) {
            if let Ok(c) = image.get_color_at(x as u32, y as u32) {
                let c = c.to_srgba();
                sum += 255.0 * (0.2126 * c.red + 0.7152 * c.green + 0.0722 * c.blue);
                n += 1.0;
            }
        }
    }
    if n > 0.0 { sum / n } else { f32::NAN }
}

fn save(image: &Image, step: Step) {
    let dir = std::env::var_os("RWT_PASSES_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from("target/passes"));
    let _ = std::fs::create_dir_all(&dir);
    let name = format!("{step:?}").to_lowercase();
    if let Ok(rgba) = image.clone().try_into_dynamic() {
        let _ = rgba.to_rgb8().save(dir.join(format!("{name}.png")));
    }
}

/// Prints the line; whether every check holds.
fn report(check: &Check) -> bool {
    let (
        [reference, sun_off, grass_off, multisampled, prepass, _],
        [straight, bent],
        [near, far, cards_at],
    ) = (
        check.shots.as_slice(),
        check.bent.as_slice(),
        check.bent_regions.as_slice(),
    )
    else {
        eprintln!(
            "rwt-passes: FAIL expected six screenshots, got {}",
            check.shots.len()
        );
        return false;
    };
    let change = |at: Vec2| region_change(straight, bent, at);
    let (bent_near, bent_far, stiff) = (change(*near), change(*far), change(*cards_at));
    let (cards, cut) = check.cards;
    println!(
        "rwt-passes: cards {cards} cut out {cut}, receive lit {:.1} shadowed {:.1}, cast off {:.1} on {:.1}, multisampled grass {:.1} ground {:.1}, prepass grass {:.1} ground {:.1}, bent near {bent_near:.1} far {bent_far:.1} stiff {stiff:.1}",
        sun_off[0],
        reference[0],
        grass_off[1],
        reference[1],
        multisampled[2],
        multisampled[1],
        prepass[2],
        prepass[1]
    );
    // Each check holds only when its comparison does (a NaN region fails it).
    let checks = [
        (
            cards > 0 && cut == cards,
            "a textured card does not show its texture, or is not cut out by its alpha",
        ),
        (
            reference[0] < 0.85 * sun_off[0],
            "the grass the box shades is not darker with the sun's shadows on",
        ),
        (
            reference[1] < 0.85 * grass_off[1],
            "the ground behind the grass is not darker when the grass casts shadows",
        ),
        (
            (multisampled[2] - multisampled[1]).abs() > 10.0,
            "with 4x MSAA and the prepasses the grass is not drawn",
        ),
        (
            (prepass[2] - prepass[1]).abs() > 10.0,
            "with the prepasses, TAA and SSAO the grass is not drawn",
        ),
        (
            not_blank(straight),
            "the screenshot with the prepasses, TAA and SSAO is blank",
        ),
        (
            bent_near > 12.0 && bent_near > 3.0 * bent_far,
            "the blades around the bender did not lie down",
        ),
        (
            stiff < 3.0 * bent_far.max(1.0),
            "the stiff cards moved under a bender",
        ),
    ];
    let mut ok = true;
    for (holds, what) in checks {
        if !holds {
            eprintln!("rwt-passes: FAIL {what}");
            ok = false;
        }
    }
    ok
}

/// Whether the smoke harness would take `image` for a rendered frame (not blank).
fn not_blank(image: &Image) -> bool {
    image
        .clone()
        .try_into_dynamic()
        .is_ok_and(|i| luminance_variance(&i.to_rgb8()) >= BLANK_VARIANCE)
}

/// Mean absolute change (0..255, over the channels) of the pixels around `at` from `a` to
/// `b`.
fn region_change(a: &Image, b: &Image, at: Vec2) -> f32 {
    let (cx, cy) = (at.x as i32, at.y as i32);
    let r = 3 * region(a);
    let mut sum = 0.0;
    let mut n = 0.0;
    for y in (cy - r).max(0)..(cy + r).min(a.height() as i32) {
        for x in (cx - r).max(0)..(cx + r).min(a.width() as i32) {
            if let (Ok(p), Ok(q)) = (
                a.get_color_at(x as u32, y as u32),
                b.get_color_at(x as u32, y as u32),
            ) {
                let (p, q) = (p.to_srgba(), q.to_srgba());
                sum += 255.0
                    * ((p.red - q.red).abs() + (p.green - q.green).abs() + (p.blue - q.blue).abs())
                    / 3.0;
                n += 1.0;
            }
        }
    }
    if n > 0.0 { sum / n } else { f32::NAN }
}
