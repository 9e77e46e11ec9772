//! Edits across the network, headless, with replicon's in-process connection (no transport):
//! a client's chops and the server's cabins reach every client, late joiners, reconnecting
//! clients and the clients of a server restarted from its save end with the server's world,
//! a mismatched client is refused with what differs (also when the server's world changes
//! under it), and hostile requests are refused and counted.

use bevy::prelude::*;
use bevy::state::app::StatesPlugin;
use bevy_replicon::prelude::*;
use bevy_replicon::test_app::{ServerTestAppExt, TestClientEntity};
use bevy_rwt::edits::{EditInstance, ScatterEdits};
use bevy_rwt::footprints::Footprint;
use bevy_rwt::prelude::*;
use bevy_rwt::rwt_core::query::PointId;
use bevy_rwt::testing::{headless_app_with, settle, spawn_viewer};
use bevy_rwt_net::*;
use std::collections::BTreeSet;

/// A layer of one class per density, entities drawn with default handles.
fn layer_of(densities: &[f64]) -> ScatterLayer {
    let class = |d: &f64| ScatterClass::new(LayerDensity::Constant(*d), default(), default());
    ScatterLayer::new(densities.iter().map(class).collect())
}

/// A peer whose world `spawn_layers` makes, with a viewer at the origin, settled.
fn peer_of(config: NetConfig, spawn_layers: impl FnOnce(&mut World)) -> App {
    let mut app = headless_app_with(RwtPlugins::default(), |app| {
        app.add_plugins((
            StatesPlugin,
            RepliconPlugins.set(ServerPlugin::new(PostUpdate)),
            RwtNetPlugin { config },
        ));
    });
    spawn_layers(app.world_mut());
    spawn_viewer(&mut app, Vec3::ZERO);
    assert!(settle(&mut app, 10_000));
    app
}

/// A world's layers: trees (and their stump class) and stones, named; `seed` is the trees'.
fn peer(seed: u64, config: NetConfig) -> App {
    peer_of(config, |world| {
        world.spawn((Name::new("trees"), layer_of(&[0.05, 0.0]).with_seed(seed)));
        world.spawn((Name::new("stones"), layer_of(&[0.02]).with_seed(9)));
    })
}

fn layer(app: &mut App, name: &str) -> Entity {
    let mut q = app.world_mut().query::<(Entity, &Name, &ScatterLayer)>();
    q.iter(app.world())
        .find(|(_, n, _)| n.as_str() == name)
        .map(|(e, ..)| e)
        .unwrap()
}

/// Every shown instance, by layer name, class and identity.
fn shown(app: &mut App) -> BTreeSet<(String, u16, PointId)> {
    let mut names = app.world_mut().query::<(Entity, &Name)>();
    let names: Vec<(Entity, String)> = names
        .iter(app.world())
        .map(|(e, n)| (e, n.as_str().to_owned()))
        .collect();
    let mut q = app.world_mut().query::<&ScatterEntity>();
    q.iter(app.world())
        .map(|s| {
            let name = names.iter().find(|(e, _)| *e == s.layer).unwrap().1.clone();
            (name, s.class, s.id)
        })
        .collect()
}

/// Runs `rounds` frames of the server and each client, moving messages between them.
fn pump(server: &mut App, clients: &mut [&mut App], rounds: usize) {
    for _ in 0..rounds {
        server.update();
        for client in clients.iter_mut() {
            server.exchange_with_client(client);
            client.update();
        }
        std::thread::sleep(std::time::Duration::from_millis(1));
    }
    for app in std::iter::once(server).chain(clients.iter_mut().map(|c| &mut **c)) {
        assert!(settle(app, 10_000));
    }
}

fn status(app: &App) -> NetClientStatus {
    app.world().resource::<NetClientStatus>().clone()
}

fn refusals(server: &App) -> Refusals {
    server.world().resource::<NetServerStats>().refused
}

/// The ids of the first `n` shown instances of `layer_name`.
fn some_ids(app: &mut App, layer_name: &str, n: usize) -> Vec<PointId> {
    shown(app)
        .into_iter()
        .filter(|(l, ..)| l == layer_name)
        .take(n)
        .map(|(.., id)| id)
        .collect()
}

/// A server and two clients that joined it.
fn server_and_two_clients() -> (App, App, App) {
    let mut server = peer(1, default());
    let mut a = peer(1, default());
    let mut b = peer(1, default());
    server.connect_client(&mut a);
    server.connect_client(&mut b);
    pump(&mut server, &mut [&mut a, &mut b], 4);
    (server, a, b)
}

#[test]
fn a_clients_edits_reach_the_server_and_every_client() {
    let (mut server, mut a, mut b) = server_and_two_clients();
    assert_eq!(status(&a), NetClientStatus::Joined);
    assert_eq!(status(&b), NetClientStatus::Joined);
    let before = shown(&mut server);

    // A chops three trees and turns one into a stump (class 1).
    let trees = layer(&mut a, "trees");
    let ids = some_ids(&mut a, "trees", 4);
    for id in &ids[..3] {
        a.world_mut()
            .write_message(EditInstance::remove(trees, *id));
    }
    a.world_mut()
        .write_message(EditInstance::reclass(trees, ids[3], 1));
    pump(&mut server, &mut [&mut a, &mut b], 6);

    let world = shown(&mut server);
    assert_eq!(
        before.len() - world.len(),
        3,
        "three trees chopped on the server"
    );
    assert!(world.contains(&("trees".into(), 1, ids[3])), "the stump");
    assert_eq!(shown(&mut a), world, "A shows the server's world");
    assert_eq!(shown(&mut b), world, "B shows the server's world");
    let stats = server.world().resource::<NetServerStats>();
    assert_eq!(stats.sent_edits, 4);
    assert_eq!(stats.refused.total(), 0);

    // A late third client joins with the edits.
    let mut c = peer(1, default());
    server.connect_client(&mut c);
    pump(&mut server, &mut [&mut a, &mut b, &mut c], 4);
    assert_eq!(status(&c), NetClientStatus::Joined);
    assert_eq!(c.world().resource::<NetClientStats>().joined_edits, 4);
    assert_eq!(
        shown(&mut c),
        world,
        "a late client shows the server's world"
    );
}

#[test]
fn a_client_of_another_world_is_refused_with_what_differs() {
    let mut server = peer(1, default());
    let mut other_seed = peer(2, default());
    server.connect_client(&mut other_seed);
    pump(&mut server, &mut [&mut other_seed], 3);
    let NetClientStatus::Refused(refused) = status(&other_seed) else {
        panic!("not refused: {:?}", status(&other_seed));
    };
    assert_eq!(refused.differences.len(), 1, "{refused}");
    let d = &refused.differences[0];
    assert_eq!(d.what, Mismatch::Layer("trees".into(), LayerField::Seed));
    assert_eq!((d.server.as_str(), d.client.as_str()), ("1", "2"));
    assert!(
        refused
            .to_string()
            .contains("layer \"trees\": Seed 2, the server's is 1")
    );

    let mut other_version = peer(
        1,
        NetConfig {
            world_version: 7,
            ..default()
        },
    );
    server.connect_client(&mut other_version);
    pump(&mut server, &mut [&mut other_version], 3);
    let NetClientStatus::Refused(refused) = status(&other_version) else {
        panic!("not refused");
    };
    assert_eq!(refused.differences[0].what, Mismatch::WorldVersion);

    // Another layer file: denser stones, and a layer of flowers the server lacks.
    let mut other_layers = peer_of(default(), |world| {
        world.spawn((Name::new("trees"), layer_of(&[0.05, 0.0]).with_seed(1)));
        world.spawn((Name::new("stones"), layer_of(&[0.03]).with_seed(9)));
        world.spawn((Name::new("flowers"), layer_of(&[0.5]).with_seed(5)));
    });
    server.connect_client(&mut other_layers);
    pump(&mut server, &mut [&mut other_layers], 3);
    let NetClientStatus::Refused(refused) = status(&other_layers) else {
        panic!("not refused: {:?}", status(&other_layers));
    };
    let what: Vec<Mismatch> = refused.differences.iter().map(|d| d.what.clone()).collect();
    assert_eq!(
        what,
        [
            Mismatch::Layer("stones".into(), LayerField::Description),
            Mismatch::ExtraLayer("flowers".into()),
        ],
        "{refused}"
    );
    assert_eq!(server.world().resource::<NetServerStats>().refused_joins, 3);
}

#[test]
fn reconnecting_clients_end_with_the_server_world() {
    let (mut server, mut a, mut b) = server_and_two_clients();

    // A leaves; B chops two trees; A, meanwhile, chops one alone (never sent: offline).
    server.disconnect_client(&mut a);
    let trees_b = layer(&mut b, "trees");
    for id in some_ids(&mut b, "trees", 2) {
        b.world_mut()
            .write_message(EditInstance::remove(trees_b, id));
    }
    pump(&mut server, &mut [&mut b], 6);
    let trees_a = layer(&mut a, "trees");
    let lone = some_ids(&mut a, "trees", 10)[9];
    a.world_mut()
        .write_message(EditInstance::remove(trees_a, lone));
    assert!(settle(&mut a, 10_000));
    assert_ne!(shown(&mut a), shown(&mut server));

    server.connect_client(&mut a);
    pump(&mut server, &mut [&mut a, &mut b], 4);
    let world = shown(&mut server);
    assert_eq!(shown(&mut a), world, "the join replaced A's own edits");
    assert_eq!(a.world().get::<ScatterEdits>(trees_a).unwrap().len(), 2);
}

/// Saves `app`'s world to `dir` (the save module, as a game's server does); the edits saved.
fn save(app: &mut App, dir: &std::path::Path) -> usize {
    app.world_mut().write_message(SaveWorld::to(dir));
    app.update();
    let mut saved = app.world_mut().resource_mut::<Messages<WorldSaved>>();
    saved.drain().last().unwrap().result.unwrap().edits
}

/// Loads the save in `dir` into `app`; the edits loaded.
fn load(app: &mut App, dir: &std::path::Path) -> usize {
    app.world_mut().write_message(LoadWorld::from(dir));
    app.update();
    let mut loaded = app.world_mut().resource_mut::<Messages<WorldLoaded>>();
    loaded.drain().last().unwrap().result.unwrap().edits
}

#[test]
fn a_restarted_server_resyncs_its_clients() {
    let dir = std::env::temp_dir().join(format!("rwt-net-restart-{}", std::process::id()));
    let mut server = peer(1, default());
    let mut a = peer(1, default());
    server.connect_client(&mut a);
    pump(&mut server, &mut [&mut a], 4);
    let trees = layer(&mut a, "trees");
    for id in some_ids(&mut a, "trees", 3) {
        a.world_mut().write_message(EditInstance::remove(trees, id));
    }
    pump(&mut server, &mut [&mut a], 6);
    assert_eq!(save(&mut server, &dir), 3);

    // The server stops, and a new one starts from the save, its game chopping one more
    // tree before the client is back.
    server.disconnect_client(&mut a);
    drop(server);
    let mut restarted = peer(1, default());
    assert_eq!(load(&mut restarted, &dir), 3);
    let trees_s = layer(&mut restarted, "trees");
    let more = some_ids(&mut restarted, "trees", 20)[19];
    restarted
        .world_mut()
        .write_message(EditInstance::remove(trees_s, more));
    assert!(settle(&mut restarted, 10_000));
    restarted.connect_client(&mut a);
    pump(&mut restarted, &mut [&mut a], 4);
    assert_eq!(status(&a), NetClientStatus::Joined);
    assert_eq!(shown(&mut a), shown(&mut restarted));
    assert_eq!(a.world().get::<ScatterEdits>(trees).unwrap().len(), 4);

    // The running server loads its save again (the fourth chop undone): the client follows.
    assert_eq!(load(&mut restarted, &dir), 3);
    pump(&mut restarted, &mut [&mut a], 4);
    assert_eq!(a.world().get::<ScatterEdits>(trees).unwrap().len(), 3);
    assert_eq!(shown(&mut a), shown(&mut restarted));
    // One resync: the first load came before the server listened, with no one to send to.
    let stats = restarted.world().resource::<NetServerStats>();
    assert_eq!((stats.resyncs, stats.joins), (1, 1), "{stats:?}");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The first shown tree's ground position on `app`.
fn a_tree(app: &mut App) -> Vec3 {
    let trees = layer(app, "trees");
    let mut q = app.world_mut().query::<(&ScatterEntity, &Transform)>();
    let mut places: Vec<Vec3> = q
        .iter(app.world())
        .filter(|(s, _)| s.layer == trees)
        .map(|(_, t)| t.translation)
        .collect();
    places.sort_by(|a, b| a.length().total_cmp(&b.length()));
    places[0]
}

/// Footprints on `app`.
fn footprints(app: &mut App) -> usize {
    let mut q = app.world_mut().query::<(&NetFootprint, &Footprint)>();
    q.iter(app.world()).count()
}

#[test]
fn a_cabin_the_server_places_clears_the_same_ground_for_every_player() {
    let (mut server, mut a, mut b) = server_and_two_clients();
    let before = shown(&mut server);
    let at = a_tree(&mut server);
    let cabin = server
        .world_mut()
        .spawn((
            NetFootprint::new(Transform::from_translation(at), Footprint::circle(6.0))
                .on_layers(["trees"]),
            Replicated,
        ))
        .id();
    pump(&mut server, &mut [&mut a, &mut b], 4);

    // Every tree within 6 m of the cabin is gone on the server, and nothing else.
    let world = shown(&mut server);
    let cleared: Vec<_> = before.difference(&world).collect();
    assert!(!cleared.is_empty());
    assert!(
        cleared.iter().all(|(layer, ..)| layer == "trees"),
        "{cleared:?}"
    );
    let trees = layer(&mut server, "trees");
    let mut q = server.world_mut().query::<(&ScatterEntity, &Transform)>();
    let near = |t: &Transform| t.translation.xz().distance(at.xz()) <= 6.0;
    assert!(
        !q.iter(server.world())
            .any(|(s, t)| s.layer == trees && near(t))
    );
    assert_eq!(shown(&mut a), world, "A shows the server's clearing");
    assert_eq!(shown(&mut b), world, "B shows the server's clearing");

    // A late player, and one that reconnects, have the cabin once.
    let mut c = peer(1, default());
    server.connect_client(&mut c);
    server.disconnect_client(&mut b);
    pump(&mut server, &mut [&mut a, &mut c], 2);
    server.connect_client(&mut b);
    pump(&mut server, &mut [&mut a, &mut b, &mut c], 4);
    for (name, app) in [("B", &mut b), ("C", &mut c)] {
        assert_eq!(shown(app), world, "{name} shows the server's clearing");
        assert_eq!(footprints(app), 1, "{name}");
    }

    // The cabin goes: the trees stand again for everyone.
    server.world_mut().entity_mut(cabin).despawn();
    pump(&mut server, &mut [&mut a, &mut b, &mut c], 4);
    assert_eq!(shown(&mut server), before);
    for app in [&mut a, &mut b, &mut c] {
        assert_eq!(shown(app), before);
    }
}

#[test]
fn a_changed_server_world_rechecks_its_clients() {
    let (mut server, mut a, mut b) = server_and_two_clients();
    // The server and A (updated alike) get a layer of apples; B does not. "apples" sorts
    // first, so the trees' index on the wire moves.
    for app in [&mut server, &mut a] {
        app.world_mut()
            .spawn((Name::new("apples"), layer_of(&[0.01]).with_seed(3)));
    }
    pump(&mut server, &mut [&mut a, &mut b], 4);
    assert_eq!(status(&a), NetClientStatus::Joined);
    let NetClientStatus::Refused(refused) = status(&b) else {
        panic!("not refused: {:?}", status(&b));
    };
    let what: Vec<Mismatch> = refused.differences.iter().map(|d| d.what.clone()).collect();
    assert_eq!(what, [Mismatch::MissingLayer("apples".into())]);
    assert_eq!(server.world().resource::<NetServerStats>().rechecks, 1);

    // A's chop lands on the server's trees.
    let trees = layer(&mut a, "trees");
    let id = some_ids(&mut a, "trees", 1)[0];
    a.world_mut().write_message(EditInstance::remove(trees, id));
    pump(&mut server, &mut [&mut a], 6);
    let trees_s = layer(&mut server, "trees");
    assert_eq!(
        server.world().get::<ScatterEdits>(trees_s).unwrap().len(),
        1
    );
    assert_eq!(shown(&mut a), shown(&mut server));
    assert_eq!(refusals(&server).total(), 0);
}

/// Sends `message` from `client` as it is, bypassing the client plugin.
fn send(client: &mut App, message: ClientNet) {
    client.world_mut().write_message(message);
}

/// Delivers `bytes` to the server as from `client`, on the channel `request` takes (learnt
/// from the request, taken back before it is sent).
fn send_bytes(server: &mut App, client: &mut App, request: ClientNet, bytes: &[u8]) {
    send(client, request);
    client.update();
    let (channel, _) = client
        .world_mut()
        .resource_mut::<ClientMessages>()
        .drain_sent()
        .last()
        .unwrap();
    let entity = **client.world().resource::<TestClientEntity>();
    let mut messages = server.world_mut().resource_mut::<ServerMessages>();
    messages.insert_received(entity, channel, bytes.to_vec());
}

#[test]
fn hostile_requests_are_refused_and_counted() {
    let config = NetConfig {
        request_burst: 10,
        requests_per_second: 0.0,
        ..default()
    };
    let mut server = peer(1, config.clone());
    let mut a = peer(1, default());
    let mut b = peer(1, default());
    server.connect_client(&mut b);
    pump(&mut server, &mut [&mut b], 3);
    server.connect_client(&mut a);
    let valid = some_ids(&mut server, "trees", 1)[0];
    let wire = |layer, level, index, edit| WireEdit {
        layer,
        level,
        x: valid.x,
        y: valid.y,
        index,
        edit,
    };
    pump(&mut server, &mut [&mut a], 3);
    assert_eq!(status(&a), NetClientStatus::Joined);
    let trees = 1; // "stones" < "trees"
    send(
        &mut a,
        ClientNet::Edit(wire(7, valid.level, valid.index, WireKind::Remove)),
    );
    send(
        &mut a,
        ClientNet::Edit(wire(trees, 30, valid.index, WireKind::Remove)),
    );
    send(
        &mut a,
        ClientNet::Edit(wire(trees, valid.level, 60_000, WireKind::Remove)),
    );
    send(
        &mut a,
        ClientNet::Edit(wire(trees, valid.level, valid.index, WireKind::Reclass(9))),
    );
    send(
        &mut a,
        ClientNet::Hello(WorldFingerprint {
            protocol: PROTOCOL,
            world_version: 0,
            tile_set: 0,
            layers: Vec::new(),
        }),
    );
    pump(&mut server, &mut [&mut a, &mut b], 4);
    let r = refusals(&server);
    assert_eq!(
        (
            r.unknown_layer,
            r.level,
            r.no_point,
            r.no_class,
            r.not_joined
        ),
        (1, 1, 1, 1, 1),
        "{r:?}"
    );

    // A flood: 10 requests a burst, none refilled; the rest refused, nothing applied twice.
    let before = server.world().resource::<NetServerStats>().sent_edits;
    for _ in 0..500 {
        send(
            &mut a,
            ClientNet::Edit(wire(trees, valid.level, valid.index, WireKind::Remove)),
        );
    }
    pump(&mut server, &mut [&mut a, &mut b], 4);
    let r = refusals(&server);
    assert_eq!(r.flood, 500 - (10 - 4), "{r:?}");
    let stats = server.world().resource::<NetServerStats>();
    assert_eq!(stats.sent_edits - before, 10 - 4);
    // Every refusal is on A's account, none on B's.
    let mut peers = server.world_mut().query::<&NetPeer>();
    let totals: Vec<u64> = peers
        .iter(server.world())
        .map(|p| p.refused.total())
        .collect();
    assert!(
        totals.contains(&0) && totals.contains(&r.total()),
        "{totals:?}"
    );
    // The valid edit reached B.
    assert!(!shown(&mut b).contains(&("trees".into(), 0, valid)));

    // Bytes that are no message, on the channel A's requests take.
    let request = ClientNet::Edit(wire(trees, valid.level, valid.index, WireKind::Remove));
    for garbage in [&[0xff_u8, 0xff, 0xff][..], &[9], &[1, 200, 1, 2]] {
        send_bytes(&mut server, &mut a, request.clone(), garbage);
    }
    pump(&mut server, &mut [&mut a, &mut b], 2);
    assert_eq!(refusals(&server).garbled, 3);
}
