//! Multiplayer for [`bevy_rwt`]: every player sees the same scattered world, and only edits
//! cross the network.
//!
//! A scattered world is a pure function of the tile set, each layer's seed and densities,
//! and the edits: so peers that agree on the first three need only share the edits (a few
//! bytes each). [`RwtNetPlugin`] does that on [`bevy_replicon`] (server-authoritative
//! messages over the transport the game picks: renet, aeronet, quinnet...):
//!
//! - **Handshake.** A connecting client sends its [`WorldFingerprint`] (tile set, each
//!   named layer's seed, lattice, tile size, classes and densities, the game's
//!   [`NetConfig::world_version`]); the server refuses a client that differs, naming every
//!   difference ([`JoinRefused`], in the client's [`NetClientStatus`]), and disconnects it.
//! - **Join.** An accepted client gets every layer's edits as `rwt_core`'s edits file (about
//!   2 bytes an edit), which replace its own: after a reconnect or a server restarted from
//!   its save, the client has the server's world.
//! - **Edits.** On a client, the game's [`EditInstance`](bevy_rwt::edits::EditInstance)s
//!   become requests; the server screens them (joined, a layer it has, a storable level,
//!   the client's rate, the game's [`EditPermission`]), applies them, and sends every
//!   applied edit, its own game's too, to every joined client. Refused requests are counted
//!   by reason ([`NetServerStats`], [`NetPeer`]); nothing a client sends can panic the
//!   server or grow its memory past [`NetConfig`]'s limits.
//! - **Footprints.** A [`NetFootprint`] the server spawns (a cabin, a camp) is replicated,
//!   and clears the same ground on every peer.
//! - **A changing server.** A server that loads a save ([`bevy_rwt::save::LoadWorld`])
//!   sends every joined client the join again; one whose named layers, tile set or world
//!   version change asks its clients to shake hands again, and refuses those that no longer
//!   match.
//!
//! Layers are matched by their `Name` (as saves match them); unnamed layers stay local.
//! Code that decides points (a custom density, the ground's height function) has no
//! fingerprint: bump [`NetConfig::world_version`] when it changes.
//!
//! Add the plugin after replicon's and the transport's, on the server and on clients alike
//! (the same app can be either: replicon's states pick which part runs).

mod client;
mod config;
mod fingerprint;
mod footprint;
mod index;
mod protocol;
mod server;

pub use client::{NetClientStats, NetClientStatus};
pub use config::NetConfig;
pub use fingerprint::{
    Difference, JoinRefused, LayerField, LayerFingerprint, MAX_LAYERS, Mismatch, PROTOCOL,
    WorldFingerprint,
};
pub use footprint::NetFootprint;
pub use protocol::{ClientNet, ServerNet, WireEdit, WireKind};
pub use server::{EditPermission, EditRequest, NetPeer, NetServerStats, Refusals};

use bevy::prelude::*;

/// Multiplayer for the scatter layers: add it to the server and to every client.
#[derive(Default)]
pub struct RwtNetPlugin {
    /// The settings.
    pub config: NetConfig,
}

impl Plugin for RwtNetPlugin {
    fn build(&self, app: &mut App) {
        app.insert_resource(self.config.clone())
            .register_type::<NetServerStats>()
            .register_type::<NetClientStats>();
        protocol::register(app);
        server::plugin(app);
        client::plugin(app);
        footprint::plugin(app);
    }
}
