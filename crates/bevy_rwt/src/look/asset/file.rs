//! A loaded glTF file as an asset's node tree: the primitives under a node (or under every
//! root node of the file), each as its mesh and material handles, ready for
//! [`AssetParts::split`](super::AssetParts::split). A node with `MSFT_lod` becomes a node
//! over `<name>_LOD0` (its own content), `<name>_LOD1`… (the nodes it names), as levels
//! named in the file are.

use super::msft_lod::MsftLods;
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
    /// A node's `MSFT_lod` names a node the loaded file does not hold.
    #[error("the MSFT_lod of node {node:?} names node {level}, which the file does not hold")]
    NoSuchLevel {
        /// The node with the extension.
        node: String,
        /// The index it names.
        level: usize,
    },
}

/// The loaded assets an asset's tree is read from.
#[derive(Clone, Copy)]
pub struct GltfAssets<'a> {
    /// The files' nodes.
    pub nodes: &'a Assets<GltfNode>,
    /// The files' meshes.
    pub meshes: &'a Assets<GltfMesh>,
    /// The files' materials.
    pub materials: &'a Assets<GltfMaterial>,
    /// The file's `MSFT_lod` nodes (see [`super::MsftLodHandler`]); `None` reads none.
    pub lods: Option<&'a MsftLods>,
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
    from: GltfAssets,
) -> Result<AssetNode<AssetPrimitive>, AssetTreeError> {
    let reader = Reader { gltf, from };
    match root {
        AssetRoot::File => reader.file(),
        AssetRoot::Node(name) => {
            let node = gltf
                .named_nodes
                .get(name.as_str())
                .ok_or_else(|| AssetTreeError::NoSuchNode(name.clone()))?;
            reader.node(node, 0)
        }
        AssetRoot::Scene(index) => {
            if *index >= gltf.scenes.len() {
                return Err(AssetTreeError::NoSuchScene(*index));
            }
            let Some(source) = &gltf.source else {
                return match gltf.scenes.len() {
                    1 => reader.file(),
                    _ => Err(AssetTreeError::SceneWithoutSource(*index)),
                };
            };
            let scene = source
                .scenes()
                .nth(*index)
                .ok_or(AssetTreeError::NoSuchScene(*index))?;
            let roots = scene.nodes().filter_map(|n| gltf.nodes.get(n.index()));
            reader.roots(roots)
        }
    }
}

/// Reads trees of one loaded file.
struct Reader<'a> {
    gltf: &'a Gltf,
    from: GltfAssets<'a>,
}

impl Reader<'_> {
    /// The whole file as one tree: a nameless root at the origin whose children are the
    /// file's root nodes (those that are no other node's child nor another's `MSFT_lod`
    /// level), in the file's order.
    fn file(&self) -> Result<AssetNode<AssetPrimitive>, AssetTreeError> {
        let mut children = HashSet::new();
        for handle in &self.gltf.nodes {
            let node = self.get(handle)?;
            children.extend(node.children.iter().map(Handle::id));
        }
        let alternates = self.from.lods.map(MsftLods::alternates).unwrap_or_default();
        let roots = self
            .gltf
            .nodes
            .iter()
            .enumerate()
            .filter(|(i, h)| !children.contains(&h.id()) && !alternates.contains(i));
        self.roots(roots.map(|(_, h)| h))
    }

    /// A nameless root at the origin over the trees of `roots`.
    fn roots<'h>(
        &self,
        roots: impl Iterator<Item = &'h Handle<GltfNode>>,
    ) -> Result<AssetNode<AssetPrimitive>, AssetTreeError> {
        let trees = roots
            .map(|root| self.node(root, 0))
            .collect::<Result<Vec<_>, _>>()?;
        Ok(AssetNode::new("", Transform::IDENTITY).with_children(trees))
    }

    fn get(&self, handle: &Handle<GltfNode>) -> Result<&GltfNode, AssetTreeError> {
        self.from
            .nodes
            .get(handle)
            .ok_or_else(|| AssetTreeError::NotLoaded(format!("{handle:?}")))
    }

    /// The tree under a node, its `MSFT_lod` levels as level nodes.
    fn node(
        &self,
        handle: &Handle<GltfNode>,
        depth: usize,
    ) -> Result<AssetNode<AssetPrimitive>, AssetTreeError> {
        if depth >= MAX_ASSET_DEPTH {
            return Err(AssetTreeError::TooDeep);
        }
        let node = self.get(handle)?;
        let own = self.plain(node, depth)?;
        let lod = self.from.lods.and_then(|l| l.nodes.get(&node.index));
        let Some(lod) = lod.filter(|l| !l.ids.is_empty()) else {
            return Ok(own);
        };
        let level = |k: usize, mut tree: AssetNode<AssetPrimitive>, transform: Transform| {
            tree.transform = transform;
            AssetNode::new(format!("{}_LOD{k}", node.name), Transform::IDENTITY)
                .with_children([tree])
        };
        let mut levels = vec![level(0, own, Transform::IDENTITY)];
        let into_node = node.transform.to_matrix().inverse();
        for (k, id) in lod.ids.iter().enumerate() {
            let missing = || AssetTreeError::NoSuchLevel {
                node: node.name.clone(),
                level: *id,
            };
            let alternate = self.gltf.nodes.get(*id).ok_or_else(missing)?;
            let tree = self.node(alternate, depth + 1)?;
            let transform = Transform::from_matrix(into_node * tree.transform.to_matrix());
            levels.push(level(k + 1, tree, transform));
        }
        Ok(AssetNode::new(node.name.clone(), node.transform)
            .with_children(levels)
            .with_coverage(lod.coverage.clone()))
    }

    /// A node as the file has it: its primitives and the trees of its children.
    fn plain(
        &self,
        node: &GltfNode,
        depth: usize,
    ) -> Result<AssetNode<AssetPrimitive>, AssetTreeError> {
        let primitives = match &node.mesh {
            Some(mesh) => {
                let mesh = self
                    .from
                    .meshes
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
            .map(|child| self.node(child, depth + 1))
            .collect::<Result<Vec<_>, _>>()?;
        Ok(AssetNode::new(node.name.clone(), node.transform)
            .with_primitives(primitives)
            .with_children(children))
    }
}
