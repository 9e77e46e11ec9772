//! A class drawn from a game's own glTF asset ([`AssetLook`]): every primitive under a
//! scene or a node, with its material ([`InstancedSurface`]) and its transform relative to
//! the asset's root; levels of detail and colliders from the nodes' names ([`AssetParts`]).

#[cfg(feature = "gltf")]
mod file;
mod parts;
#[cfg(feature = "gltf")]
mod resolve;
mod surface;

#[cfg(feature = "gltf")]
pub use file::{
    AssetPrimitive, AssetRoot, AssetTreeError, MAX_ASSET_DEPTH, asset_tree, file_tree, node_tree,
};
pub use parts::{AssetNode, AssetParts, NodeRole, Placed};
#[cfg(feature = "gltf")]
pub use resolve::{
    AssetCollider, AssetLods, AssetLook, AssetLookError, AssetPart, GltfAssets, ResolvedAsset,
    resolve_asset,
};
pub use surface::{InstancedSurface, SurfaceAlpha, SurfaceError};
