//! A game scene streamed by `bevy_rwt`: an unbounded hilly world (walk 10 km in any
//! direction: nothing is precomputed) with dense wind-blown grass and painted flower
//! meadows drawn from per-chunk instance buffers, ferns with textured fronds on the forest
//! floor, bushes, rocks and three tree species from glTF files the example writes (bark and
//! leaf-card trees with two levels of detail, normal-mapped rocks), drawn instanced,
//! forests at full density to the horizon (impostors from 350 m), and a density brush that
//! paints the flower and bush maps live.
//!
//! `cargo run --release --example open_world`
//! - WASD / arrows fly, Q / E down and up, Shift boosts, hold the right mouse button to
//!   look, the wheel sets the speed;
//! - B toggles the brush: left mouse paints, right erases, the wheel sizes it, T sets the
//!   strength, 1-4 choose the map, Z undoes, F5 saves the maps and the flower and bush
//!   layer files to `painted/` (or `RWT_PAINT_DIR`), F9 loads the maps;
//! - V toggles the wind, F the fade-in (see the popping it hides), G chunk outlines, O
//!   temporal anti-aliasing with ambient occlusion (on; off gives 4x MSAA instead);
//! - with the brush off, a left click chops the tree under the cursor (a stump stays), H
//!   places a cabin that clears the ground under it; F5 saves these edits with the maps;
//! - K walks on foot (a capsule that trunks, stumps and rocks stop; avian3d), K again flies;
//! - F1 hides the overlay (`RWT_HUD=off` starts without it).
//!
//! The camera culls what hills, trees and bushes hide (`OcclusionCulling`; `RWT_OCCLUSION=0`
//! draws it all); `RWT_COST=1` times the scripted view's frame culled so, drawn whole, and
//! drawn whole by a camera that still occludes Bevy's own meshes (`cost`).

mod cost;
mod gameplay;
mod play;
mod script;
mod walk;

use bevy::anti_alias::taa::TemporalAntiAliasing;
use bevy::pbr::ScreenSpaceAmbientOcclusion;
use bevy::prelude::*;
use bevy::render::occlusion_culling::OcclusionCulling;
use bevy::render::pipelined_rendering::PipelinedRenderingPlugin;
use bevy_rwt::brush::DensityBrush;
use bevy_rwt::prelude::*;
use rwt_examples::prelude::*;
use rwt_examples::terrain::Terrain;
use rwt_examples::world::{WorldScenePlugin, WorldSystems, layers, world_fog};

fn main() {
    let mut window = example_plugins("rwt open_world").build();
    if cost::requested() {
        // The render world's time is its own only when the worlds run one after the other.
        window = window.disable::<PipelinedRenderingPlugin>();
    }
    rwt_examples::pack::write_pack();
    App::new()
        .add_plugins((
            window,
            WorldScenePlugin,
            SmokePlugin,
            HudPlugin,
            FlyCameraPlugin,
            BrushStatusPlugin,
        ))
        .add_plugins((
            // Five layers stream at once: more generation tasks in flight per layer.
            RwtPlugins::default()
                .with_max_tasks(32)
                .build()
                .enable::<RwtGizmosPlugin>()
                .enable::<RwtBrushPlugin>(),
            gameplay::GameplayPlugin,
            walk::WalkPlugin,
            script::ScriptPlugin,
            cost::CostPlugin,
        ))
        .add_systems(Startup, (setup_camera, layers::setup_layers))
        .configure_sets(Update, WorldSystems.after(script::ScriptSystems))
        .add_systems(
            Update,
            (toggles, toggle_taa_ssao, hud).chain().after(WorldSystems),
        )
        .run();
}

/// The camera, flying over the world ([`WorldScenePlugin`] adds the sun, ground and water)
/// with TAA, SSAO and occlusion culling.
fn setup_camera(mut commands: Commands, terrain: Res<Terrain>, mut gizmos: ResMut<RwtGizmos>) {
    *gizmos = RwtGizmos {
        chunks: false,
        tiles: false,
        lift: 60.0,
    };
    let start = Vec2::ZERO;
    let camera = commands
        .spawn((
            Camera3d::default(),
            Projection::Perspective(PerspectiveProjection {
                far: 7000.0,
                ..default()
            }),
            Transform::from_xyz(start.x, terrain.height(start) + 40.0, start.y),
            FlyCamera {
                speed: 40.0,
                ..default()
            },
            RwtViewer::default(),
            world_fog(),
        ))
        .id();
    // TAA and SSAO read the depth, normal and motion-vector prepasses, which the instanced
    // grass takes part in (its sway included), and need MSAA off.
    commands.entity(camera).insert(taa_ssao());
    // Grass, trees and rocks behind hills are not drawn (the depth prepass TAA and SSAO
    // need is there anyway); `RWT_OCCLUSION=0` draws them.
    if std::env::var("RWT_OCCLUSION").map_or(true, |v| v != "0") {
        commands.entity(camera).insert(OcclusionCulling);
    }
}

/// V wind, F fade-in, G chunk outlines; the mouse is the brush's while it is on.
fn toggles(
    keys: Res<ButtonInput<KeyCode>>,
    brush: Res<DensityBrush>,
    mut gizmos: ResMut<RwtGizmos>,
    mut wind: ResMut<RwtWind>,
    mut fade: ResMut<RwtFadeIn>,
    mut cameras: Query<&mut FlyCamera>,
) {
    if keys.just_pressed(KeyCode::KeyG) {
        gizmos.chunks = !gizmos.chunks;
    }
    if keys.just_pressed(KeyCode::KeyV) {
        wind.strength = if wind.strength > 0.0 { 0.0 } else { 0.5 };
    }
    if keys.just_pressed(KeyCode::KeyF) {
        fade.0 = !fade.0;
    }
    for mut cam in &mut cameras {
        if cam.mouse == brush.enabled {
            cam.mouse = !brush.enabled;
        }
    }
}

/// O: TAA with SSAO (the default), or 4x MSAA without them (they cannot be combined).
fn toggle_taa_ssao(
    keys: Res<ButtonInput<KeyCode>>,
    mut commands: Commands,
    cameras: Query<(Entity, Has<TemporalAntiAliasing>), With<FlyCamera>>,
) {
    if !keys.just_pressed(KeyCode::KeyO) {
        return;
    }
    for (camera, taa) in &cameras {
        if taa {
            commands
                .entity(camera)
                .remove::<(TemporalAntiAliasing, ScreenSpaceAmbientOcclusion)>()
                .insert(Msaa::Sample4);
        } else {
            commands.entity(camera).insert(taa_ssao());
        }
    }
}

/// TAA and SSAO, and MSAA off (they cannot be combined with it).
fn taa_ssao() -> impl Bundle {
    (
        Msaa::Off,
        TemporalAntiAliasing::default(),
        ScreenSpaceAmbientOcclusion::default(),
    )
}

#[allow(clippy::too_many_arguments)]
fn hud(
    time: Res<Time>,
    stats: Res<RwtStats>,
    brush: Res<DensityBrush>,
    status: Res<BrushStatus>,
    wind: Res<RwtWind>,
    fade: Res<RwtFadeIn>,
    layers: Query<(&Name, &ScatterLayerStatus)>,
    camera: Query<(&Transform, &FlyCamera, Has<TemporalAntiAliasing>)>,
    mut hud: ResMut<Hud>,
    mut fps: Local<f32>,
) {
    let dt = time.delta_secs().max(1e-4);
    *fps = if *fps == 0.0 {
        1.0 / dt
    } else {
        *fps * 0.95 + 0.05 / dt
    };
    let Ok((t, cam, taa)) = camera.single() else {
        return;
    };
    let on = |b: bool| if b { "on" } else { "off" };
    let per_layer: Vec<String> = layers
        .iter()
        .map(|(name, s)| match (s.live_entities, s.live_instanced) {
            (n, 0) => format!("{name} {n}"),
            (0, m) => format!("{name} {m} inst."),
            (n, m) => format!("{name} {n} + {m} inst."),
        })
        .collect();
    hud.lines = vec![
        "WASD fly, Q/E down/up, right mouse look, wheel speed | B brush | click chops, H cabin, K walk | V wind, F fade, G chunks, O TAA".into(),
        format!(
            "position {:.0}, {:.0} m, altitude {:.0} m, speed {:.0} m/s",
            t.translation.x, t.translation.z, t.translation.y, cam.speed
        ),
        format!("live: {}", per_layer.join(", ")),
        format!(
            "entities {}  instanced {}  chunks {}  pending tasks {}  streaming {:.2} ms  {:.0} fps",
            stats.live_entities,
            stats.live_instanced,
            stats.loaded_chunks,
            stats.pending_tasks,
            stats.streaming_ms,
            *fps
        ),
        format!(
            "wind {}  fade-in {}  TAA+SSAO {}  {}",
            on(wind.strength > 0.0),
            on(fade.0),
            on(taa),
            brush_line(&brush, &status)
        ),
    ];
    if brush.enabled {
        hud.lines
            .push("wheel radius, T strength, Z undo, F5 save, F9 load, 1-4 map".into());
    }
}

fn brush_line(brush: &DensityBrush, status: &BrushStatus) -> String {
    if !brush.enabled {
        return "brush off (B)".into();
    }
    let names: Vec<String> = brush
        .targets
        .iter()
        .enumerate()
        .map(|(i, t)| {
            let mark = if i == brush.selected { "*" } else { "" };
            format!("{}{mark}{}", i + 1, t.name)
        })
        .collect();
    let last = status.line();
    format!(
        "brush: {} | radius {:.1} m, strength {} {last}",
        names.join(" "),
        brush.radius,
        brush.strength
    )
}
