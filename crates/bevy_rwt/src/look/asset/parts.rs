//! An asset's node tree split into what is drawn at each level of detail and what only
//! collides, by the names exporters give nodes: `<name>_LOD0`, `_LOD1`… (Unreal's, Unity's
//! and Blender's convention) and `UCX_<name>` (Unreal), `<name>_collider`, `-colonly` and
//! `-convcolonly` (Godot). Each part keeps its transform relative to the asset's root.

use bevy::prelude::*;
use std::collections::BTreeMap;

/// A node of an asset's tree as the file gives it: a name, a transform relative to its
/// parent, the primitives it draws (`P`: a mesh and its material) and its children.
#[derive(Clone, Debug, PartialEq)]
pub struct AssetNode<P> {
    /// The node's name in the file (empty when it has none).
    pub name: String,
    /// Its transform relative to its parent.
    pub transform: Transform,
    /// The primitives of its mesh, if it has one.
    pub primitives: Vec<P>,
    /// Its children.
    pub children: Vec<AssetNode<P>>,
    /// The fraction of the screen's height down to which each level under it is shown,
    /// nearest first, when the file hints it (`MSFT_screencoverage`); empty otherwise.
    pub coverage: Vec<f32>,
}

impl<P> AssetNode<P> {
    /// A node with no primitives and no children.
    pub fn new(name: impl Into<String>, transform: Transform) -> Self {
        Self {
            name: name.into(),
            transform,
            primitives: Vec::new(),
            children: Vec::new(),
            coverage: Vec::new(),
        }
    }

    /// This node, hinting the screen coverage of the levels under it.
    pub fn with_coverage(mut self, coverage: Vec<f32>) -> Self {
        self.coverage = coverage;
        self
    }

    /// This node, drawing `primitives`.
    pub fn with_primitives(mut self, primitives: impl IntoIterator<Item = P>) -> Self {
        self.primitives.extend(primitives);
        self
    }

    /// This node, with `children`.
    pub fn with_children(mut self, children: impl IntoIterator<Item = AssetNode<P>>) -> Self {
        self.children.extend(children);
        self
    }
}

/// A primitive with its transform relative to the asset's root.
#[derive(Clone, Debug, PartialEq)]
pub struct Placed<P> {
    /// The primitive.
    pub primitive: P,
    /// Where it stands in the asset's frame (the root's own transform left out).
    pub transform: Transform,
}

/// What a node's name makes of it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum NodeRole {
    /// A level of detail: the node and everything under it are drawn at that level only.
    Level(u32),
    /// A collision shape: never drawn, handed to promotion's inserter.
    Collider,
    /// Anything else: drawn at the level of the nearest level node above it, at every level
    /// when there is none.
    Plain,
}

impl NodeRole {
    /// The role of a node called `name`.
    pub fn of(name: &str) -> Self {
        let lower = name.to_ascii_lowercase();
        let collider = lower.starts_with("ucx_")
            || ["_collider", "-colonly", "-convcolonly"]
                .iter()
                .any(|suffix| lower.ends_with(suffix));
        if collider {
            return NodeRole::Collider;
        }
        match lower.rfind("_lod") {
            Some(at) => {
                let digits = &lower[at + 4..];
                match digits.parse::<u32>() {
                    Ok(level)
                        if !digits.is_empty() && digits.bytes().all(|b| b.is_ascii_digit()) =>
                    {
                        NodeRole::Level(level)
                    }
                    _ => NodeRole::Plain,
                }
            }
            None => NodeRole::Plain,
        }
    }
}

/// An asset's primitives, split by their nodes' names.
#[derive(Clone, Debug, PartialEq)]
pub struct AssetParts<P> {
    /// What each level of detail draws, nearest first: the levels the names give, in the
    /// order of their numbers (numbers need not follow each other), each with the parts
    /// outside any level node; one level when no node names one.
    pub levels: Vec<Vec<Placed<P>>>,
    /// The primitives of collider nodes, never drawn.
    pub colliders: Vec<Placed<P>>,
    /// The screen coverage hint of the levels (the first node's in the tree that has one;
    /// see [`AssetNode::coverage`]).
    pub coverage: Vec<f32>,
}

impl<P: Clone> AssetParts<P> {
    /// Splits the tree under `root` (whose own transform is the asset's frame, left out).
    pub fn split(root: &AssetNode<P>) -> Self {
        let mut found = Found {
            levels: BTreeMap::new(),
            shared: Vec::new(),
            colliders: Vec::new(),
            coverage: root.coverage.clone(),
        };
        found.place(&root.primitives, Transform::IDENTITY, Bin::Shared);
        for child in &root.children {
            found.walk(child, Transform::IDENTITY, Bin::Shared);
        }
        let levels = match found.levels.is_empty() {
            true => vec![found.shared],
            false => found
                .levels
                .into_values()
                .map(|mut parts| {
                    parts.extend(found.shared.iter().cloned());
                    parts
                })
                .collect(),
        };
        AssetParts {
            levels,
            colliders: found.colliders,
            coverage: found.coverage,
        }
    }
}

/// Where a node's primitives go.
#[derive(Clone, Copy)]
enum Bin {
    /// Drawn at every level: under no level node.
    Shared,
    /// Drawn at this level only.
    Level(u32),
    /// Never drawn: under a collider node.
    Collider,
}

/// The parts found so far, while walking the tree.
struct Found<P> {
    /// Each named level's parts, in the order of the levels' numbers.
    levels: BTreeMap<u32, Vec<Placed<P>>>,
    /// Parts under no level node.
    shared: Vec<Placed<P>>,
    colliders: Vec<Placed<P>>,
    coverage: Vec<f32>,
}

impl<P: Clone> Found<P> {
    /// Adds `node` (under `parent`, relative to the root) and what is under it; `bin` is
    /// where its parent's primitives went. A collider's subtree is all collider.
    fn walk(&mut self, node: &AssetNode<P>, parent: Transform, bin: Bin) {
        let transform = parent.mul_transform(node.transform);
        let bin = match (bin, NodeRole::of(&node.name)) {
            (Bin::Collider, _) | (_, NodeRole::Collider) => Bin::Collider,
            (_, NodeRole::Level(n)) => Bin::Level(n),
            (bin, NodeRole::Plain) => bin,
        };
        self.place(&node.primitives, transform, bin);
        if self.coverage.is_empty() {
            self.coverage.clone_from(&node.coverage);
        }
        for child in &node.children {
            self.walk(child, transform, bin);
        }
    }

    fn place(&mut self, primitives: &[P], transform: Transform, bin: Bin) {
        let parts = match bin {
            Bin::Shared => &mut self.shared,
            Bin::Level(n) => self.levels.entry(n).or_default(),
            Bin::Collider => &mut self.colliders,
        };
        parts.extend(primitives.iter().cloned().map(|primitive| Placed {
            primitive,
            transform,
        }));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn at(x: f32) -> Transform {
        Transform::from_xyz(x, 0.0, 0.0)
    }

    fn names(parts: &[Placed<&'static str>]) -> Vec<&'static str> {
        let mut out: Vec<_> = parts.iter().map(|p| p.primitive).collect();
        out.sort();
        out
    }

    #[test]
    fn names_give_levels_colliders_and_plain_nodes() {
        assert_eq!(NodeRole::of("Oak_LOD0"), NodeRole::Level(0));
        assert_eq!(NodeRole::of("oak_lod12"), NodeRole::Level(12));
        assert_eq!(NodeRole::of("UCX_Oak_00"), NodeRole::Collider);
        assert_eq!(NodeRole::of("trunk_collider"), NodeRole::Collider);
        assert_eq!(NodeRole::of("rock-colonly"), NodeRole::Collider);
        assert_eq!(NodeRole::of("rock-convcolonly"), NodeRole::Collider);
        for plain in [
            "Oak",
            "Oak_LOD",
            "Oak_LODx",
            "Oak_LOD-1",
            "slodge",
            "LOD0",
            "",
        ] {
            assert_eq!(NodeRole::of(plain), NodeRole::Plain, "{plain}");
        }
    }

    #[test]
    fn a_tree_without_names_is_one_level_with_every_primitive_placed() {
        let root = AssetNode::new("oak", at(100.0))
            .with_primitives(["root mesh"])
            .with_children([AssetNode::new("trunk", at(1.0))
                .with_primitives(["bark", "leaves"])
                .with_children([AssetNode::new("branch", at(2.0)).with_primitives(["twig"])])]);
        let parts = AssetParts::split(&root);
        assert_eq!(parts.levels.len(), 1);
        assert!(parts.colliders.is_empty());
        let level = &parts.levels[0];
        assert_eq!(names(level), ["bark", "leaves", "root mesh", "twig"]);
        // Relative to the root: the root's own 100 m is left out, the chain composes.
        let x = |name| {
            level
                .iter()
                .find(|p| p.primitive == name)
                .unwrap()
                .transform
                .translation
                .x
        };
        assert_eq!((x("root mesh"), x("bark"), x("twig")), (0.0, 1.0, 3.0));
    }

    #[test]
    fn level_nodes_split_the_tree_in_their_numbers_order_and_share_the_rest() {
        let root = AssetNode::new("rock", Transform::IDENTITY).with_children([
            AssetNode::new("rock_LOD2", at(0.0)).with_primitives(["far"]),
            AssetNode::new("rock_LOD0", at(0.0))
                .with_primitives(["near"])
                .with_children([AssetNode::new("moss", at(0.5)).with_primitives(["moss"])]),
            AssetNode::new("UCX_rock", at(0.0)).with_primitives(["hull"]),
            AssetNode::new("base", at(0.0)).with_primitives(["base"]),
        ]);
        let parts = AssetParts::split(&root);
        assert_eq!(parts.levels.len(), 2);
        assert_eq!(names(&parts.levels[0]), ["base", "moss", "near"]);
        assert_eq!(names(&parts.levels[1]), ["base", "far"]);
        assert_eq!(names(&parts.colliders), ["hull"]);
    }

    #[test]
    fn everything_under_a_collider_collides_and_is_never_drawn() {
        let root = AssetNode::new("bush", Transform::IDENTITY).with_children([
            AssetNode::new("bush_collider", at(1.0)).with_children([AssetNode::new(
                "piece_LOD0",
                at(1.0),
            )
            .with_primitives(["hull"])]),
            AssetNode::new("leaves", at(0.0)).with_primitives(["leaves"]),
        ]);
        let parts = AssetParts::split(&root);
        assert_eq!(names(&parts.levels[0]), ["leaves"]);
        assert_eq!(names(&parts.colliders), ["hull"]);
        assert_eq!(parts.colliders[0].transform.translation.x, 2.0);
    }
}
