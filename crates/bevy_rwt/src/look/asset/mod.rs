//! A class drawn from a game's own glTF asset ([`AssetLook`]): every primitive under a
//! scene or a node, with its material ([`InstancedSurface`]) and its transform relative to
//! the asset's root; levels of detail and colliders from the nodes' names ([`AssetParts`])
//! or glTF's `MSFT_lod` extension ([`MsftLods`]).

#[cfg(feature = "gltf")]
mod file;
#[cfg(feature = "gltf")]
mod msft_lod;
mod parts;
#[cfg(feature = "gltf")]
mod resolve;
mod surface;

#[cfg(feature = "gltf")]
pub use file::{
    AssetPrimitive, AssetRoot, AssetTreeError, GltfAssets, MAX_ASSET_DEPTH, asset_tree,
};
#[cfg(feature = "gltf")]
pub use msft_lod::{
    MAX_MSFT_LEVELS, MsftLod, MsftLodHandler, MsftLodTable, MsftLods, register as register_msft_lod,
};
pub use parts::{AssetNode, AssetParts, NodeRole, Placed};
#[cfg(feature = "gltf")]
pub use resolve::{
    AssetCollider, AssetLods, AssetLook, AssetLookError, AssetPart, ResolvedAsset, resolve_asset,
};
pub use surface::{InstancedSurface, SurfaceAlpha, SurfaceError};
