//! A class drawn from a game's own glTF asset: every primitive under a scene or a node, with
//! its material and its transform relative to the asset's root; levels of detail and
//! colliders from the nodes' names ([`AssetParts`]).

mod parts;

pub use parts::{AssetNode, AssetParts, NodeRole, Placed};
