//! The server: headless (no window, no renderer, nothing streamed), listening on UDP. It
//! checks each player's world, applies the chops it allows and sends them on, places the
//! cabins players ask for, and saves the world (edits and cabins) to its folder, from which
//! it starts again. A save that does not load is kept as it is and the server stops: it
//! never overwrites a world it could not read.
//!
//! Lines for the launcher (and a log): `rwt-multiplayer-server: listening on ADDRESS`,
//! `... restored SUMMARY` (or `... new world at DIR`), `... world SUMMARY` when the world
//! changed, `... saved SUMMARY` when it is on disk.

use crate::options::ServerOptions;
use crate::world::{
    CabinRequest, MAX_CABINS, PROTOCOL_ID, WorldState, WorldSummary, connection_config,
    net_plugins, spawn_undrawn_layers,
};
use bevy::app::ScheduleRunnerPlugin;
use bevy::log::LogPlugin;
use bevy::prelude::*;
use bevy::state::app::StatesPlugin;
use bevy_replicon::prelude::*;
use bevy_replicon_renet::RenetServer;
use bevy_replicon_renet::netcode::{NetcodeServerTransport, ServerAuthentication, ServerConfig};
use bevy_rwt::prelude::*;
use bevy_rwt::save::SaveSystems;
use rwt_examples::terrain::Terrain;
use rwt_examples::world::TERRAIN_SEED;
use rwt_examples::world::layers::Detail;
use std::error::Error;
use std::net::{Ipv4Addr, UdpSocket};
use std::path::{Path, PathBuf};
use std::time::{Duration, SystemTime};

/// The server's frame rate.
const TICKS_PER_SECOND: f64 = 60.0;
/// Least time between two saves (seconds).
const SAVE_EVERY: f32 = 0.5;
/// The largest cabins file the server reads (bytes; 64 cabins take about 4 KiB).
const MAX_CABINS_FILE: u64 = 64 * 1024;

/// Runs the server until it is stopped (or fails to start).
pub fn run(options: ServerOptions) -> AppExit {
    let mut app = App::new();
    let tick = Duration::from_secs_f64(1.0 / TICKS_PER_SECOND);
    app.add_plugins((
        MinimalPlugins.set(ScheduleRunnerPlugin::run_loop(tick)),
        AssetPlugin::default(),
        LogPlugin::default(),
        StatesPlugin,
    ))
    // The layers are built as a player's are: from meshes and materials nobody draws.
    .init_asset::<Mesh>()
    .init_asset::<StandardMaterial>()
    .add_plugins(RwtPlugins::default());
    net_plugins(&mut app);
    app.insert_resource(Terrain::new(TERRAIN_SEED))
        .insert_resource(Detail(options.detail))
        .insert_resource(Saving::new(options.save))
        .insert_resource(Port(options.port))
        .add_systems(
            Startup,
            (
                spawn_undrawn_layers,
                listen,
                restore.run_if(resource_exists::<RenetServer>),
            )
                .chain(),
        )
        .add_systems(
            Update,
            (place_cabins, restored, note_changes, save, saved)
                .chain()
                .after(SaveSystems),
        );
    app.run()
}

#[derive(Resource)]
struct Port(u16);

/// A cabin the server placed (what its save holds).
#[derive(Component)]
struct Cabin(CabinRequest);

/// Where the world is saved, and whether it must be.
#[derive(Resource)]
struct Saving {
    dir: PathBuf,
    /// The save was read back (or there was none): from now on the world may be saved
    /// over it. Never set when it did not load.
    restored: bool,
    /// The world changed since the last save.
    dirty: bool,
    /// The world a save was asked for, until it is answered.
    in_flight: Option<WorldSummary>,
    /// Seconds since the last save was asked for.
    since: f32,
}

impl Saving {
    fn new(dir: PathBuf) -> Self {
        Self {
            dir,
            restored: false,
            dirty: false,
            in_flight: None,
            since: SAVE_EVERY,
        }
    }

    /// The edits' folder (a save of the save module).
    fn edits(&self) -> PathBuf {
        self.dir.join("edits")
    }

    /// The cabins' file.
    fn cabins(&self) -> PathBuf {
        self.dir.join("cabins.ron")
    }
}

/// Listens on 127.0.0.1; stops the app when the port cannot be had.
fn listen(
    port: Res<Port>,
    channels: Res<RepliconChannels>,
    mut commands: Commands,
    mut exit: MessageWriter<AppExit>,
) {
    match open(port.0, &channels) {
        Ok((server, transport)) => {
            println!("rwt-multiplayer-server: listening on 127.0.0.1:{}", port.0);
            commands.insert_resource(server);
            commands.insert_resource(transport);
        }
        Err(error) => {
            eprintln!(
                "rwt-multiplayer-server: cannot listen on port {}: {error}",
                port.0
            );
            exit.write(AppExit::error());
        }
    }
}

fn open(
    port: u16,
    channels: &RepliconChannels,
) -> Result<(RenetServer, NetcodeServerTransport), Box<dyn Error>> {
    let socket = UdpSocket::bind((Ipv4Addr::LOCALHOST, port))?;
    let config = ServerConfig {
        current_time: SystemTime::now().duration_since(SystemTime::UNIX_EPOCH)?,
        max_clients: 16,
        protocol_id: PROTOCOL_ID,
        authentication: ServerAuthentication::Unsecure,
        public_addresses: vec![socket.local_addr()?],
    };
    let transport = NetcodeServerTransport::new(config, socket)?;
    Ok((RenetServer::new(connection_config(channels)), transport))
}

/// Starts from the save, if there is one: its cabins now, its edits through the save
/// module (answered in [`restored`]).
fn restore(
    mut saving: ResMut<Saving>,
    terrain: Res<Terrain>,
    mut loads: MessageWriter<LoadWorld>,
    mut exit: MessageWriter<AppExit>,
    mut commands: Commands,
) {
    match read_cabins(&saving.cabins()) {
        Ok(cabins) => {
            for request in cabins {
                spawn_cabin(&mut commands, &terrain, request);
            }
        }
        Err(error) => {
            let path = saving.cabins();
            eprintln!(
                "rwt-multiplayer-server: the save's cabins do not load, and it is kept as it is: {}: {error}",
                path.display()
            );
            exit.write(AppExit::error());
            return;
        }
    }
    if saving.edits().exists() {
        loads.write(LoadWorld::from(saving.edits()));
    } else {
        println!(
            "rwt-multiplayer-server: new world at {}",
            saving.dir.display()
        );
        saving.restored = true;
    }
}

/// The saved cabins (none when there is no file); every one valid, at most
/// [`MAX_CABINS`].
fn read_cabins(path: &Path) -> Result<Vec<CabinRequest>, Box<dyn Error>> {
    let Ok(meta) = std::fs::metadata(path) else {
        return Ok(Vec::new());
    };
    if meta.len() > MAX_CABINS_FILE {
        return Err(format!("{} bytes, over the limit of {MAX_CABINS_FILE}", meta.len()).into());
    }
    let cabins: Vec<CabinRequest> = ron::from_str(&std::fs::read_to_string(path)?)?;
    if cabins.len() > MAX_CABINS {
        return Err(format!("{} cabins, over the limit of {MAX_CABINS}", cabins.len()).into());
    }
    if let Some(bad) = cabins.iter().find(|c| !c.is_valid()) {
        return Err(format!("a cabin off the map: {bad:?}").into());
    }
    Ok(cabins)
}

fn spawn_cabin(commands: &mut Commands, terrain: &Terrain, request: CabinRequest) {
    commands.spawn((Cabin(request), request.footprint(terrain), Replicated));
}

/// Places the cabins players ask for (valid, and while there are fewer than
/// [`MAX_CABINS`]).
fn place_cabins(
    mut requests: MessageReader<FromClient<CabinRequest>>,
    cabins: Query<(), With<Cabin>>,
    terrain: Res<Terrain>,
    mut commands: Commands,
) {
    let mut count = cabins.iter().count();
    for FromClient { client_id, message } in requests.read() {
        if !message.is_valid() || count >= MAX_CABINS {
            warn!("cabin refused ({count} placed): {message:?} from {client_id:?}");
            continue;
        }
        spawn_cabin(&mut commands, &terrain, *message);
        count += 1;
    }
}

/// The save's edits are back (or do not load: then the server stops, the save untouched).
fn restored(
    mut loaded: MessageReader<WorldLoaded>,
    world: WorldState,
    mut saving: ResMut<Saving>,
    mut exit: MessageWriter<AppExit>,
) {
    for answer in loaded.read() {
        match &answer.result {
            Ok(_) => {
                println!("rwt-multiplayer-server: restored {}", world.summary());
                saving.restored = true;
            }
            Err(error) => {
                eprintln!(
                    "rwt-multiplayer-server: the save's edits do not load, and it is kept as it is: {error}"
                );
                exit.write(AppExit::error());
            }
        }
    }
}

/// Prints the world when it changed, and marks it to be saved.
fn note_changes(mut world: WorldState, mut saving: ResMut<Saving>) {
    if world.changed() {
        println!("rwt-multiplayer-server: world {}", world.summary());
        saving.dirty = true;
    }
}

/// Saves a changed world, at most every [`SAVE_EVERY`] seconds: the cabins (written
/// atomically), then the edits through the save module (one transaction).
fn save(
    time: Res<Time<Real>>,
    mut saving: ResMut<Saving>,
    cabins: Query<&Cabin>,
    world: WorldState,
    mut saves: MessageWriter<SaveWorld>,
) {
    saving.since += time.delta_secs();
    let waiting = saving.in_flight.is_some() || saving.since < SAVE_EVERY;
    if !saving.restored || !saving.dirty || waiting {
        return;
    }
    saving.since = 0.0;
    let list: Vec<CabinRequest> = cabins.iter().map(|c| c.0).collect();
    if let Err(error) = write_cabins(&saving.dir, &saving.cabins(), &list) {
        error!("the cabins are not saved: {error}");
        return;
    }
    saves.write(SaveWorld::to(saving.edits()));
    saving.dirty = false;
    saving.in_flight = Some(world.summary());
}

fn write_cabins(dir: &Path, path: &Path, cabins: &[CabinRequest]) -> Result<(), Box<dyn Error>> {
    let text = ron::ser::to_string_pretty(cabins, default())?;
    std::fs::create_dir_all(dir)?;
    bevy_rwt::rwt_core::files::write_atomic(path, text.as_bytes())?;
    Ok(())
}

/// The save module's answer.
fn saved(mut answers: MessageReader<WorldSaved>, mut saving: ResMut<Saving>) {
    for answer in answers.read() {
        let summary = saving.in_flight.take();
        match (&answer.result, summary) {
            (Ok(_), Some(summary)) => println!("rwt-multiplayer-server: saved {summary}"),
            (Ok(_), None) => {}
            (Err(error), _) => {
                error!("the world is not saved: {error}");
                saving.dirty = true;
            }
        }
    }
}
