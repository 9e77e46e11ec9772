//! The settings every peer shares.

use bevy::prelude::*;

/// How the server treats its clients, and what every peer must agree on.
#[derive(Resource, Clone, Debug, PartialEq, Reflect)]
#[reflect(Resource)]
pub struct NetConfig {
    /// The game's content version: peers must have the same. Bump it when code that
    /// decides points changes (a custom density, the ground).
    pub world_version: u64,
    /// Edit requests a client may send per second, on average.
    pub requests_per_second: f32,
    /// Edit requests a client may send at once.
    pub request_burst: u32,
    /// Screened requests the server holds in a frame, over all clients.
    pub max_pending: usize,
    /// Largest slice of an edits file in one join message, in bytes.
    pub join_part_bytes: usize,
}

impl Default for NetConfig {
    fn default() -> Self {
        Self {
            world_version: 0,
            requests_per_second: 20.0,
            request_burst: 64,
            max_pending: 4096,
            join_part_bytes: 16 * 1024,
        }
    }
}
