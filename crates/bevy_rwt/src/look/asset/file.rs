//! A loaded glTF file as an asset's node tree: the primitives under a node (or under every
//! root node of the file), each as its mesh and material handles, ready for
//! [`AssetParts::split`](super::AssetParts::split).

use super::parts::AssetNode;
use bevy::gltf::{Gltf, GltfMaterial, GltfMesh, GltfNode};
use bevy::prelude::*;
use std::collections::HashSet;

/// The deepest node tree read (glTF forbids cycles; a file that nests deeper is refused).
pub const MAX_ASSET_DEPTH: usize = 64;

/// A primitive of a glTF asset: its mesh and its material (none: glTF's default material).
#[derive(Clone, Debug, PartialEq)]
pub struct AssetPrimitive {
    /// The primitive's mesh.
    pub mesh: Handle<Mesh>,
    /// The primitive's material.
    pub material: Option<Handle<GltfMaterial>>,
}

/// Why a loaded file's tree cannot be read (yet).
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum AssetTreeError {
    /// A node or mesh of the file is not loaded yet.
    #[error("node or mesh {0} of the asset is not loaded yet")]
    NotLoaded(String),
    /// The tree nests deeper than [`MAX_ASSET_DEPTH`].
    #[error("the asset's nodes nest deeper than {MAX_ASSET_DEPTH}")]
    TooDeep,
    /// The file has no node of that name.
    #[error("the asset has no node named {0:?}")]
    NoSuchNode(String),
    /// The file has no scene of that index.
    #[error("the asset has no scene {0}")]
    NoSuchScene(usize),
    /// A scene of a file of several is asked for, but the loader kept no source to tell
    /// which nodes it holds (load it with `GltfLoaderSettings::include_source`).
    #[error("scene {0} of a file of several scenes needs the file loaded with its source")]
    SceneWithoutSource(usize),
}

/// Which part of a file is the asset.
#[derive(Clone, Debug, Default, PartialEq, Eq, Hash, Reflect)]
#[reflect(Clone, Debug, Default, PartialEq, Hash)]
pub enum AssetRoot {
    /// Every root node of the file.
    #[default]
    File,
    /// The root nodes of a scene (`"oak.glb#Scene0"` is scene 0).
    Scene(usize),
    /// A node, by name, and what is under it.
    Node(String),
}

/// The tree of `root` in a loaded file: a nameless root at the origin over the scene's or
/// the file's root nodes, or the named node itself.
pub fn asset_tree(
    gltf: &Gltf,
    root: &AssetRoot,
    nodes: &Assets<GltfNode>,
    meshes: &Assets<GltfMesh>,
) -> Result<AssetNode<AssetPrimitive>, AssetTreeError> {
    match root {
        AssetRoot::File => file_tree(gltf, nodes, meshes),
        AssetRoot::Node(name) => {
            let node = gltf
                .named_nodes
                .get(name.as_str())
                .ok_or_else(|| AssetTreeError::NoSuchNode(name.clone()))?;
            node_tree(node, nodes, meshes)
        }
        AssetRoot::Scene(index) => {
            if *index >= gltf.scenes.len() {
                return Err(AssetTreeError::NoSuchScene(*index));
            }
            let Some(source) = &gltf.source else {
                return match gltf.scenes.len() {
                    1 => file_tree(gltf, nodes, meshes),
                    _ => Err(AssetTreeError::SceneWithoutSource(*index)),
                };
            };
            let scene = source
                .scenes()
                .nth(*index)
                .ok_or(AssetTreeError::NoSuchScene(*index))?;
            let roots = scene.nodes().filter_map(|n| gltf.nodes.get(n.index()));
            roots_tree(roots, nodes, meshes)
        }
    }
}

/// The tree under `node`, read from the loaded file's node and mesh assets.
pub fn node_tree(
    node: &Handle<GltfNode>,
    nodes: &Assets<GltfNode>,
    meshes: &Assets<GltfMesh>,
) -> Result<AssetNode<AssetPrimitive>, AssetTreeError> {
    read_node(node, nodes, meshes, 0)
}

/// The whole file as one tree: a nameless root at the origin whose children are the file's
/// root nodes (those that are no other node's child), in the file's order.
pub fn file_tree(
    gltf: &Gltf,
    nodes: &Assets<GltfNode>,
    meshes: &Assets<GltfMesh>,
) -> Result<AssetNode<AssetPrimitive>, AssetTreeError> {
    let mut children = HashSet::new();
    for handle in &gltf.nodes {
        let node = nodes
            .get(handle)
            .ok_or_else(|| AssetTreeError::NotLoaded(format!("{handle:?}")))?;
        children.extend(node.children.iter().map(Handle::id));
    }
    let roots = gltf.nodes.iter().filter(|h| !children.contains(&h.id()));
    roots_tree(roots, nodes, meshes)
}

/// A nameless root at the origin over the trees of `roots`.
fn roots_tree<'a>(
    roots: impl Iterator<Item = &'a Handle<GltfNode>>,
    nodes: &Assets<GltfNode>,
    meshes: &Assets<GltfMesh>,
) -> Result<AssetNode<AssetPrimitive>, AssetTreeError> {
    let trees = roots
        .map(|root| node_tree(root, nodes, meshes))
        .collect::<Result<Vec<_>, _>>()?;
    Ok(AssetNode::new("", Transform::IDENTITY).with_children(trees))
}

fn read_node(
    handle: &Handle<GltfNode>,
    nodes: &Assets<GltfNode>,
    meshes: &Assets<GltfMesh>,
    depth: usize,
) -> Result<AssetNode<AssetPrimitive>, AssetTreeError> {
    if depth >= MAX_ASSET_DEPTH {
        return Err(AssetTreeError::TooDeep);
    }
    let node = nodes
        .get(handle)
        .ok_or_else(|| AssetTreeError::NotLoaded(format!("{handle:?}")))?;
    let primitives = match &node.mesh {
        Some(mesh) => {
            let mesh = meshes
                .get(mesh)
                .ok_or_else(|| AssetTreeError::NotLoaded(node.name.clone()))?;
            mesh.primitives
                .iter()
                .map(|p| AssetPrimitive {
                    mesh: p.mesh.clone(),
                    material: p.material.clone(),
                })
                .collect()
        }
        None => Vec::new(),
    };
    let children = node
        .children
        .iter()
        .map(|child| read_node(child, nodes, meshes, depth + 1))
        .collect::<Result<Vec<_>, _>>()?;
    Ok(AssetNode::new(node.name.clone(), node.transform)
        .with_primitives(primitives)
        .with_children(children))
}
