//! The client: introduces its world on connecting, takes the server's edits as its own
//! (replacing what it had: a reconnect or a restarted server leaves it with the server's
//! world), and sends the game's edits to the server instead of applying them.

use crate::config::NetConfig;
use crate::fingerprint::{JoinRefused, WorldFingerprint};
use crate::index::LayerIndex;
use crate::protocol::{ClientNet, ServerNet, WireEdit};
use bevy::prelude::*;
use bevy_replicon::prelude::*;
use bevy_rwt::RwtSystems;
use bevy_rwt::RwtTileSet;
use bevy_rwt::edits::{ConfirmedEdit, EditAuthority, EditInstance, EditSet, ScatterEdits};
use bevy_rwt::layers::ScatterLayer;
use bevy_rwt::rwt_core::edits::{EditsError, MAX_EDITS_FILE_BYTES};

/// Where this client stands with the server.
#[derive(Resource, Clone, Debug, Default, PartialEq)]
pub enum NetClientStatus {
    /// Not connected (or not a client).
    #[default]
    Offline,
    /// Connected; the handshake or the join is under way.
    Joining,
    /// The world is the server's, and edits go to it.
    Joined,
    /// The server refused this client (it disconnects it): what differs.
    Refused(JoinRefused),
    /// The server's edits of a layer did not read (a broken server).
    Broken {
        /// The layer.
        layer: String,
        /// Why.
        error: EditsError,
    },
}

/// What the client did, for a HUD, logs and tests.
#[derive(Resource, Clone, Debug, Default, PartialEq, Reflect)]
#[reflect(Resource)]
pub struct NetClientStats {
    /// Edit requests sent to the server.
    pub requested: u64,
    /// The game's edits dropped: written before the join, or of a layer the server lacks.
    pub unsent: u64,
    /// Edits the server sent and this client applied.
    pub received: u64,
    /// Edits read from joins.
    pub joined_edits: u64,
}

/// The server's layers (from its welcome) and the joins being read.
#[derive(Resource, Default)]
struct ServerLayers {
    /// This client's entity for each of the server's layers (`None`: no layer of that name).
    entities: Vec<Option<Entity>>,
    /// The edits files being received, one per layer.
    files: Vec<Vec<u8>>,
    /// The server's layer names.
    names: Vec<String>,
    /// Layers whose file has not ended.
    remaining: usize,
}

pub(crate) fn plugin(app: &mut App) {
    app.init_resource::<NetClientStatus>()
        .init_resource::<NetClientStats>()
        .init_resource::<ServerLayers>()
        .add_systems(OnEnter(ClientState::Connected), hello)
        .add_systems(OnEnter(ClientState::Disconnected), offline)
        .add_systems(
            Update,
            (forward, receive)
                .chain()
                .before(RwtSystems::Plan)
                .run_if(in_state(ClientState::Connected)),
        );
}

/// This client's world, as the handshake introduces it.
#[derive(bevy::ecs::system::SystemParam)]
struct OwnWorld<'w, 's> {
    tile_set: Res<'w, RwtTileSet>,
    layers: Query<'w, 's, (&'static Name, &'static ScatterLayer)>,
    config: Res<'w, NetConfig>,
}

impl OwnWorld<'_, '_> {
    fn hello(&self) -> ClientNet {
        let layers = self.layers.iter();
        ClientNet::Hello(WorldFingerprint::of(
            &self.tile_set,
            layers,
            self.config.world_version,
        ))
    }
}

/// Introduces this client's world to the server.
fn hello(
    world: OwnWorld,
    mut status: ResMut<NetClientStatus>,
    mut authority: ResMut<EditAuthority>,
    mut server_layers: ResMut<ServerLayers>,
    mut out: MessageWriter<ClientNet>,
) {
    *status = NetClientStatus::Joining;
    *authority = EditAuthority::Remote;
    *server_layers = ServerLayers::default();
    out.write(world.hello());
}

/// Offline, the game's edits apply here again (a join replaces them). A refusal stays
/// readable after the disconnect that follows it.
fn offline(mut status: ResMut<NetClientStatus>, mut authority: ResMut<EditAuthority>) {
    *authority = EditAuthority::Local;
    if !matches!(*status, NetClientStatus::Refused(_)) {
        *status = NetClientStatus::Offline;
    }
}

/// Sends the game's edits to the server (connected, the plugin does not apply them: see
/// [`EditAuthority`]): the server applies and sends back what it allows, to every client
/// alike.
fn forward(
    mut edits: MessageReader<EditInstance>,
    server_layers: Res<ServerLayers>,
    status: Res<NetClientStatus>,
    mut stats: ResMut<NetClientStats>,
    mut out: MessageWriter<ClientNet>,
) {
    for edit in edits.read() {
        let layer = server_layers
            .entities
            .iter()
            .position(|e| *e == Some(edit.layer));
        match layer {
            Some(i) if *status == NetClientStatus::Joined => {
                stats.requested += 1;
                out.write(ClientNet::Edit(WireEdit::new(i as u16, edit)));
            }
            _ => {
                stats.unsent += 1;
                warn!(
                    "edit of layer {} not sent: not joined to the server, or a layer it lacks",
                    edit.layer
                );
            }
        }
    }
}

/// Reads the server's messages: a refusal, the welcome and join, live edits.
#[allow(clippy::too_many_arguments)]
fn receive(
    mut messages: MessageReader<ServerNet>,
    layers: Query<(Entity, &Name, &ScatterLayer)>,
    world: OwnWorld,
    mut server_layers: ResMut<ServerLayers>,
    mut status: ResMut<NetClientStatus>,
    mut stats: ResMut<NetClientStats>,
    mut edits: MessageWriter<ConfirmedEdit>,
    mut out: MessageWriter<ClientNet>,
    mut commands: Commands,
) {
    for message in messages.read() {
        match message {
            ServerNet::Refused(refused) => {
                error!("{refused}");
                *status = NetClientStatus::Refused(refused.clone());
            }
            ServerNet::Welcome { layers: names } => {
                let index = LayerIndex::new(layers.iter().map(|(e, n, _)| (e, n)));
                *server_layers = ServerLayers {
                    entities: names.iter().map(|n| index.by_name(n)).collect(),
                    files: vec![Vec::new(); names.len()],
                    names: names.clone(),
                    remaining: names.len(),
                };
                if names.is_empty() {
                    *status = NetClientStatus::Joined;
                }
            }
            ServerNet::JoinPart { layer, last, bytes } => {
                let (i, file) = match server_layers.add_part(*layer, *last, bytes) {
                    Ok(Some(done)) => done,
                    Ok(None) => continue,
                    Err(error) => {
                        *status = server_layers.broken(*layer as usize, error);
                        continue;
                    }
                };
                if let Some(entity) = server_layers.entities[i]
                    && let Ok((_, _, scatter)) = layers.get(entity)
                {
                    match EditSet::from_bytes(&file, &world.tile_set.stamp(scatter)) {
                        Ok(set) => {
                            stats.joined_edits += set.len() as u64;
                            commands.entity(entity).insert(ScatterEdits::new(set));
                        }
                        Err(error) => {
                            *status = server_layers.broken(i, error);
                            continue;
                        }
                    }
                }
                if server_layers.remaining == 0 {
                    *status = NetClientStatus::Joined;
                }
            }
            ServerNet::Recheck => {
                *status = NetClientStatus::Joining;
                out.write(world.hello());
            }
            ServerNet::Edits(batch) => {
                for wire in batch {
                    if let Some(Some(layer)) = server_layers.entities.get(wire.layer as usize) {
                        stats.received += 1;
                        edits.write(ConfirmedEdit(wire.to_instance(*layer)));
                    }
                }
            }
        }
    }
}

impl ServerLayers {
    /// Adds a slice of layer `layer`'s edits file; at its last, the layer's index and the
    /// whole file.
    fn add_part(
        &mut self,
        layer: u16,
        last: bool,
        bytes: &[u8],
    ) -> Result<Option<(usize, Vec<u8>)>, EditsError> {
        let i = layer as usize;
        let Some(file) = self.files.get_mut(i) else {
            return Ok(None);
        };
        let size = (file.len() + bytes.len()) as u64;
        if size > MAX_EDITS_FILE_BYTES {
            return Err(EditsError::TooMany {
                count: size,
                limit: MAX_EDITS_FILE_BYTES as usize,
            });
        }
        file.extend_from_slice(bytes);
        if !last {
            return Ok(None);
        }
        self.remaining = self.remaining.saturating_sub(1);
        Ok(Some((i, std::mem::take(file))))
    }

    /// The status for layer `i`'s edits that did not read.
    fn broken(&self, i: usize, error: EditsError) -> NetClientStatus {
        let layer = self.names.get(i).cloned().unwrap_or_default();
        error!("the server's edits of layer \"{layer}\" do not read: {error}");
        NetClientStatus::Broken { layer, error }
    }
}
