//! A player: a window onto the open world, joined to the server, and joining again by
//! itself whenever the connection drops (unless the server refused it). A left click chops
//! the tree under the cursor and H asks the server for a cabin: both reach every player
//! through the server.
//!
//! Lines for the launcher (and a log): `rwt-multiplayer-client: NAME joined|offline|refused
//! ...` when that changes, `... NAME world SUMMARY` when its world changed.

use crate::options::ClientOptions;
use crate::world::{
    CabinRequest, PROTOCOL_ID, WorldState, connection_config, net_plugins, spawn_drawn_layers,
};
use bevy::prelude::*;
use bevy_replicon::prelude::*;
use bevy_replicon_renet::RenetClient;
use bevy_replicon_renet::netcode::{ClientAuthentication, NetcodeClientTransport};
use bevy_rwt::prelude::*;
use bevy_rwt_net::{NetClientStatus, NetFootprint};
use rwt_examples::cabin::{CabinPlugin, Cabins, cabin_ahead};
use rwt_examples::forest::{STUMP, TreeUnderCursor};
use rwt_examples::prelude::*;
use rwt_examples::terrain::Terrain;
use rwt_examples::world::layers::Detail;
use rwt_examples::world::{WorldScenePlugin, forest_edge_camera};
use std::error::Error;
use std::net::{Ipv4Addr, SocketAddr, UdpSocket};
use std::time::SystemTime;

/// Seconds between tries to reach the server while offline.
const RETRY: f32 = 2.0;
/// Where the players start: a meadow by a forest's edge near here.
const START: Vec2 = Vec2::new(-443.0, -1433.0);

/// Runs a player until its window closes; `script` adds what it does by itself.
pub fn run(options: ClientOptions, script: impl FnOnce(&mut App)) -> AppExit {
    rwt_examples::pack::write_pack();
    let mut app = App::new();
    let title = format!("rwt multiplayer: {}", options.name);
    app.add_plugins((
        example_plugins(&title),
        WorldScenePlugin,
        FlyCameraPlugin,
        HudPlugin,
        SmokePlugin,
        CabinPlugin,
    ))
    // Six layers stream at once: more generation tasks in flight per layer.
    .add_plugins(RwtPlugins::default().with_max_tasks(32));
    net_plugins(&mut app);
    app.insert_resource(Detail(options.detail))
        .insert_resource(Player {
            name: options.name,
            server: options.server,
            retry: Timer::from_seconds(RETRY, TimerMode::Repeating),
        })
        .add_systems(Startup, (spawn_drawn_layers, setup_camera))
        .add_systems(
            Update,
            (connect, chop_on_click, cabin_on_key, report, hud).chain(),
        )
        .add_observer(draw_cabin);
    script(&mut app);
    app.run()
}

/// This player: its name, its server, when to try to reach it again.
#[derive(Resource)]
pub struct Player {
    /// Its name.
    pub name: String,
    server: SocketAddr,
    retry: Timer,
}

fn setup_camera(mut commands: Commands, terrain: Res<Terrain>) {
    commands.spawn(forest_edge_camera(&terrain, START));
}

/// Connects at start, and again every [`RETRY`] seconds while offline, unless refused.
fn connect(
    time: Res<Time<Real>>,
    mut player: ResMut<Player>,
    client: Option<Res<RenetClient>>,
    status: Res<NetClientStatus>,
    channels: Res<RepliconChannels>,
    mut commands: Commands,
) {
    let online = client.as_ref().is_some_and(|c| !c.is_disconnected());
    if online || matches!(*status, NetClientStatus::Refused(_)) {
        player.retry.reset();
        return;
    }
    if client.is_some() && !player.retry.tick(time.delta()).just_finished() {
        return;
    }
    match open(player.server, &channels) {
        Ok((client, transport)) => {
            // Taken away first, so that the new client counts as added (and connects).
            commands.remove_resource::<RenetClient>();
            commands.remove_resource::<NetcodeClientTransport>();
            commands.insert_resource(client);
            commands.insert_resource(transport);
        }
        Err(error) => error!("cannot open a connection to {}: {error}", player.server),
    }
}

fn open(
    server: SocketAddr,
    channels: &RepliconChannels,
) -> Result<(RenetClient, NetcodeClientTransport), Box<dyn Error>> {
    let now = SystemTime::now().duration_since(SystemTime::UNIX_EPOCH)?;
    let socket = UdpSocket::bind((Ipv4Addr::UNSPECIFIED, 0))?;
    // Unique among the server's clients: the time, and this process.
    let client_id = (now.as_nanos() as u64) ^ ((std::process::id() as u64) << 40);
    let authentication = ClientAuthentication::Unsecure {
        client_id,
        protocol_id: PROTOCOL_ID,
        server_addr: server,
        user_data: None,
    };
    let transport = NetcodeClientTransport::new(now, authentication, socket)?;
    Ok((RenetClient::new(connection_config(channels)), transport))
}

/// Left click: the tree under the cursor becomes a stump (a request to the server, which
/// sends it back to every player once applied).
fn chop_on_click(
    buttons: Res<ButtonInput<MouseButton>>,
    cursor: TreeUnderCursor,
    mut edits: MessageWriter<EditInstance>,
) {
    if !buttons.just_pressed(MouseButton::Left) {
        return;
    }
    if let Some(hit) = cursor.tree() {
        edits.write(EditInstance::reclass(hit.layer, hit.id, STUMP));
    }
}

/// H: asks the server for a cabin ahead of the camera, its door towards the camera.
fn cabin_on_key(
    keys: Res<ButtonInput<KeyCode>>,
    camera: Query<&Transform, With<FlyCamera>>,
    mut requests: MessageWriter<CabinRequest>,
) {
    if !keys.just_pressed(KeyCode::KeyH) {
        return;
    }
    if let Ok(eye) = camera.single() {
        let (at, facing) = cabin_ahead(eye);
        requests.write(CabinRequest { at, facing });
    }
}

/// The server's cabins (their footprints arrive replicated) get the cabin's look.
fn draw_cabin(added: On<Add, NetFootprint>, cabins: Res<Cabins>, mut commands: Commands) {
    commands
        .entity(added.entity)
        .insert((cabins.look(), CountedInstance));
}

/// Prints where the player stands with the server when that changes, and its world when
/// that changes.
fn report(
    player: Res<Player>,
    status: Res<NetClientStatus>,
    mut world: WorldState,
    mut last: Local<Option<String>>,
) {
    let changed = world.changed();
    if status.is_changed() {
        // A player that joins again says so, and what its world is then.
        *last = None;
        match &*status {
            NetClientStatus::Offline if status.is_added() => {}
            NetClientStatus::Offline => report_line(&player, "offline"),
            NetClientStatus::Joining => {}
            NetClientStatus::Joined => report_line(&player, "joined"),
            NetClientStatus::Refused(why) => report_line(&player, &why.to_string()),
            NetClientStatus::Broken { layer, error } => {
                report_line(&player, &format!("broken join of {layer}: {error}"))
            }
        }
    }
    if *status != NetClientStatus::Joined || !(changed || status.is_changed()) {
        return;
    }
    let summary = world.summary().to_string();
    if last.as_ref() != Some(&summary) {
        report_line(&player, &format!("world {summary}"));
        *last = Some(summary);
    }
}

/// A line for the launcher: `rwt-multiplayer-client: NAME TEXT`.
pub fn report_line(player: &Player, text: &str) {
    println!("rwt-multiplayer-client: {} {text}", player.name);
}

/// The overlay: the player, the connection, the world, the keys.
fn hud(player: Res<Player>, status: Res<NetClientStatus>, world: WorldState, mut hud: ResMut<Hud>) {
    let server = player.server;
    let connection = match &*status {
        NetClientStatus::Offline => format!("offline: reaching {server} every {RETRY} s"),
        NetClientStatus::Joining => format!("joining {server}"),
        NetClientStatus::Joined => format!("joined {server}"),
        NetClientStatus::Refused(why) => why.to_string(),
        NetClientStatus::Broken { layer, error } => format!("broken join of {layer}: {error}"),
    };
    let (edits, cabins) = world.counts();
    hud.lines = vec![
        format!("{}: {connection}", player.name),
        format!("edits {edits}, cabins {cabins}"),
        "click: chop   H: cabin   right mouse: look   F1: hide".into(),
    ];
}
