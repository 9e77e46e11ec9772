//! Frames compared in a real renderer: screenshots captured by name into [`Captures`]
//! (and saved as PNG), their differences, and what the examples that check culling against
//! the frame drawn whole share.

use bevy::light::CascadeShadowConfigBuilder;
use bevy::platform::collections::HashMap;
use bevy::prelude::*;
use bevy::render::view::screenshot::{Screenshot, ScreenshotCaptured};
use bevy_rwt::prelude::*;
use bevy_rwt::testing::CullingCheck;
use std::path::PathBuf;

/// The frames captured so far, by name, and whether a capture is under way.
#[derive(Resource, Default)]
pub struct Captures {
    frames: HashMap<&'static str, image::RgbImage>,
    pending: bool,
}

impl Captures {
    /// The frame captured as `name`.
    pub fn get(&self, name: &str) -> Option<&image::RgbImage> {
        self.frames.get(name)
    }

    /// Whether a capture is under way.
    pub fn pending(&self) -> bool {
        self.pending
    }

    /// Captures the next frame as `name` and saves it as `name.png` in `dir`.
    pub fn capture(&mut self, commands: &mut Commands, name: &'static str, dir: PathBuf) {
        self.pending = true;
        commands.spawn(Screenshot::primary_window()).observe(
            move |captured: On<ScreenshotCaptured>, mut captures: ResMut<Captures>| {
                captures.pending = false;
                let Ok(image) = captured.image.clone().try_into_dynamic() else {
                    return;
                };
                let rgb = image.to_rgb8();
                let file = dir.join(format!("{name}.png"));
                if std::fs::create_dir_all(&dir).is_ok()
                    && let Err(error) = rgb.save(&file)
                {
                    eprintln!("cannot save {}: {error}", file.display());
                }
                captures.frames.insert(name, rgb);
            },
        );
    }
}

/// The folder named by the environment variable `var`, or `default`.
pub fn output_dir(var: &str, default: &str) -> PathBuf {
    std::env::var_os(var)
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(default))
}

/// Mean absolute difference of two images' channels (255 when their sizes differ).
pub fn mean_difference(a: &image::RgbImage, b: &image::RgbImage) -> f64 {
    if a.dimensions() != b.dimensions() {
        return 255.0;
    }
    let total: u64 = a
        .as_raw()
        .iter()
        .zip(b.as_raw())
        .map(|(x, y)| u64::from(x.abs_diff(*y)))
        .sum();
    total as f64 / a.as_raw().len().max(1) as f64
}

/// Pixels of which some channel differs by more than `by` (every pixel when the sizes
/// differ).
pub fn pixels_differing(a: &image::RgbImage, b: &image::RgbImage, by: u8) -> usize {
    if a.dimensions() != b.dimensions() {
        return a.pixels().len().max(b.pixels().len());
    }
    a.pixels()
        .zip(b.pixels())
        .filter(|(p, q)| p.0.iter().zip(q.0).any(|(x, y)| x.abs_diff(y) > by))
        .count()
}

/// The app of an example that compares frames: Bevy's and rwt's plugins, no wind (so that
/// two frames can match), the [`Captures`].
pub fn still_check_app(title: &str) -> App {
    let mut app = App::new();
    app.add_plugins(crate::example_plugins(title))
        .add_plugins(RwtPlugins::default())
        .insert_resource(RwtWind {
            strength: 0.0,
            ..default()
        })
        .init_resource::<Captures>();
    app
}

/// The app of an example that checks culling against the frame drawn whole: a
/// [`still_check_app`] whose chunks are drawn whole to begin with, and a [`CullingCheck`].
pub fn culling_check_app(title: &str) -> App {
    let mut app = still_check_app(title);
    app.insert_resource(InstanceCulling::PerChunk)
        .init_resource::<CullingCheck>();
    app
}

/// The multisampling of a camera whose frames are compared: none. Lavapipe shades every
/// sample on the CPU (without it a check runs about three times quicker), and the frames then
/// differ pixel by pixel, not smoothed under a threshold by the resolve.
pub const COMPARED_MSAA: Msaa = Msaa::Off;

/// Towards a sun 61 degrees up.
pub const HIGH_SUN: Vec3 = Vec3::new(1.0, 2.0, 0.5);

/// A sun towards `toward_sun` casting shadows into one cascade (a software driver draws every
/// cascade on the CPU).
pub fn spawn_shadow_sun(commands: &mut Commands, toward_sun: Vec3) -> Entity {
    commands
        .spawn((
            DirectionalLight {
                shadow_maps_enabled: true,
                ..default()
            },
            Transform::from_translation(toward_sun).looking_at(Vec3::ZERO, Vec3::Y),
            CascadeShadowConfigBuilder {
                num_cascades: 1,
                maximum_distance: 60.0,
                ..default()
            }
            .build(),
        ))
        .id()
}

/// Prints `PREFIX: FAIL what` for each failed check; whether none failed.
pub fn passed(prefix: &str, checks: &[(bool, &str)]) -> bool {
    for (_, what) in checks.iter().filter(|(failed, _)| *failed) {
        println!("{prefix}: FAIL {what}");
    }
    checks.iter().all(|(failed, _)| !failed)
}

/// Counts one more frame of a check that may take `patience` frames; past them prints
/// `PREFIX: FAIL no result in N frames`, asks the app to exit with an error and returns
/// true (the check gives up).
pub fn out_of_patience(
    frame: &mut u32,
    patience: u32,
    prefix: &str,
    exit: &mut MessageWriter<AppExit>,
) -> bool {
    *frame += 1;
    if *frame <= patience {
        return false;
    }
    eprintln!("{prefix}: FAIL no result in {patience} frames");
    exit.write(AppExit::error());
    true
}

/// The sky the checks that count an object's pixels clear to: a pixel of another colour is
/// the object's.
pub const CHECK_SKY: Color = Color::srgb(0.62, 0.75, 0.92);

/// A disc of constant density on the ground: where the checks scatter what they compare.
#[derive(Clone, Copy, Debug)]
pub struct Disc {
    /// Its centre.
    pub center: bevy::math::DVec2,
    /// Its radius.
    pub radius: f64,
    /// Points per square unit inside.
    pub density: f64,
}

impl bevy_rwt::rwt_core::density::Density for Disc {
    fn density(&self, p: bevy::math::DVec2) -> f64 {
        let inside = p.distance(self.center) <= self.radius;
        if inside { self.density } else { 0.0 }
    }

    fn max_over(&self, min: bevy::math::DVec2, max: bevy::math::DVec2) -> f64 {
        self.density(self.center.clamp(min, max))
    }
}

/// Whether a pixel shows something other than [`CHECK_SKY`]: a channel differs from the
/// sky's by more than `by` (of 255).
pub fn off_sky(p: &image::Rgb<u8>, by: u8) -> bool {
    let sky = CHECK_SKY.to_srgba().to_u8_array();
    p.0.iter().zip(sky).any(|(c, s)| c.abs_diff(s) > by)
}

/// Spawns `scene` at every instance the chunks draw, at its transform as the chunk holds it
/// (an asset class has one chunk entity per primitive: the first one's are every
/// instance); returns how many.
pub fn scene_per_instance(
    commands: &mut Commands,
    chunks: &Query<(&bevy_rwt::instancing::InstancedChunk, &Transform)>,
    scene: &Handle<bevy::world_serialization::WorldAsset>,
) -> usize {
    let mut seen = std::collections::HashSet::new();
    let mut count = 0;
    for (chunk, corner) in chunks {
        if !seen.insert(chunk.chunk) {
            continue;
        }
        for g in &chunk.buffer.instances {
            let transform = Transform {
                translation: corner.translation + Vec3::from_array(g.offset),
                rotation: g.rotation(),
                scale: Vec3::splat(g.scale),
            };
            commands.spawn((WorldAssetRoot(scene.clone()), transform));
            count += 1;
        }
    }
    count
}
