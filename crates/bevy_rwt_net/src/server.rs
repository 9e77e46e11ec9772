//! The server: checks each client's handshake, sends a joining client every layer's edits,
//! screens edit requests (joined, known layer, storable level, rate, the game's permission)
//! before the plugin applies them, and sends every applied edit on to the joined clients.

use crate::config::NetConfig;
use crate::fingerprint::{JoinRefused, WorldFingerprint};
use crate::index::LayerIndex;
use crate::protocol::{ClientNet, ServerNet, WireEdit};
use bevy::ecs::system::SystemId;
use bevy::prelude::*;
use bevy_replicon::prelude::*;
use bevy_rwt::RwtTileSet;
use bevy_rwt::edits::{EditError, EditInstance, EditOutcome, ScatterEdits};
use bevy_rwt::layers::ScatterLayer;
use bevy_rwt::rwt_core::query::MAX_LEVEL;
use std::collections::VecDeque;

/// A connected client as the server sees it (on replicon's client entity).
#[derive(Component, Clone, Debug, Default)]
pub struct NetPeer {
    /// Whether its handshake passed and its join was sent.
    pub joined: bool,
    /// Whether its join is to be sent this frame.
    welcome: bool,
    /// Requests it may still send now (refilled at [`NetConfig::requests_per_second`]).
    tokens: f32,
    /// Its requests that were refused, by reason.
    pub refused: Refusals,
}

/// Refused requests, by reason.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Reflect)]
pub struct Refusals {
    /// Bytes that decode to no message.
    pub garbled: u64,
    /// An edit before the handshake passed, or a second handshake.
    pub not_joined: u64,
    /// A layer index past the server's layers.
    pub unknown_layer: u64,
    /// A point level past the deepest (`MAX_LEVEL`).
    pub level: u64,
    /// An identity the layer's tiling has no point for.
    pub no_point: u64,
    /// A reclass to a class the layer lacks.
    pub no_class: u64,
    /// The layer's edit set is full.
    pub too_many: u64,
    /// Over the client's rate ([`NetConfig::requests_per_second`], its burst) or the
    /// server's queue ([`NetConfig::max_pending`]).
    pub flood: u64,
    /// The game's [`EditPermission`] said no.
    pub denied: u64,
}

impl Refusals {
    /// Every refusal.
    pub fn total(&self) -> u64 {
        let Refusals {
            garbled,
            not_joined,
            unknown_layer,
            level,
            no_point,
            no_class,
            too_many,
            flood,
            denied,
        } = *self;
        garbled
            + not_joined
            + unknown_layer
            + level
            + no_point
            + no_class
            + too_many
            + flood
            + denied
    }

    fn count(&mut self, reason: fn(&mut Refusals) -> &mut u64) {
        *reason(self) += 1;
    }
}

/// What the server did, for a HUD, logs and tests.
#[derive(Resource, Clone, Debug, Default, PartialEq, Reflect)]
#[reflect(Resource)]
pub struct NetServerStats {
    /// Clients whose handshake passed.
    pub joins: u64,
    /// Clients refused at the handshake.
    pub refused_joins: u64,
    /// Requests refused, by reason, over all clients.
    pub refused: Refusals,
    /// Edits applied and sent on (clients' and the server's own).
    pub sent_edits: u64,
    /// Bytes of join messages sent (edits files and their framing).
    pub join_bytes: u64,
    /// Bytes of live-edit messages sent, per client they went to.
    pub live_bytes: u64,
}

/// A client's edit request after screening, handed to the game's [`EditPermission`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EditRequest {
    /// The client.
    pub client: ClientId,
    /// The edit, on the server's layer entity.
    pub edit: EditInstance,
}

/// The game's say over clients' edits: a system that gets each screened request and
/// returns whether to apply it (e.g. the player stands near the tree). Register it with
/// `world.register_system(...)` and insert this resource; without it every screened
/// request is applied.
#[derive(Resource, Clone, Copy, Debug)]
pub struct EditPermission(pub SystemId<In<EditRequest>, bool>);

/// Screened requests waiting for the game's permission (at most
/// [`NetConfig::max_pending`]).
#[derive(Resource, Default)]
struct Pending(Vec<EditRequest>);

/// Requests handed to the plugin this frame, to find whose each outcome is.
#[derive(Resource, Default)]
struct InFlight(VecDeque<EditRequest>);

pub(crate) fn plugin(app: &mut App) {
    app.init_resource::<NetServerStats>()
        .init_resource::<Pending>()
        .init_resource::<InFlight>()
        .add_observer(on_client_connected)
        .add_systems(
            PreUpdate,
            (receive, ask_permission)
                .chain()
                .after(ServerSystems::Receive)
                .run_if(in_state(ServerState::Running)),
        )
        .add_systems(
            PostUpdate,
            (send_on, welcome)
                .chain()
                .before(ServerSystems::Send)
                .run_if(in_state(ServerState::Running)),
        );
}

/// Every connected client gets a [`NetPeer`], with a full burst of requests.
fn on_client_connected(
    added: On<Add, ConnectedClient>,
    config: Res<NetConfig>,
    mut commands: Commands,
) {
    commands.entity(added.entity).insert(NetPeer {
        tokens: config.request_burst as f32,
        ..default()
    });
}

/// Reads the clients' messages: handshakes, and edit requests screened into [`Pending`].
#[allow(clippy::too_many_arguments)]
fn receive(
    mut messages: MessageReader<FromClient<ClientNet>>,
    mut peers: Query<&mut NetPeer>,
    layers: Query<(Entity, &Name, &ScatterLayer)>,
    tile_set: Res<RwtTileSet>,
    config: Res<NetConfig>,
    time: Res<Time<Real>>,
    mut pending: ResMut<Pending>,
    mut stats: ResMut<NetServerStats>,
    mut out: MessageWriter<ToClients<ServerNet>>,
    mut disconnect: MessageWriter<DisconnectRequest>,
) {
    let refill = time.delta_secs() * config.requests_per_second;
    for mut peer in &mut peers {
        peer.tokens = (peer.tokens + refill).min(config.request_burst as f32);
    }
    let index = LayerIndex::new(layers.iter().map(|(e, n, _)| (e, n)));
    for FromClient { client_id, message } in messages.read() {
        let ClientId::Client(client) = *client_id else {
            continue;
        };
        let Ok(mut peer) = peers.get_mut(client) else {
            continue;
        };
        let mut refuse = |reason: fn(&mut Refusals) -> &mut u64, peer: &mut NetPeer| {
            peer.refused.count(reason);
            stats.refused.count(reason);
        };
        match message {
            ClientNet::Hello(_) if peer.joined || peer.welcome => {
                refuse(|r| &mut r.not_joined, &mut peer)
            }
            ClientNet::Hello(theirs) => {
                let ours = WorldFingerprint::of(
                    &tile_set,
                    layers.iter().map(|(_, n, l)| (n, l)),
                    config.world_version,
                );
                let differences = ours.differences(theirs);
                if differences.is_empty() {
                    peer.welcome = true;
                } else {
                    warn!("refused client {client}: {} differences", differences.len());
                    stats.refused_joins += 1;
                    out.write(ToClients {
                        targets: SendTargets::Single(*client_id),
                        message: ServerNet::Refused(JoinRefused { differences }),
                    });
                    disconnect.write(DisconnectRequest { client });
                }
            }
            ClientNet::Garbled => refuse(|r| &mut r.garbled, &mut peer),
            ClientNet::Edit(_) if !peer.joined => refuse(|r| &mut r.not_joined, &mut peer),
            ClientNet::Edit(_) if peer.tokens < 1.0 || pending.0.len() >= config.max_pending => {
                refuse(|r| &mut r.flood, &mut peer)
            }
            ClientNet::Edit(wire) => {
                peer.tokens -= 1.0;
                let Some(layer) = index.entity(wire.layer) else {
                    refuse(|r| &mut r.unknown_layer, &mut peer);
                    continue;
                };
                if wire.level as u32 > MAX_LEVEL {
                    refuse(|r| &mut r.level, &mut peer);
                    continue;
                }
                pending.0.push(EditRequest {
                    client: *client_id,
                    edit: wire.to_instance(layer),
                });
            }
        }
    }
}

/// Asks the game's [`EditPermission`] about each screened request; hands the allowed ones
/// to the plugin.
fn ask_permission(world: &mut World) {
    let requests = std::mem::take(&mut world.resource_mut::<Pending>().0);
    let permission = world.get_resource::<EditPermission>().copied();
    for request in requests {
        let allowed = match permission {
            // A hook that fails (e.g. was removed) allows nothing.
            Some(EditPermission(id)) => world.run_system_with(id, request).unwrap_or(false),
            None => true,
        };
        if !allowed {
            count(world, request.client, |r| &mut r.denied);
            continue;
        }
        world.write_message(request.edit);
        world.resource_mut::<InFlight>().0.push_back(request);
    }
}

fn count(world: &mut World, client: ClientId, reason: fn(&mut Refusals) -> &mut u64) {
    world.resource_mut::<NetServerStats>().refused.count(reason);
    if let ClientId::Client(entity) = client
        && let Some(mut peer) = world.get_mut::<NetPeer>(entity)
    {
        peer.refused.count(reason);
    }
}

/// Sends the frame's applied edits on to every joined client, and counts the refused ones
/// against the client that asked.
fn send_on(
    mut outcomes: MessageReader<EditOutcome>,
    mut in_flight: ResMut<InFlight>,
    mut peers: Query<(Entity, &mut NetPeer)>,
    layers: Query<(Entity, &Name), With<ScatterLayer>>,
    mut stats: ResMut<NetServerStats>,
    mut out: MessageWriter<ToClients<ServerNet>>,
) {
    let index = LayerIndex::new(layers.iter());
    let mut batch = Vec::new();
    for outcome in outcomes.read() {
        let asked = in_flight.0.iter().position(|r| r.edit == outcome.edit);
        let client = asked.and_then(|i| in_flight.0.remove(i)).map(|r| r.client);
        match &outcome.result {
            Ok(()) => {
                if let Some(layer) = index.position(outcome.edit.layer) {
                    batch.push(WireEdit::new(layer, &outcome.edit));
                }
            }
            Err(error) => {
                let reason = reason(error);
                stats.refused.count(reason);
                if let Some(ClientId::Client(entity)) = client
                    && let Ok((_, mut peer)) = peers.get_mut(entity)
                {
                    peer.refused.count(reason);
                }
            }
        }
    }
    in_flight.0.clear();
    if batch.is_empty() {
        return;
    }
    stats.sent_edits += batch.len() as u64;
    let message = ServerNet::Edits(batch);
    let bytes = postcard::to_allocvec(&message).map_or(0, |b| b.len() as u64);
    for (client, _) in peers.iter().filter(|(_, p)| p.joined) {
        stats.live_bytes += bytes;
        out.write(ToClients {
            targets: SendTargets::Single(ClientId::Client(client)),
            message: message.clone(),
        });
    }
}

fn reason(error: &EditError) -> fn(&mut Refusals) -> &mut u64 {
    match error {
        EditError::NoLayer(_) => |r| &mut r.unknown_layer,
        EditError::NoSuchPoint(_) => |r| &mut r.no_point,
        EditError::NoSuchClass { .. } => |r| &mut r.no_class,
        EditError::Refused(_) => |r| &mut r.too_many,
    }
}

/// Sends each client whose handshake passed the layer list and every layer's edits (after
/// this frame's edits were applied: the live edits that follow are all newer).
fn welcome(
    mut peers: Query<(Entity, &mut NetPeer)>,
    layers: Query<(Entity, &Name, &ScatterLayer, &ScatterEdits)>,
    tile_set: Res<RwtTileSet>,
    config: Res<NetConfig>,
    mut stats: ResMut<NetServerStats>,
    mut out: MessageWriter<ToClients<ServerNet>>,
) {
    let index = LayerIndex::new(layers.iter().map(|(e, n, ..)| (e, n)));
    for (client, mut peer) in peers.iter_mut().filter(|(_, p)| p.welcome) {
        peer.welcome = false;
        peer.joined = true;
        stats.joins += 1;
        let target = SendTargets::Single(ClientId::Client(client));
        let mut send = |message: ServerNet| {
            stats.join_bytes += postcard::to_allocvec(&message).map_or(0, |b| b.len() as u64);
            out.write(ToClients {
                targets: target,
                message,
            });
        };
        send(ServerNet::Welcome {
            layers: index.names().map(str::to_owned).collect(),
        });
        for (i, entity) in index.entities().enumerate() {
            let Ok((_, _, layer, edits)) = layers.get(entity) else {
                continue;
            };
            let file = edits.edits().to_bytes(&tile_set.stamp(layer));
            let parts: Vec<&[u8]> = file.chunks(config.join_part_bytes.max(1)).collect();
            for (k, part) in parts.iter().enumerate() {
                send(ServerNet::JoinPart {
                    layer: i as u16,
                    last: k + 1 == parts.len(),
                    bytes: part.to_vec(),
                });
            }
        }
    }
}
