//! The plugin group: every part in the schedule it is given (the brush too, ordered before
//! the streaming sets), parts disabled, parts used alone.

use crate::common::*;
use bevy::asset::AssetPlugin;
use bevy::ecs::schedule::ScheduleLabel;
use bevy::prelude::*;
use bevy_rwt::prelude::*;

/// A schedule the game runs itself (here: by hand).
#[derive(ScheduleLabel, Clone, Debug, PartialEq, Eq, Hash)]
struct Streamed;

fn headless<M>(plugins: impl bevy::app::Plugins<M>) -> App {
    let mut app = App::new();
    app.add_plugins((MinimalPlugins, AssetPlugin::default()))
        .add_plugins(plugins);
    app.finish();
    app.cleanup();
    app
}

fn entity_instances(app: &mut App) -> usize {
    app.world_mut()
        .query::<&ScatterEntity>()
        .iter(app.world())
        .count()
}

/// Runs `frames` frames, each followed by a run of `schedule` when given.
fn run(app: &mut App, frames: usize, schedule: Option<Streamed>) {
    for _ in 0..frames {
        app.update();
        if let Some(label) = &schedule {
            app.world_mut().run_schedule(label.clone());
        }
        std::thread::sleep(std::time::Duration::from_millis(1));
    }
}

/// Whether `schedule` still builds with `probe` added, ordered by `order`.
fn builds_with(
    app: &mut App,
    order: impl FnOnce(fn()) -> bevy::ecs::schedule::ScheduleConfigs<bevy::ecs::system::ScheduleSystem>,
) -> bool {
    fn probe() {}
    let world = app.world_mut();
    let mut schedule = world
        .resource_mut::<Schedules>()
        .remove(Streamed)
        .expect("the group made it");
    schedule.add_systems(order(probe));
    let built = schedule.initialize(world).is_ok();
    world.resource_mut::<Schedules>().insert(schedule);
    built
}

#[test]
fn every_part_runs_in_the_schedule_it_is_given_the_brush_first() {
    let mut app = headless(
        RwtPlugins::new(Streamed)
            .with_spawn_budget(50_000)
            .build()
            .enable::<RwtBrushPlugin>(),
    );
    spawn_viewer(&mut app, Vec3::ZERO);
    let (map, density) = blank_canvas(&mut app);
    let meadow = app.world_mut().spawn(layer(density)).id();
    app.world_mut().spawn(layer(LayerDensity::Constant(0.2)));
    app.world_mut().resource_mut::<DensityBrush>().targets =
        vec![NamedMap::new(meadow, 0, "meadow")];
    // `Update` alone streams nothing, and paints nothing.
    let dab = PaintDab {
        target: 0,
        centre: Vec2::ZERO,
        radius: 8.0,
        amount: 1.0,
    };
    let painted = |app: &App| {
        let image = app.world().resource::<Assets<Image>>().get(&map).unwrap();
        image
            .data
            .as_ref()
            .unwrap()
            .iter()
            .any(|&b| b != 0 && b != 255)
    };
    app.world_mut().write_message(dab);
    run(&mut app, 50, None);
    assert_eq!(entity_instances(&mut app), 0);
    assert!(!painted(&app));
    run(&mut app, 2_000, Some(Streamed));
    let live = app.world().resource::<RwtStats>().live_entities;
    assert!(live > 100, "{live}");
    assert_eq!(entity_instances(&mut app), live);
    app.world_mut().write_message(dab);
    run(&mut app, 1, Some(Streamed));
    assert!(painted(&app));
    // The brush paints before the viewers are read (a dab's chunks are planned in the
    // frame it lands), and the streaming sets follow in their order: a system after the
    // stats and before the brush would close a cycle.
    assert!(builds_with(&mut app, |p| p
        .after(RwtSystems::Stats)
        .into_configs()));
    assert!(!builds_with(&mut app, |p| p
        .after(RwtSystems::Stats)
        .before(BrushSystems)
        .into_configs()));
}

#[test]
fn disabled_parts_are_left_out_and_the_rest_streams() {
    let mut app = headless(
        RwtPlugins::default()
            .with_spawn_budget(50_000)
            .build()
            .disable::<RwtDiagnosticsPlugin>()
            .disable::<RwtLayersPlugin>(),
    );
    assert!(!app.world().contains_resource::<RwtStats>());
    assert!(
        !app.world()
            .contains_resource::<bevy_rwt::layers::file::NamedAssets>()
    );
    spawn_viewer(&mut app, Vec3::ZERO);
    app.world_mut().spawn(layer(LayerDensity::Constant(0.2)));
    run(&mut app, 1_000, None);
    assert!(entity_instances(&mut app) > 100);
}

#[test]
fn parts_work_alone_with_the_settings_the_app_gives() {
    let mut app = App::new();
    app.add_plugins((MinimalPlugins, AssetPlugin::default()))
        .insert_resource(RwtSettings {
            spawn_budget: 7,
            ..default()
        })
        .add_plugins((
            RwtViewersPlugin::new(Streamed),
            RwtStreamingPlugin::new(Streamed),
        ));
    app.finish();
    app.cleanup();
    spawn_viewer(&mut app, Vec3::ZERO);
    app.world_mut().spawn(layer(LayerDensity::Constant(0.2)));
    // The app's budget holds: seven spawns a frame.
    let mut before = 0;
    for _ in 0..20 {
        run(&mut app, 1, Some(Streamed));
        let now = entity_instances(&mut app);
        assert!(now - before <= 7, "{before} -> {now}");
        before = now;
    }
    run(&mut app, 2_000, Some(Streamed));
    assert!(entity_instances(&mut app) > 100);
}
