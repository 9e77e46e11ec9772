//! The server: checks each client's handshake, sends a joining client every layer's edits,
//! screens edit requests (joined, known layer, storable level, rate, the game's permission)
//! before the plugin applies them, and sends every applied edit on to the joined clients.
//! When its world changes under them (a save loaded, named layers changed) it sends its
//! clients the join again, or asks them to shake hands again.

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
use bevy_rwt::save::WorldLoaded;
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
    /// Times the joined clients were sent the join again (a save was loaded).
    pub resyncs: u64,
    /// Times the joined clients were asked to shake hands again (the named layers, the tile
    /// set or the world version changed).
    pub rechecks: u64,
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

/// The server's world as clients see it: its fingerprint and its named layers, made again
/// only when they change.
#[derive(Resource, Default)]
struct ServerWorld {
    /// `None` before the first frame.
    fingerprint: Option<WorldFingerprint>,
    index: LayerIndex,
}

/// A named layer that appeared, was renamed or changed.
type LayerChanged = (
    With<ScatterLayer>,
    Or<(Changed<Name>, Changed<ScatterLayer>)>,
);

pub(crate) fn plugin(app: &mut App) {
    app.init_resource::<NetServerStats>()
        .init_resource::<Pending>()
        .init_resource::<InFlight>()
        .init_resource::<ServerWorld>()
        .add_observer(on_client_connected)
        .add_systems(
            PreUpdate,
            (track_world, receive, ask_permission)
                .chain()
                .after(ServerSystems::Receive)
                .run_if(in_state(ServerState::Running)),
        )
        .add_systems(
            PostUpdate,
            (send_on, resync_after_load, welcome)
                .chain()
                .before(ServerSystems::Send)
                .run_if(in_state(ServerState::Running)),
        );
}

/// Takes the world's fingerprint and layer index again when what they are made of changed;
/// when the fingerprint differs, asks every joined client to shake hands again (its
/// requests are refused as not joined until it has).
#[allow(clippy::too_many_arguments)]
fn track_world(
    layers: Query<(Entity, &Name, &ScatterLayer)>,
    changed: Query<(), LayerChanged>,
    mut gone: RemovedComponents<ScatterLayer>,
    mut unnamed: RemovedComponents<Name>,
    tile_set: Res<RwtTileSet>,
    config: Res<NetConfig>,
    mut world: ResMut<ServerWorld>,
    mut peers: Query<(Entity, &mut NetPeer)>,
    mut stats: ResMut<NetServerStats>,
    mut out: MessageWriter<ToClients<ServerNet>>,
) {
    let removed = gone.read().count() + unnamed.read().count() > 0;
    let first = world.fingerprint.is_none();
    if !(first || removed || !changed.is_empty() || tile_set.is_changed() || config.is_changed()) {
        return;
    }
    let now = WorldFingerprint::of(
        &tile_set,
        layers.iter().map(|(_, n, l)| (n, l)),
        config.world_version,
    );
    world.index = LayerIndex::new(layers.iter().map(|(e, n, _)| (e, n)));
    let was = world.fingerprint.replace(now);
    if first || was == world.fingerprint {
        return;
    }
    let mut asked = false;
    for (client, mut peer) in peers.iter_mut().filter(|(_, p)| p.joined || p.welcome) {
        peer.joined = false;
        peer.welcome = false;
        asked = true;
        out.write(ToClients {
            targets: SendTargets::Single(ClientId::Client(client)),
            message: ServerNet::Recheck,
        });
    }
    if asked {
        info!("the server's world changed: its clients shake hands again");
        stats.rechecks += 1;
    }
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
    world: Res<ServerWorld>,
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
                let Some(ours) = &world.fingerprint else {
                    continue;
                };
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
                let Some(layer) = world.index.entity(wire.layer) else {
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
    world: Res<ServerWorld>,
    mut stats: ResMut<NetServerStats>,
    mut out: MessageWriter<ToClients<ServerNet>>,
) {
    let mut batch = Vec::new();
    for outcome in outcomes.read() {
        let client = in_flight.requester(&outcome.edit);
        match &outcome.result {
            Ok(()) => {
                if let Some(layer) = world.index.position(outcome.edit.layer) {
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

impl InFlight {
    /// Who asked for `edit` (`None`: the server's game), taken off the queue. Outcomes come
    /// in the order the requests were handed on, so a client's is at the front unless the
    /// game's own edits came between.
    fn requester(&mut self, edit: &EditInstance) -> Option<ClientId> {
        let at = match self.0.front() {
            Some(first) if first.edit == *edit => Some(0),
            _ => self.0.iter().position(|r| r.edit == *edit),
        };
        at.and_then(|i| self.0.remove(i)).map(|r| r.client)
    }
}

/// A loaded save replaced the server's edits: every joined client gets the join again.
fn resync_after_load(
    mut loaded: MessageReader<WorldLoaded>,
    mut peers: Query<&mut NetPeer>,
    mut stats: ResMut<NetServerStats>,
) {
    if !loaded.read().any(|l| l.result.is_ok()) {
        return;
    }
    stats.resyncs += 1;
    for mut peer in peers.iter_mut().filter(|p| p.joined) {
        peer.welcome = true;
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
    layers: Query<(&ScatterLayer, &ScatterEdits)>,
    world: Res<ServerWorld>,
    tile_set: Res<RwtTileSet>,
    config: Res<NetConfig>,
    mut stats: ResMut<NetServerStats>,
    mut out: MessageWriter<ToClients<ServerNet>>,
) {
    let index = &world.index;
    for (client, mut peer) in peers.iter_mut().filter(|(_, p)| p.welcome) {
        peer.welcome = false;
        if !peer.joined {
            stats.joins += 1;
        }
        peer.joined = true;
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
            let Ok((layer, edits)) = layers.get(entity) else {
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
