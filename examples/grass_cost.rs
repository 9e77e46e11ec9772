//! What a field of grass costs the CPU in a real renderer, drawn by the instanced path or
//! with one entity per blade:
//!
//! `cargo run --release --example grass_cost -- instanced 1000000`
//! `cargo run --release --example grass_cost -- entities 1000000`
//!
//! A flat field holds about the given number of live blades (streamed by the plugin) around
//! a camera 2 m above it, under a sun with cascaded shadow maps. The instanced path is
//! timed in nine settings in one run: culled as `InstanceCulling::Auto` chooses, the grass
//! class's shadows off, on, and on within 30 m of the camera; shadows off, chunks drawn
//! whole (the direct path, `PerChunk`), culled per instance on the GPU (`PerInstance`), and
//! culled per instance with occlusion (the camera's depth prepass and `OcclusionCulling`);
//! `Auto` with open_world's forests around the field to 2.6 km, far trees as meshes with a
//! fifth of them kept from 1.4 km on (as drawing each tree as a mesh affords), then every
//! tree with impostors from 350 m; and `Auto` with the camera's depth, normal and
//! motion-vector prepasses on. The entity path is timed in the first only. In each, once streaming has settled and 10 frames have
//! warmed up, 30 frames are timed and one line is printed:
//!
//! `grass-cost: path=P shadows=S prepass=Q cull=C live=N main_ms=X/Y render_world_ms=X/Y frame_ms=X/Y`
//! (median/p95), then the frame-time ratios measured in the same run, to the first setting
//! and to the direct path:
//!
//! `grass-cost: frame_ms ratio shadows_on=R shadows_within_30m=R prepass_on=R`
//! `grass-cost: frame_ms ratio gpu_cull=R1 occlusion=R2 impostors=R3`
//!
//! (`impostors`: the full forest with impostors over the thinned forest of meshes.)
//!
//! `main_ms` is the main world's schedules (the plugin, transforms, visibility);
//! `render_world_ms` is extraction, preparation and queueing in the render world, from the
//! end of the main world's frame to the start of the render graph (pipelined rendering is
//! off, so the two run one after the other); `frame_ms` is the whole frame, including the
//! render graph and, with a software driver such as lavapipe, the drawing itself.

use bevy::core_pipeline::prepass::{DepthPrepass, MotionVectorPrepass, NormalPrepass};
use bevy::prelude::*;
use bevy::render::occlusion_culling::OcclusionCulling;
use bevy::render::pipelined_rendering::PipelinedRenderingPlugin;
use bevy_rwt::prelude::*;
use rwt_examples::forest::{FarTrees, tree_layer};
use rwt_examples::frame_clock::{FrameClock, FrameClockPlugin};
use rwt_examples::grass_field::{self, field_layer, nominal_density, set_instanced_shadows};
use rwt_examples::prelude::*;

/// Frames timed once streaming has settled.
const TIMED: usize = 30;
/// Frames run before, to warm up.
const WARM_UP: usize = 10;
/// The camera's prepasses in a setting.
#[derive(Clone, Copy, PartialEq)]
enum Prepass {
    None,
    /// Depth, normals and motion vectors.
    All,
    /// Depth, and occlusion culling.
    Occlusion,
}

/// One setting timed: the grass class's shadows, the camera's prepasses, the culling, and
/// the forests around the field, if any.
#[derive(Clone, Copy)]
struct Setting {
    shadows: InstancedShadows,
    prepass: Prepass,
    culling: InstanceCulling,
    forest: Option<FarTrees>,
}

const fn at(shadows: InstancedShadows, prepass: Prepass, culling: InstanceCulling) -> Setting {
    Setting {
        shadows,
        prepass,
        culling,
        forest: None,
    }
}

const fn with_forest(far: FarTrees) -> Setting {
    Setting {
        forest: Some(far),
        ..at(InstancedShadows::Off, Prepass::None, InstanceCulling::Auto)
    }
}

/// The settings timed, in order.
const SETTINGS: [Setting; 9] = {
    use InstanceCulling::*;
    use InstancedShadows::*;
    [
        at(Off, Prepass::None, Auto),
        at(On, Prepass::None, Auto),
        at(Within(30.0), Prepass::None, Auto),
        at(Off, Prepass::None, PerChunk),
        at(Off, Prepass::None, PerInstance),
        at(Off, Prepass::Occlusion, PerInstance),
        with_forest(FarTrees::Thinned),
        with_forest(FarTrees::Impostors),
        // Last: Bevy 0.19 keeps a view's background motion-vector pipeline once its motion
        // vector prepass is removed, and fails the next frame with a depth prepass.
        at(Off, Prepass::All, Auto),
    ]
};

fn main() {
    let mut args = std::env::args().skip(1);
    let entities = match args.next().as_deref() {
        Some("entities") => true,
        Some("instanced") | None => false,
        Some(other) => {
            eprintln!("usage: grass_cost [instanced|entities] [COUNT] (not {other:?})");
            std::process::exit(2);
        }
    };
    let count: f64 = args.next().and_then(|c| c.parse().ok()).unwrap_or(1.0e6);
    App::new()
        .add_plugins(
            example_plugins("rwt grass_cost")
                .build()
                .disable::<PipelinedRenderingPlugin>(),
        )
        .add_plugins((
            FrameClockPlugin,
            RwtPlugins::default()
                .with_spawn_budget(200_000)
                .with_max_tasks(16),
        ))
        .insert_resource(Field {
            entities,
            count,
            setting: 0,
            frame_ms: Vec::new(),
        })
        .add_systems(Startup, setup)
        .add_systems(Last, settle)
        .run();
}

/// The forests' layer.
#[derive(Component)]
struct Forest;

/// The trees' material.
#[derive(Resource)]
struct ForestMaterial(Handle<StandardMaterial>);

/// What to draw, the setting being timed and the median frame times of those timed.
#[derive(Resource)]
struct Field {
    entities: bool,
    count: f64,
    setting: usize,
    frame_ms: Vec<f64>,
}

fn setup(
    mut commands: Commands,
    field: Res<Field>,
    mut meshes: ResMut<Assets<Mesh>>,
    mut materials: ResMut<Assets<StandardMaterial>>,
) {
    commands.spawn((
        Camera3d::default(),
        RwtViewer::all_around(),
        grass_field::camera_transform(),
    ));
    grass_field::spawn_sun_and_ground(&mut commands, &mut meshes, &mut materials);
    let density = LayerDensity::Constant(nominal_density(field.count));
    let blade = meshes.add(grass_field::blade());
    let grass = if field.entities {
        let material = materials.add(StandardMaterial {
            base_color: Color::srgb(0.3, 0.5, 0.15),
            double_sided: true,
            cull_mode: None,
            ..default()
        });
        ScatterClass::new(density, blade, material)
    } else {
        let material = InstancedShading {
            shadows: SETTINGS[0].shadows,
            ..default()
        };
        ScatterClass::instanced(density, blade, material)
    };
    commands.spawn(field_layer(grass));
    commands.insert_resource(ForestMaterial(materials.add(StandardMaterial {
        perceptual_roughness: 0.9,
        reflectance: 0.2,
        ..default()
    })));
}

/// Waits for streaming to settle, warms up for [`WARM_UP`] frames, times [`TIMED`]
/// frames and prints them; then moves to the next setting, or prints the ratios and exits.
#[allow(clippy::too_many_arguments)]
fn settle(
    clock: Res<FrameClock>,
    stats: Res<RwtStats>,
    mut field: ResMut<Field>,
    mut settled_frames: Local<usize>,
    mut exit: MessageWriter<AppExit>,
    layers: Query<(Entity, &ScatterLayer, Has<Forest>)>,
    cameras: Query<Entity, With<Camera3d>>,
    mut commands: Commands,
    (mut meshes, forest_material): (ResMut<Assets<Mesh>>, Res<ForestMaterial>),
) {
    let live = stats.live_entities + stats.live_instanced;
    if *settled_frames == 0 && (stats.pending_tasks > 0 || stats.queued_spawns > 0 || live == 0) {
        return;
    }
    *settled_frames += 1;
    clock.record(*settled_frames > WARM_UP);
    if clock.recorded() < TIMED {
        return;
    }
    let times = clock.take();
    println!(
        "grass-cost: {} live={live} {times}",
        describe(field.entities, SETTINGS[field.setting]),
    );
    field.frame_ms.push(times.frame.median);
    *settled_frames = 0;
    field.setting += 1;
    if field.entities || field.setting == SETTINGS.len() {
        print_ratios(&field.frame_ms);
        exit.write(AppExit::Success);
        return;
    }
    let setting = SETTINGS[field.setting];
    apply(
        setting,
        &layers,
        &cameras,
        &mut commands,
        &mut meshes,
        &forest_material,
    );
}

/// A setting as the result line names it.
fn describe(entities: bool, setting: Setting) -> String {
    let path = if entities { "entities" } else { "instanced" };
    let shadows = match setting.shadows {
        InstancedShadows::Off => "off".to_string(),
        InstancedShadows::On => "on".to_string(),
        InstancedShadows::Within(d) => format!("within_{d}m"),
    };
    let prepass = match setting.prepass {
        Prepass::None => "off",
        Prepass::All => "on",
        Prepass::Occlusion => "depth",
    };
    let forest = match setting.forest {
        None => "",
        Some(FarTrees::Thinned) => " forest=thinned_meshes",
        Some(FarTrees::Impostors) => " forest=impostors",
    };
    let cull = match (setting.culling, setting.prepass) {
        (InstanceCulling::Auto, _) => "auto",
        (InstanceCulling::PerChunk, _) => "whole",
        (InstanceCulling::PerInstance, Prepass::Occlusion) => "occlusion",
        (InstanceCulling::PerInstance, _) => "gpu",
    };
    format!("path={path} shadows={shadows} prepass={prepass} cull={cull}{forest}")
}

/// The frame-time ratios, once every setting was timed.
fn print_ratios(frame_ms: &[f64]) {
    if let [
        base,
        on,
        within,
        whole,
        gpu,
        occlusion,
        thinned,
        impostors,
        prepass,
    ] = frame_ms[..]
    {
        println!(
            "grass-cost: frame_ms ratio shadows_on={:.2} shadows_within_30m={:.2} prepass_on={:.2}",
            on / base,
            within / base,
            prepass / base
        );
        println!(
            "grass-cost: frame_ms ratio gpu_cull={:.2} occlusion={:.2} impostors={:.2}",
            gpu / whole,
            occlusion / whole,
            impostors / thinned
        );
    }
}

/// Gives the grass class the setting's shadows (a replaced layer streams anew), the field
/// its forests, the camera its prepasses, and the culling its setting.
fn apply(
    setting: Setting,
    layers: &Query<(Entity, &ScatterLayer, Has<Forest>)>,
    cameras: &Query<Entity, With<Camera3d>>,
    commands: &mut Commands,
    meshes: &mut Assets<Mesh>,
    forest_material: &ForestMaterial,
) {
    for (entity, layer, forest) in layers {
        if forest {
            commands.entity(entity).despawn();
            continue;
        }
        let mut layer = layer.clone();
        set_instanced_shadows(&mut layer, setting.shadows);
        commands.entity(entity).insert(layer);
    }
    if let Some(far) = setting.forest {
        let flat = HeightSource::Constant(0.0);
        let forest = tree_layer(&flat, meshes, &forest_material.0, far);
        commands.spawn((Forest, forest));
    }
    for camera in cameras {
        let mut camera = commands.entity(camera);
        camera.remove::<(
            DepthPrepass,
            NormalPrepass,
            MotionVectorPrepass,
            OcclusionCulling,
        )>();
        match setting.prepass {
            Prepass::None => {}
            Prepass::All => {
                camera.insert((DepthPrepass, NormalPrepass, MotionVectorPrepass));
            }
            Prepass::Occlusion => {
                camera.insert((DepthPrepass, OcclusionCulling));
            }
        }
    }
    commands.insert_resource(setting.culling);
}
