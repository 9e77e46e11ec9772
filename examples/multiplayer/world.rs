//! What the server and the players share: the network's plugins and settings, the open
//! world's layers, the cabin a player asks for, and the summary that shows two worlds agree.

use bevy::ecs::system::SystemParam;
use bevy::prelude::*;
use bevy_replicon::prelude::*;
use bevy_replicon_renet::renet::ConnectionConfig;
use bevy_replicon_renet::{RenetChannelsExt, RepliconRenetPlugins};
use bevy_rwt::edits::{EditOutcome, ScatterEdits};
use bevy_rwt::layers::file::NamedAssets;
use bevy_rwt::prelude::*;
use bevy_rwt::rwt_core::rng::fnv1a;
use bevy_rwt::{ClassLook, RwtTileSet};
use bevy_rwt_net::{NetConfig, NetFootprint, RwtNetPlugin};
use rwt_examples::cabin::{cabin_footprint, cabin_transform};
use rwt_examples::terrain::Terrain;
use rwt_examples::world::layers::{Detail, LayerParts};
use serde::{Deserialize, Serialize};
use std::fmt;

/// The port the server listens on unless told another.
pub const DEFAULT_PORT: u16 = 5710;
/// Netcode's protocol id: peers of another game or version do not connect.
pub const PROTOCOL_ID: u64 = 0x7277_745f_6e65_7401;
/// The world's content version (its terrain and densities in code): peers must agree.
const WORLD_VERSION: u64 = 1;
/// The most cabins the server places.
pub const MAX_CABINS: usize = 64;
/// Cabins stand within this far of the origin (metres).
const CABIN_RANGE: f32 = 5_000.0;

/// The transport's settings both sides share.
pub fn connection_config(channels: &RepliconChannels) -> ConnectionConfig {
    ConnectionConfig {
        server_channels_config: channels.server_configs(),
        client_channels_config: channels.client_configs(),
        ..default()
    }
}

/// Replicon over renet, the scatter's replication and the cabin request: the same on the
/// server and on every player (the order of registration is part of the protocol).
pub fn net_plugins(app: &mut App) {
    app.add_plugins((
        RepliconPlugins,
        RepliconRenetPlugins,
        RwtNetPlugin {
            config: NetConfig {
                world_version: WORLD_VERSION,
                ..default()
            },
        },
    ))
    .add_client_message::<CabinRequest>(Channel::Ordered);
}

/// A player asks the server for a cabin: where it stands on the ground and where its door
/// looks.
#[derive(Message, Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct CabinRequest {
    /// Ground position (x, z).
    pub at: Vec2,
    /// The door's direction on the ground.
    pub facing: Vec2,
}

impl CabinRequest {
    /// Whether the server may place it: finite, on the map, facing somewhere.
    pub fn is_valid(&self) -> bool {
        self.at.is_finite()
            && self.facing.is_finite()
            && self.at.length() <= CABIN_RANGE
            && self.facing.length() > 1e-3
    }

    /// The shared footprint of the cabin on `terrain`: it clears every layer under it.
    pub fn footprint(&self, terrain: &Terrain) -> NetFootprint {
        let transform = cabin_transform(terrain, self.at, self.facing.normalize());
        NetFootprint::new(transform, cabin_footprint())
    }
}

/// Spawns the open world's layers drawn with the pack's files (a player).
pub fn spawn_drawn_layers(parts: WorldLayerParts) {
    parts.spawn(true);
}

/// Spawns the open world's layers with no looks at all (the server, which draws nothing:
/// only where things grow must agree).
pub fn spawn_undrawn_layers(parts: WorldLayerParts) {
    parts.spawn(false);
}

/// What the world's layers are made from.
#[derive(SystemParam)]
pub struct WorldLayerParts<'w, 's> {
    commands: Commands<'w, 's>,
    terrain: Res<'w, Terrain>,
    server: Res<'w, AssetServer>,
    meshes: ResMut<'w, Assets<Mesh>>,
    materials: ResMut<'w, Assets<StandardMaterial>>,
    images: ResMut<'w, Assets<Image>>,
    names: Res<'w, NamedAssets>,
    detail: Res<'w, Detail>,
}

impl WorldLayerParts<'_, '_> {
    fn spawn(mut self, draw: bool) {
        let server = self.server.clone();
        let load = |path: &str| match draw {
            true => server.load(path.to_string()),
            false => Handle::default(),
        };
        let mut world = LayerParts {
            terrain: &self.terrain,
            load: &load,
            meshes: &mut self.meshes,
            materials: &mut self.materials,
            images: &mut self.images,
            detail: *self.detail,
        }
        .build(&self.names);
        if !draw {
            for (_, layer) in &mut world.layers {
                draw_nothing(layer);
            }
        }
        world.spawn(&mut self.commands);
    }
}

/// A server's layer: where its points grow and which classes they are, nothing to draw
/// (it has no viewer: nothing streams, but edits are checked against the tiling).
fn draw_nothing(layer: &mut ScatterLayer) {
    for class in &mut layer.classes {
        class.look = ClassLook::Mesh {
            mesh: Handle::default(),
            material: Handle::default(),
        };
        class.lod = None;
        class.promotion = None;
        class.impostor = None;
    }
}

/// A world as the players compare it: its edits and cabins, and a digest of both.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct WorldSummary {
    /// Edited instances over the named layers.
    pub edits: usize,
    /// Cabins.
    pub cabins: usize,
    /// FNV-1a of every named layer's edits file (by name) and every cabin's placement.
    pub digest: u64,
}

impl fmt::Display for WorldSummary {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        let WorldSummary {
            edits,
            cabins,
            digest,
        } = self;
        write!(f, "edits={edits} cabins={cabins} digest={digest:016x}")
    }
}

/// Reads a peer's world for its [`WorldSummary`].
#[derive(SystemParam)]
pub struct WorldState<'w, 's> {
    tile_set: Res<'w, RwtTileSet>,
    layers: Query<'w, 's, (&'static Name, &'static ScatterLayer, &'static ScatterEdits)>,
    cabins: Query<'w, 's, &'static NetFootprint>,
    /// A layer's edits replaced (a join, a load).
    changed_edits: Query<'w, 's, (), Changed<ScatterEdits>>,
    /// Single edits (they leave `ScatterEdits` unmarked).
    outcomes: MessageReader<'w, 's, EditOutcome>,
    changed_cabins: Query<'w, 's, (), Changed<NetFootprint>>,
    gone: RemovedComponents<'w, 's, NetFootprint>,
}

impl WorldState<'_, '_> {
    /// Whether edits or cabins changed since the last call.
    pub fn changed(&mut self) -> bool {
        let gone = self.gone.read().count() > 0;
        let edited = self.outcomes.read().filter(|o| o.result.is_ok()).count() > 0;
        gone || edited || !self.changed_edits.is_empty() || !self.changed_cabins.is_empty()
    }

    /// Edited instances over the named layers, and cabins.
    pub fn counts(&self) -> (usize, usize) {
        let edits = self.layers.iter().map(|(_, _, e)| e.len()).sum();
        (edits, self.cabins.iter().count())
    }

    /// The summary of the world now.
    pub fn summary(&self) -> WorldSummary {
        let mut layers: Vec<_> = self.layers.iter().collect();
        layers.sort_by(|a, b| a.0.as_str().cmp(b.0.as_str()));
        let mut bytes = Vec::new();
        let mut edits = 0;
        for (name, layer, set) in layers {
            edits += set.len();
            bytes.extend_from_slice(name.as_str().as_bytes());
            bytes.extend(set.edits().to_bytes(&self.tile_set.stamp(layer)));
        }
        let mut cabins: Vec<[u32; 3]> = self
            .cabins
            .iter()
            .map(|c| c.translation.to_array().map(f32::to_bits))
            .collect();
        cabins.sort_unstable();
        for cabin in &cabins {
            cabin.iter().for_each(|b| bytes.extend(b.to_le_bytes()));
        }
        WorldSummary {
            edits,
            cabins: cabins.len(),
            digest: fnv1a(&bytes),
        }
    }
}
