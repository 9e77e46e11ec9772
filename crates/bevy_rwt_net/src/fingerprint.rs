//! What a client and its server must agree on before edits can cross: the tile set, each
//! named layer's tiling and what decides its points, and the game's own content version.
//! A client that differs is refused with every difference named ([`JoinRefused`]).

use bevy::prelude::*;
use bevy_rwt::RwtTileSet;
use bevy_rwt::layers::{LayerDensity, ScatterLayer};
use bevy_rwt::rwt_core::rng::fnv1a;
use serde::{Deserialize, Serialize};
use std::fmt;

/// Version of this crate's messages: peers of another version are refused.
pub const PROTOCOL: u16 = 1;

/// Most layers a fingerprint may list (a longer one is refused unread).
pub const MAX_LAYERS: usize = 1024;

/// What a peer's world is made of: compared field by field at the handshake.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct WorldFingerprint {
    /// [`PROTOCOL`] of the peer.
    pub protocol: u16,
    /// The game's content version ([`crate::NetConfig::world_version`]).
    pub world_version: u64,
    /// [`RwtTileSet::fingerprint`].
    pub tile_set: u64,
    /// The named layers, by name.
    pub layers: Vec<LayerFingerprint>,
}

/// One named layer: what names its points and where they are.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct LayerFingerprint {
    /// The layer's `Name`.
    pub name: String,
    /// Its tiling seed.
    pub seed: u64,
    /// Its lattice (`Debug` text: aligned or seeded).
    pub lattice: String,
    /// Its tile size, as bits of the `f64`.
    pub tile_size: u64,
    /// Its number of classes.
    pub classes: u16,
    /// A hash of the rest of what decides its points: each class's density, the
    /// exclusion, falloff, plane, height range and slope limit.
    pub description: u64,
}

impl WorldFingerprint {
    /// The fingerprint of a world: its tile set and its named layers (unnamed ones cannot be
    /// addressed across the network and are left out), sorted by name.
    pub fn of<'a>(
        tile_set: &RwtTileSet,
        layers: impl IntoIterator<Item = (&'a Name, &'a ScatterLayer)>,
        world_version: u64,
    ) -> Self {
        let mut layers: Vec<_> = layers
            .into_iter()
            .map(|(name, layer)| LayerFingerprint::of(name, layer))
            .collect();
        layers.sort_by(|a, b| a.name.cmp(&b.name));
        layers.dedup_by(|a, b| a.name == b.name);
        Self {
            protocol: PROTOCOL,
            world_version,
            tile_set: tile_set.fingerprint(),
            layers,
        }
    }

    /// Every way `client` differs from this (the server's) fingerprint; empty if none.
    pub fn differences(&self, client: &WorldFingerprint) -> Vec<Difference> {
        let mut out = Vec::new();
        let mut differ = |what, server: String, client: String| {
            if server != client {
                out.push(Difference {
                    what,
                    server,
                    client,
                });
            }
        };
        differ(
            Mismatch::Protocol,
            self.protocol.to_string(),
            client.protocol.to_string(),
        );
        differ(
            Mismatch::WorldVersion,
            self.world_version.to_string(),
            client.world_version.to_string(),
        );
        differ(
            Mismatch::TileSet,
            format!("{:016x}", self.tile_set),
            format!("{:016x}", client.tile_set),
        );
        if client.layers.len() > MAX_LAYERS {
            out.push(Difference {
                what: Mismatch::Layers,
                server: self.layers.len().to_string(),
                client: client.layers.len().to_string(),
            });
            return out;
        }
        for layer in &self.layers {
            match client.layers.iter().find(|l| l.name == layer.name) {
                Some(theirs) => out.extend(layer.differences(theirs)),
                None => out.push(Difference {
                    what: Mismatch::MissingLayer(layer.name.clone()),
                    server: "present".into(),
                    client: "missing".into(),
                }),
            }
        }
        for theirs in &client.layers {
            if !self.layers.iter().any(|l| l.name == theirs.name) {
                out.push(Difference {
                    what: Mismatch::ExtraLayer(theirs.name.clone()),
                    server: "missing".into(),
                    client: "present".into(),
                });
            }
        }
        out
    }
}

impl LayerFingerprint {
    /// The fingerprint of `layer`, called `name`.
    pub fn of(name: &Name, layer: &ScatterLayer) -> Self {
        Self {
            name: name.as_str().to_owned(),
            seed: layer.seed,
            lattice: format!("{:?}", layer.lattice),
            tile_size: layer.tile_size.to_bits(),
            classes: layer.classes.len().min(u16::MAX as usize) as u16,
            description: fnv1a(description(layer).as_bytes()),
        }
    }

    fn differences(&self, client: &LayerFingerprint) -> Vec<Difference> {
        let name = || self.name.clone();
        let fields = [
            (
                LayerField::Seed,
                self.seed.to_string(),
                client.seed.to_string(),
            ),
            (
                LayerField::Lattice,
                self.lattice.clone(),
                client.lattice.clone(),
            ),
            (
                LayerField::TileSize,
                f64::from_bits(self.tile_size).to_string(),
                f64::from_bits(client.tile_size).to_string(),
            ),
            (
                LayerField::Classes,
                self.classes.to_string(),
                client.classes.to_string(),
            ),
            (
                LayerField::Description,
                format!("{:016x}", self.description),
                format!("{:016x}", client.description),
            ),
        ];
        fields
            .into_iter()
            .filter(|(_, s, c)| s != c)
            .map(|(field, server, client)| Difference {
                what: Mismatch::Layer(name(), field),
                server,
                client,
            })
            .collect()
    }
}

/// What a refused client differs in.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Mismatch {
    /// The crate's message version.
    Protocol,
    /// The game's content version.
    WorldVersion,
    /// The tile set.
    TileSet,
    /// More layers than [`MAX_LAYERS`].
    Layers,
    /// A layer the server has and the client lacks.
    MissingLayer(String),
    /// A layer the client has and the server lacks.
    ExtraLayer(String),
    /// A field of a layer both have.
    Layer(String, LayerField),
}

/// A field of a [`LayerFingerprint`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum LayerField {
    /// The tiling seed.
    Seed,
    /// The lattice.
    Lattice,
    /// The tile size.
    TileSize,
    /// The number of classes.
    Classes,
    /// The densities and filters.
    Description,
}

/// One difference: what, and its value on each side.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Difference {
    /// What differs.
    pub what: Mismatch,
    /// The server's value.
    pub server: String,
    /// The client's value.
    pub client: String,
}

impl fmt::Display for Difference {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        let (server, client) = (&self.server, &self.client);
        match &self.what {
            Mismatch::Protocol => write!(f, "protocol {client}, the server's is {server}"),
            Mismatch::WorldVersion => write!(f, "world version {client}, the server's is {server}"),
            Mismatch::TileSet => write!(f, "tile set {client}, the server's is {server}"),
            Mismatch::Layers => write!(f, "{client} layers, over the limit of {MAX_LAYERS}"),
            Mismatch::MissingLayer(name) => write!(f, "no layer \"{name}\" (the server has one)"),
            Mismatch::ExtraLayer(name) => write!(f, "a layer \"{name}\" the server lacks"),
            Mismatch::Layer(name, field) => {
                write!(
                    f,
                    "layer \"{name}\": {field:?} {client}, the server's is {server}"
                )
            }
        }
    }
}

/// Why the server refused this client: every difference, named.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize, thiserror::Error)]
#[error("the server refused this client: {}", list(.differences))]
pub struct JoinRefused {
    /// What differs.
    pub differences: Vec<Difference>,
}

fn list(differences: &[Difference]) -> String {
    let items: Vec<String> = differences.iter().map(ToString::to_string).collect();
    items.join("; ")
}

/// The text of what decides a layer's points beyond its tiling: densities (a painted map
/// by its asset path, else by its place and scale), exclusion, falloff, plane, per-area
/// scaling, height range and slope limit. Code (a custom density, the ground's height
/// function) has no text: [`crate::NetConfig::world_version`] covers it.
fn description(layer: &ScatterLayer) -> String {
    let densities: Vec<String> = layer.classes.iter().map(|c| density(&c.density)).collect();
    format!(
        "{densities:?} exclusion {:?} falloff {:?} plane {:?} per_area {} height {:?} slope {:?}",
        layer.exclusion.as_ref().map(density),
        layer.falloff,
        layer.plane,
        layer.per_area,
        layer.height_range,
        layer.max_slope,
    )
}

fn density(d: &LayerDensity) -> String {
    match d {
        LayerDensity::Image(map) => {
            let path = map.image.path().map(|p| p.to_string()).unwrap_or_default();
            format!("image {path} {} {} {}", map.min, map.size, map.scale)
        }
        other => format!("{other:?}"),
    }
}
