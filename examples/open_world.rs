//! Fly over an unbounded hilly world (walk 10 km in any direction: nothing is precomputed)
//! where trees, bushes and grass stream in around the camera: trees and grass from fractal
//! noise, bushes from a painted map (`assets/images/meadows.png`, 6 km across), all on a
//! noise height field, thinning out with distance (level of detail by density).
//!
//! `cargo run --release --example open_world`: WASD / arrows fly, Q / E down and up, hold
//! the right mouse button to look, the wheel sets the speed, Shift boosts, G toggles chunk
//! outlines.

use bevy::asset::RenderAssetUsages;
use bevy::mesh::{Indices, PrimitiveTopology};
use bevy::pbr::{DistanceFog, FogFalloff};
use bevy::prelude::*;
use bevy_rwt::instancing::blade_mesh;
use bevy_rwt::prelude::*;
use noise::{Fbm, MultiFractal, NoiseFn, Perlin};
use rwt_core::density::{NoiseDensity, NoiseParams};
use rwt_examples::prelude::*;
use std::sync::Arc;

const SKY: Color = Color::srgb(0.62, 0.74, 0.86);
/// Water level: valleys below it are lakes, where nothing grows.
const WATER: f32 = -30.0;
/// The ground mesh: a grid of this many cells a side, this wide, re-centred under the
/// camera when it has moved a tenth of the way to the edge.
const GROUND_CELLS: usize = 200;
const GROUND_SIZE: f32 = 5000.0;

fn main() {
    App::new()
        .insert_resource(ClearColor(SKY))
        .insert_resource(Terrain::new(2006))
        .add_plugins((
            example_plugins("rwt open_world"),
            SmokePlugin,
            HudPlugin,
            FlyCameraPlugin,
        ))
        .add_plugins((RwtPlugin::default(), RwtGizmosPlugin))
        .add_systems(Startup, (setup_scene, setup_layers))
        .add_systems(
            Update,
            (
                fly_script.run_if(|s: Res<Smoke>| s.active()),
                stay_above_ground,
                follow_ground,
                toggle_outlines,
                hud,
            )
                .chain(),
        )
        .run();
}

/// The height field: fBm of Perlin noise, about +-140 m over kilometre-wide hills.
#[derive(Resource, Clone)]
struct Terrain(Arc<Fbm<Perlin>>);

impl Terrain {
    fn new(seed: u32) -> Self {
        Self(Arc::new(Fbm::<Perlin>::new(seed).set_octaves(6)))
    }

    fn height(&self, p: Vec2) -> f32 {
        150.0 * self.0.get([p.x as f64 / 2200.0, p.y as f64 / 2200.0]) as f32
    }

    fn source(&self) -> HeightSource {
        let terrain = self.clone();
        HeightSource::Function(Arc::new(move |p| terrain.height(p)))
    }
}

#[derive(Component)]
struct Ground {
    centre: Vec2,
}

#[derive(Component)]
struct Water;

/// The world around the layers: camera, sun, sky light, ground and water.
fn setup_scene(
    mut commands: Commands,
    terrain: Res<Terrain>,
    mut meshes: ResMut<Assets<Mesh>>,
    mut materials: ResMut<Assets<StandardMaterial>>,
    mut gizmos: ResMut<RwtGizmos>,
) {
    *gizmos = RwtGizmos {
        chunks: false,
        tiles: false,
        lift: 60.0,
    };
    let start = Vec2::new(0.0, 0.0);
    commands.spawn((
        Camera3d::default(),
        Projection::Perspective(PerspectiveProjection {
            far: 4000.0,
            ..default()
        }),
        Transform::from_xyz(start.x, terrain.height(start) + 40.0, start.y),
        FlyCamera {
            speed: 40.0,
            ..default()
        },
        RwtViewer::default(),
        DistanceFog {
            color: SKY,
            falloff: FogFalloff::Linear {
                start: 900.0,
                end: 3000.0,
            },
            ..default()
        },
    ));
    commands.spawn((
        DirectionalLight {
            illuminance: 9000.0,
            ..default()
        },
        Transform::from_xyz(0.4, 1.0, 0.3).looking_at(Vec3::ZERO, Vec3::Y),
    ));
    commands.insert_resource(GlobalAmbientLight {
        brightness: 600.0,
        ..default()
    });
    commands.spawn((
        Ground {
            centre: Vec2::splat(f32::MAX),
        },
        Mesh3d(meshes.add(Plane3d::default().mesh().size(1.0, 1.0))),
        MeshMaterial3d(materials.add(StandardMaterial {
            perceptual_roughness: 0.95,
            ..default()
        })),
    ));
    commands.spawn((
        Water,
        Mesh3d(meshes.add(Plane3d::default().mesh().size(GROUND_SIZE, GROUND_SIZE))),
        MeshMaterial3d(materials.add(StandardMaterial {
            base_color: Color::srgb(0.16, 0.33, 0.45),
            perceptual_roughness: 0.3,
            ..default()
        })),
        Transform::from_xyz(0.0, WATER, 0.0),
    ));
}

/// The meshes and materials of the layers' classes.
struct Looks {
    conifer: (Handle<Mesh>, Handle<StandardMaterial>),
    broadleaf: (Handle<Mesh>, Handle<StandardMaterial>),
    bush: (Handle<Mesh>, Handle<StandardMaterial>),
    blade: (Handle<Mesh>, InstancedMaterial),
}

fn looks(meshes: &mut Assets<Mesh>, materials: &mut Assets<StandardMaterial>) -> Looks {
    let mut solid = |color: Color| {
        materials.add(StandardMaterial {
            base_color: color,
            perceptual_roughness: 0.9,
            ..default()
        })
    };
    let conifer = meshes
        .add(Mesh::from(Cone::new(2.2, 9.0).mesh().resolution(7)).translated_by(Vec3::Y * 5.0));
    let broadleaf = meshes.add(
        Sphere::new(3.0)
            .mesh()
            .ico(1)
            .unwrap()
            .scaled_by(Vec3::new(1.0, 1.25, 1.0))
            .translated_by(Vec3::Y * 5.5),
    );
    let bush = meshes.add(
        Sphere::new(0.9)
            .mesh()
            .ico(1)
            .unwrap()
            .scaled_by(Vec3::new(1.2, 0.7, 1.2))
            .translated_by(Vec3::Y * 0.4),
    );
    let blade = meshes.add(blade_mesh(0.09, 0.72, 0.12));

    Looks {
        conifer: (conifer, solid(Color::srgb(0.09, 0.24, 0.12))),
        broadleaf: (broadleaf, solid(Color::srgb(0.2, 0.36, 0.12))),
        bush: (bush, solid(Color::srgb(0.3, 0.42, 0.14))),
        blade: (blade, InstancedMaterial::default()),
    }
}

/// The vegetation: trees, bushes and grass, each a layer streamed by the plugin.
fn setup_layers(
    mut commands: Commands,
    terrain: Res<Terrain>,
    assets: Res<AssetServer>,
    mut meshes: ResMut<Assets<Mesh>>,
    mut materials: ResMut<Assets<StandardMaterial>>,
) {
    let looks = looks(&mut meshes, &mut materials);
    commands.spawn((Name::new("trees"), trees(&terrain, &looks)));
    commands.spawn((Name::new("bushes"), bushes(&terrain, &looks, &assets)));
    commands.spawn((Name::new("grass"), grass(&terrain, &looks)));
}

/// Trees: two classes sharing one blue-noise set, forests from noise.
fn trees(terrain: &Terrain, looks: &Looks) -> ScatterLayer {
    let forest = |seed| {
        NoiseDensity::new(NoiseParams {
            seed,
            frequency: 1.0 / 700.0,
            octaves: 4,
            base: -0.05,
            amplitude: 1.8,
            scale: 0.012,
        })
    };
    ScatterLayer::new(vec![
        ScatterClass::new(
            LayerDensity::Noise(forest(11)),
            looks.conifer.0.clone(),
            looks.conifer.1.clone(),
        ),
        ScatterClass::new(
            LayerDensity::Noise(forest(12)),
            looks.broadleaf.0.clone(),
            looks.broadleaf.1.clone(),
        ),
    ])
    .with_seed(1)
    .with_tile_size(128.0)
    .with_streaming(StreamingConfig {
        chunk_size: 128.0,
        load_distance: 1800.0,
        unload_distance: 2000.0,
        near_distance: 200.0,
    })
    .with_falloff(500.0, 1800.0)
    .with_height(terrain.source())
    .with_height_range(WATER + 1.0, 120.0)
    .with_max_slope(0.7)
}

/// Bushes: the painted map, 6 km across, up to 0.05 bushes per square metre.
fn bushes(terrain: &Terrain, looks: &Looks, assets: &AssetServer) -> ScatterLayer {
    ScatterLayer::new(vec![ScatterClass::new(
        LayerDensity::Image {
            image: assets.load("images/meadows.png"),
            min: Vec2::splat(-3000.0),
            size: Vec2::splat(6000.0),
            scale: 0.05,
        },
        looks.bush.0.clone(),
        looks.bush.1.clone(),
    )])
    .with_seed(2)
    .with_tile_size(64.0)
    .with_streaming(StreamingConfig {
        chunk_size: 64.0,
        load_distance: 500.0,
        unload_distance: 580.0,
        near_distance: 80.0,
    })
    .with_falloff(120.0, 500.0)
    .with_height(terrain.source())
    .with_height_range(WATER + 0.5, 200.0)
}

/// Grass blades, drawn from per-chunk instance buffers (no entity per blade), growing in
/// and out with the level of detail.
fn grass(terrain: &Terrain, looks: &Looks) -> ScatterLayer {
    let mut class = ScatterClass::instanced(
        LayerDensity::Noise(NoiseDensity::new(NoiseParams {
            seed: 3,
            frequency: 1.0 / 120.0,
            octaves: 3,
            base: 0.45,
            amplitude: 0.9,
            scale: 140.0,
        })),
        looks.blade.0.clone(),
        looks.blade.1.clone(),
    );
    class.scale_variation = 0.35;
    ScatterLayer::new(vec![class])
        .with_seed(3)
        .with_tile_size(4.0)
        .with_streaming(StreamingConfig {
            chunk_size: 16.0,
            load_distance: 120.0,
            unload_distance: 140.0,
            near_distance: 24.0,
        })
        .with_falloff(35.0, 115.0)
        .with_height(terrain.source())
        .with_height_range(WATER + 0.3, 90.0)
}

/// The smoke session's flight: 1.5 km along a gentle curve, 22 m above the ground, then
/// down to 2.5 m, in the grass.
fn fly_script(
    smoke: Res<Smoke>,
    terrain: Res<Terrain>,
    mut camera: Query<(&mut FlyCamera, &mut Transform)>,
) {
    // Three quarters of the session flying, the last quarter hovering down into the grass.
    let t = (smoke.progress() / 0.75).min(1.0);
    let landing = ((smoke.progress() - 0.75) / 0.2).clamp(0.0, 1.0);
    for (mut cam, mut transform) in &mut camera {
        cam.yaw = 0.6 * t;
        cam.pitch = -0.12 + 0.06 * landing;
        let along = 1500.0 * t;
        let p = Vec2::new(-along * (0.3 * t).sin(), -along * (0.3 * t).cos());
        let y = terrain.height(p).max(WATER) + 22.0 - 19.5 * landing;
        transform.translation = Vec3::new(p.x, y, p.y);
        transform.rotation = cam.rotation();
    }
}

fn stay_above_ground(terrain: Res<Terrain>, mut camera: Query<&mut Transform, With<FlyCamera>>) {
    for mut t in &mut camera {
        let ground = terrain.height(t.translation.xz()).max(WATER) + 3.0;
        if t.translation.y < ground {
            t.translation.y = ground;
        }
    }
}

/// Rebuilds the ground mesh (and moves the water) under the camera when it strays from the
/// mesh's centre; the grid stays on a fixed lattice, so only the far border changes.
fn follow_ground(
    terrain: Res<Terrain>,
    camera: Query<&Transform, With<FlyCamera>>,
    mut ground: Query<(&mut Ground, &Mesh3d), Without<Water>>,
    mut water: Query<&mut Transform, (With<Water>, Without<FlyCamera>)>,
    mut meshes: ResMut<Assets<Mesh>>,
) {
    let Ok(eye) = camera.single() else {
        return;
    };
    let spacing = GROUND_SIZE / GROUND_CELLS as f32;
    let here = (eye.translation.xz() / spacing).round() * spacing;
    for mut w in &mut water {
        w.translation.x = here.x;
        w.translation.z = here.y;
    }
    for (mut g, mesh) in &mut ground {
        if g.centre.distance(here) > GROUND_SIZE * 0.1 {
            g.centre = here;
            if let Some(mut m) = meshes.get_mut(&mesh.0) {
                *m = ground_mesh(&terrain, here);
            }
        }
    }
}

fn ground_mesh(terrain: &Terrain, centre: Vec2) -> Mesh {
    let n = GROUND_CELLS + 1;
    let spacing = GROUND_SIZE / GROUND_CELLS as f32;
    let origin = centre - Vec2::splat(GROUND_SIZE / 2.0);
    let mut positions = Vec::with_capacity(n * n);
    let mut normals = Vec::with_capacity(n * n);
    let mut colors = Vec::with_capacity(n * n);
    for j in 0..n {
        for i in 0..n {
            let p = origin + Vec2::new(i as f32, j as f32) * spacing;
            let h = terrain.height(p);
            let e = 2.0;
            let dx = terrain.height(p + Vec2::X * e) - terrain.height(p - Vec2::X * e);
            let dz = terrain.height(p + Vec2::Y * e) - terrain.height(p - Vec2::Y * e);
            let normal = Vec3::new(-dx, 2.0 * e, -dz).normalize();
            let steep = (1.0 - normal.y).clamp(0.0, 0.4) / 0.4;
            let high = ((h - 60.0) / 80.0).clamp(0.0, 1.0);
            let shore = ((WATER + 4.0 - h) / 4.0).clamp(0.0, 1.0);
            // Linear RGB.
            let grass = Vec3::new(0.07, 0.16, 0.035);
            let rock = Vec3::new(0.2, 0.18, 0.15);
            let sand = Vec3::new(0.45, 0.38, 0.22);
            let c = grass.lerp(rock, steep.max(high)).lerp(sand, shore);
            positions.push([p.x, h, p.y]);
            normals.push(normal.to_array());
            colors.push([c.x, c.y, c.z, 1.0]);
        }
    }
    let mut indices = Vec::with_capacity(GROUND_CELLS * GROUND_CELLS * 6);
    for j in 0..GROUND_CELLS {
        for i in 0..GROUND_CELLS {
            let a = (j * n + i) as u32;
            let (b, c, d) = (a + 1, a + n as u32, a + n as u32 + 1);
            indices.extend_from_slice(&[a, c, b, b, c, d]);
        }
    }
    Mesh::new(
        PrimitiveTopology::TriangleList,
        RenderAssetUsages::default(),
    )
    .with_inserted_attribute(Mesh::ATTRIBUTE_POSITION, positions)
    .with_inserted_attribute(Mesh::ATTRIBUTE_NORMAL, normals)
    .with_inserted_attribute(Mesh::ATTRIBUTE_COLOR, colors)
    .with_inserted_indices(Indices::U32(indices))
}

fn toggle_outlines(keys: Res<ButtonInput<KeyCode>>, mut gizmos: ResMut<RwtGizmos>) {
    if keys.just_pressed(KeyCode::KeyG) {
        gizmos.chunks = !gizmos.chunks;
    }
}

fn hud(
    time: Res<Time>,
    stats: Res<RwtStats>,
    live: Res<LiveInstances>,
    camera: Query<(&Transform, &FlyCamera)>,
    mut hud: ResMut<Hud>,
    mut fps: Local<f32>,
) {
    let dt = time.delta_secs().max(1e-4);
    *fps = if *fps == 0.0 {
        1.0 / dt
    } else {
        *fps * 0.95 + 0.05 / dt
    };
    let Ok((t, cam)) = camera.single() else {
        return;
    };
    hud.lines = vec![
        "rwt open_world: WASD fly, Q/E down/up, right mouse look, wheel speed, G chunks".into(),
        format!(
            "position {:.0} m, {:.0} m, altitude {:.0} m, speed {:.0} m/s",
            t.translation.x, t.translation.z, t.translation.y, cam.speed
        ),
        format!(
            "live instances {} entities + {} instanced   chunks {}   pending tasks {}",
            live.0, live.1, stats.loaded_chunks, stats.pending_tasks
        ),
        format!(
            "streaming {:.2} ms/frame   {:.0} fps",
            stats.streaming_ms, *fps
        ),
    ];
}
