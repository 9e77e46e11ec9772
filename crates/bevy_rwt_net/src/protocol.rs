//! The two messages that cross the network, one each way, each on one ordered reliable
//! channel (so a join always arrives before the live edits that follow it), and the one
//! replicated component ([`NetFootprint`]).

use crate::fingerprint::{JoinRefused, WorldFingerprint};
use crate::footprint::NetFootprint;
use bevy::prelude::*;
use bevy_replicon::bytes::Bytes;
use bevy_replicon::postcard_utils;
use bevy_replicon::prelude::*;
use bevy_replicon::shared::message::ctx::{ClientSendCtx, ServerReceiveCtx};
use bevy_rwt::edits::{EditInstance, InstanceEdit};
use bevy_rwt::rwt_core::query::PointId;
use serde::{Deserialize, Serialize};

/// From a client to the server.
#[derive(Message, Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum ClientNet {
    /// The first message: what the client's world is made of.
    Hello(WorldFingerprint),
    /// A request to edit one instance.
    Edit(WireEdit),
    /// Bytes that decode to no message (never sent: what the server reads from a broken or
    /// hostile client, so that it is counted).
    #[serde(skip)]
    Garbled,
}

/// From the server to a client.
#[derive(Message, Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum ServerNet {
    /// The handshake failed: what differs. The server disconnects the client next.
    Refused(JoinRefused),
    /// The handshake passed: the server's named layers, in the order [`WireEdit::layer`]
    /// indexes them. The edits of each follow as [`ServerNet::JoinPart`]s.
    Welcome {
        /// Layer names.
        layers: Vec<String>,
    },
    /// A slice of one layer's edits file (`rwt_core`'s edits format, stamped with the
    /// layer's seed, lattice and tile set).
    JoinPart {
        /// The layer's index in [`ServerNet::Welcome`].
        layer: u16,
        /// Whether this is the file's last slice.
        last: bool,
        /// The slice.
        bytes: Vec<u8>,
    },
    /// Edits the server applied, in order.
    Edits(Vec<WireEdit>),
    /// The server's world changed (its named layers, tile set or world version): the
    /// client shakes hands again, with its world as it is now.
    Recheck,
}

/// One instance edit on the wire: the layer by index, the point by identity.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct WireEdit {
    /// The layer's index in the server's [`ServerNet::Welcome`].
    pub layer: u16,
    /// The point's level.
    pub level: u8,
    /// Its tile's column at that level.
    pub x: i64,
    /// Its tile's row.
    pub y: i64,
    /// Its index in the tile.
    pub index: u16,
    /// What to do.
    pub edit: WireKind,
}

/// What a [`WireEdit`] does.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum WireKind {
    /// [`InstanceEdit::Remove`].
    Remove,
    /// [`InstanceEdit::Restore`].
    Restore,
    /// [`InstanceEdit::Reclass`].
    Reclass(u16),
}

impl WireEdit {
    /// `edit` of the layer at `layer` in the welcome's list.
    pub fn new(layer: u16, edit: &EditInstance) -> Self {
        let PointId { level, x, y, index } = edit.id;
        let edit = match edit.edit {
            InstanceEdit::Remove => WireKind::Remove,
            InstanceEdit::Restore => WireKind::Restore,
            InstanceEdit::Reclass(c) => WireKind::Reclass(c),
        };
        Self {
            layer,
            level,
            x,
            y,
            index,
            edit,
        }
    }

    /// The edit for the layer entity `layer`.
    pub fn to_instance(self, layer: Entity) -> EditInstance {
        let id = PointId {
            level: self.level,
            x: self.x,
            y: self.y,
            index: self.index,
        };
        let edit = match self.edit {
            WireKind::Remove => InstanceEdit::Remove,
            WireKind::Restore => InstanceEdit::Restore,
            WireKind::Reclass(c) => InstanceEdit::Reclass(c),
        };
        EditInstance { layer, id, edit }
    }
}

/// Registers both messages and the replicated footprint (the same order on every peer: it
/// is part of replicon's protocol hash).
pub(crate) fn register(app: &mut App) {
    app.replicate::<NetFootprint>()
        .add_client_message_with(Channel::Ordered, serialize_client, deserialize_client)
        .add_server_message::<ServerNet>(Channel::Ordered)
        // The world's messages need no replicated entity first.
        .make_message_independent::<ServerNet>();
}

fn serialize_client(_: &mut ClientSendCtx, message: &ClientNet, bytes: &mut Vec<u8>) -> Result {
    postcard_utils::to_extend_mut(message, bytes)?;
    Ok(())
}

/// Decodes a client's message; bytes that are none become [`ClientNet::Garbled`], which
/// the server counts (replicon would drop them unseen).
fn deserialize_client(_: &mut ServerReceiveCtx, bytes: &mut Bytes) -> Result<ClientNet> {
    Ok(postcard_utils::from_buf(bytes).unwrap_or(ClientNet::Garbled))
}
