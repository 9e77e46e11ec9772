//! What edits cost on the network: `cargo bench -p bevy_rwt_net --bench net`. A server
//! holding 100 000 edits (as if loaded from its save) and a client joining it, in one
//! process over replicon's in-process connection; bytes are what replicon hands its
//! transport (its framing included, the transport's own not). Prints
//! `net: edits=E join_bytes=J bytes_per_edit_join=Bj live_bytes_per_edit=Bl`, then the
//! client's frame that applies the join against its median frame, and the requests' bytes.

use bevy::prelude::*;
use bevy::state::app::StatesPlugin;
use bevy_replicon::prelude::*;
use bevy_replicon::test_app::{ServerTestAppExt, TestClientEntity};
use bevy_rwt::edits::{Edit, EditInstance, EditSet, ScatterEdits};
use bevy_rwt::prelude::*;
use bevy_rwt::rwt_core::query::{PointId, Rect, Sampler};
use bevy_rwt::rwt_core::{Constant, TileSet};
use bevy_rwt::testing::{headless_app_with, settle, spawn_viewer};
use bevy_rwt_net::{NetClientStatus, NetConfig, RwtNetPlugin};
use glam::DVec2;
use std::time::Instant;

const EDITS: usize = 100_000;
/// Live edits sent one per frame, as players chop.
const LIVE: usize = 1_000;

fn main() {
    let config = NetConfig {
        requests_per_second: 1e6,
        request_burst: 1_000_000,
        ..default()
    };
    let mut server = peer(config.clone());
    let ids = point_ids(&mut server, EDITS);
    let mut set = EditSet::default();
    for id in &ids {
        set.set(*id, Edit::Remove).unwrap();
    }
    let layer = layer_entity(&mut server);
    server
        .world_mut()
        .entity_mut(layer)
        .insert(ScatterEdits::new(set));
    assert!(settle(&mut server, 100_000));

    let mut client = peer(config);
    let mut frames = Vec::new();
    for _ in 0..30 {
        frames.push(timed(&mut client));
    }
    server.connect_client(&mut client);
    let mut join_bytes = 0;
    let mut join_ms = 0.0;
    for _ in 0..10 {
        server.update();
        join_bytes += exchange(&mut server, &mut client).0;
        let ms = timed(&mut client);
        if *client.world().resource::<NetClientStatus>() == NetClientStatus::Joined
            && join_ms == 0.0
        {
            join_ms = ms;
        }
    }
    let layer_c = layer_entity(&mut client);
    assert_eq!(
        client.world().get::<ScatterEdits>(layer_c).unwrap().len(),
        EDITS
    );
    assert!(settle(&mut client, 100_000));

    // Live: the client asks for one edit a frame (restores of edited points), the server
    // applies it and sends it back to every client, this one included.
    let (mut live_bytes, mut request_bytes) = (0, 0);
    for id in ids.iter().take(LIVE) {
        client
            .world_mut()
            .write_message(EditInstance::restore(layer_c, *id));
        client.update();
        let (down, up) = exchange(&mut server, &mut client);
        request_bytes += up;
        live_bytes += down;
        server.update();
        let (down, up) = exchange(&mut server, &mut client);
        live_bytes += down;
        request_bytes += up;
        client.update();
    }
    let restored = EDITS - client.world().get::<ScatterEdits>(layer_c).unwrap().len();
    assert_eq!(restored, LIVE, "every live edit came back");
    frames.sort_by(f64::total_cmp);
    let median = frames[frames.len() / 2];
    println!(
        "net: edits={EDITS} join_bytes={join_bytes} bytes_per_edit_join={:.2} live_bytes_per_edit={:.2}",
        join_bytes as f64 / EDITS as f64,
        live_bytes as f64 / LIVE as f64
    );
    println!(
        "  join applied in one client frame of {join_ms:.2} ms (median frame before {median:.2} ms); \
         requests {:.2} bytes per edit",
        request_bytes as f64 / LIVE as f64
    );
}

/// A peer with one layer, dense enough to hold the edits near the viewer.
fn peer(config: NetConfig) -> App {
    let mut app = headless_app_with(RwtPlugins::default(), |app| {
        app.add_plugins((
            StatesPlugin,
            RepliconPlugins.set(ServerPlugin::new(PostUpdate)),
            RwtNetPlugin { config },
        ));
    });
    let grass = ScatterClass::new(LayerDensity::Constant(2.0), default(), default());
    app.world_mut().spawn((
        Name::new("grass"),
        ScatterLayer::new(vec![grass]).with_seed(3),
    ));
    spawn_viewer(&mut app, Vec3::ZERO);
    assert!(settle(&mut app, 100_000));
    app
}

fn layer_entity(app: &mut App) -> Entity {
    let mut q = app
        .world_mut()
        .query_filtered::<Entity, With<ScatterLayer>>();
    q.single(app.world()).unwrap()
}

/// The first `n` points of the layer around the origin, by the layer's own tiling.
fn point_ids(app: &mut App, n: usize) -> Vec<PointId> {
    let mut q = app.world_mut().query::<&ScatterLayer>();
    let layer = q.single(app.world()).unwrap();
    let sampler = Sampler::new(&TileSet::embedded(), layer.seed)
        .with_lattice(layer.lattice)
        .with_tile_size(layer.tile_size);
    let side = ((n as f64 / 2.0).sqrt() * 1.2).ceil();
    let rect = Rect::new(DVec2::splat(-side / 2.0), DVec2::splat(side / 2.0)).unwrap();
    let mut points = Vec::new();
    sampler.query(rect, &Constant(2.0), &mut points).unwrap();
    assert!(points.len() >= n, "{} points", points.len());
    points.into_iter().take(n).map(|p| p.id).collect()
}

fn timed(app: &mut App) -> f64 {
    let t = Instant::now();
    app.update();
    t.elapsed().as_secs_f64() * 1000.0
}

/// Moves messages both ways (as replicon's test connection does); the bytes each way:
/// (server to client, client to server).
fn exchange(server: &mut App, client: &mut App) -> (usize, usize) {
    let entity = **client.world().resource::<TestClientEntity>();
    let sent: Vec<_> = client
        .world_mut()
        .resource_mut::<ClientMessages>()
        .drain_sent()
        .collect();
    let up = sent.iter().map(|(_, m)| m.len()).sum();
    let mut server_messages = server.world_mut().resource_mut::<ServerMessages>();
    for (channel, message) in sent {
        server_messages.insert_received(entity, channel, message);
    }
    let down: Vec<_> = server_messages.drain_sent().collect();
    let mut client_messages = client.world_mut().resource_mut::<ClientMessages>();
    let mut bytes = 0;
    for (to, channel, message) in down {
        if to == entity {
            bytes += message.len();
            client_messages.insert_received(channel, message);
        }
    }
    (bytes, up)
}
