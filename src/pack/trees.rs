//! Trees as a game's artist would ship them: a trunk of bark (albedo and normal map) under a
//! crown of alpha-masked leaf cards, at two levels of detail (`_LOD0`, `_LOD1`), with a
//! `UCX_` convex hull round the trunk for physics.

use super::cards::{Card, Hash, cards_mesh};
use super::textures::{Leaves, Maps, bark, birch_bark, leaf_cluster};
use bevy::prelude::*;
use bevy_rwt::testing::glb::{Glb, GlbAlpha, GlbMaterial, GlbNode, GlbPrimitive};

/// The outline leaf cards fill.
#[derive(Clone, Copy, Debug)]
pub enum Crown {
    /// A cone from `base` to `top` (heights), `radius` wide at its base: a spruce's tiers.
    Cone {
        /// Height of its base.
        base: f32,
        /// Height of its tip.
        top: f32,
        /// Radius at its base.
        radius: f32,
    },
    /// An ellipsoid centred at `centre` with these radii.
    Round {
        /// Its centre.
        centre: Vec3,
        /// Its radii.
        radii: Vec3,
    },
}

impl Crown {
    /// A point inside the crown, towards its surface, from three numbers in 0..1; and the
    /// outward direction there.
    fn point(&self, [a, b, c]: [f32; 3]) -> (Vec3, Vec3) {
        match *self {
            Crown::Cone { base, top, radius } => {
                let h = b.powf(0.8);
                let y = base + (top - base) * h;
                let r = radius * (1.0 - h) * (0.55 + 0.45 * c.sqrt());
                let around = Vec2::from_angle(a * std::f32::consts::TAU);
                let at = Vec3::new(around.x * r, y, around.y * r);
                let out = Vec3::new(around.x, 0.35, around.y).normalize();
                (at, out)
            }
            Crown::Round { centre, radii } => {
                let around = Vec2::from_angle(a * std::f32::consts::TAU);
                let up = b * 2.0 - 1.0;
                let ring = (1.0 - up * up).max(0.0).sqrt();
                let dir = Vec3::new(around.x * ring, up, around.y * ring);
                let depth = 0.6 + 0.4 * c.sqrt();
                (centre + dir * radii * depth, dir)
            }
        }
    }

    /// The highest point of the crown.
    fn top(&self) -> f32 {
        match *self {
            Crown::Cone { top, .. } => top,
            Crown::Round { centre, radii } => centre.y + radii.y,
        }
    }
}

/// Trunk radii at the ground of the spruce, the oak and the birch.
pub const TRUNK_RADII: [f32; 3] = [0.28, 0.4, 0.18];
/// The trunk hull's radius, as a fraction of the trunk's.
const HULL: f32 = 1.1;

/// The radius of the `UCX_` hull round the trunk of species `i` (spruce, oak, birch) at
/// scale 1: where a capsule walking into it stops.
pub fn hull_radius(species: usize) -> f32 {
    TRUNK_RADII[species.min(2)] * HULL
}

/// A tree species.
#[derive(Clone, Debug)]
pub struct TreeSpec {
    /// Node name (levels are `<name>_LOD0`, `<name>_LOD1`; the hull `UCX_<name>`).
    pub name: &'static str,
    /// Trunk radius at the ground.
    pub trunk_radius: f32,
    /// Bark textures.
    pub bark: Maps,
    /// The crown.
    pub crown: Crown,
    /// Leaf cards at the near level (the far level has a quarter, twice as large).
    pub cards: u32,
    /// Side of a near card, in metres.
    pub card_size: f32,
    /// The leaf cluster texture (PNG).
    pub leaves: Vec<u8>,
    /// Tint of the leaves (linear).
    pub leaf_tint: [f32; 4],
    /// Random seed of the card placement.
    pub seed: u32,
}

/// A spruce: a straight trunk through a cone of drooping needle sprays.
pub fn spruce() -> TreeSpec {
    TreeSpec {
        name: "spruce",
        trunk_radius: TRUNK_RADII[0],
        bark: bark(3, [0.42, 0.3, 0.2], [0.12, 0.08, 0.05]),
        crown: Crown::Cone {
            base: 1.4,
            top: 9.4,
            radius: 2.8,
        },
        cards: 150,
        card_size: 1.5,
        leaves: leaf_cluster(Leaves {
            count: 26,
            size: (0.28, 0.05),
            colours: ([0.14, 0.3, 0.16], [0.07, 0.18, 0.1]),
            seed: 11,
        }),
        leaf_tint: [1.0, 1.0, 1.0, 1.0],
        seed: 1,
    }
}

/// An oak: a stout trunk under a broad, round crown.
pub fn oak() -> TreeSpec {
    TreeSpec {
        name: "oak",
        trunk_radius: TRUNK_RADII[1],
        bark: bark(5, [0.45, 0.38, 0.3], [0.14, 0.11, 0.08]),
        crown: Crown::Round {
            centre: Vec3::new(0.0, 6.4, 0.0),
            radii: Vec3::new(3.3, 2.7, 3.3),
        },
        cards: 320,
        card_size: 1.35,
        leaves: leaf_cluster(Leaves {
            count: 12,
            size: (0.3, 0.13),
            colours: ([0.3, 0.48, 0.14], [0.17, 0.33, 0.08]),
            seed: 12,
        }),
        leaf_tint: [1.0, 1.0, 1.0, 1.0],
        seed: 2,
    }
}

/// A birch: a slender white trunk under a narrow, light crown.
pub fn birch() -> TreeSpec {
    TreeSpec {
        name: "birch",
        trunk_radius: TRUNK_RADII[2],
        bark: birch_bark(7),
        crown: Crown::Round {
            centre: Vec3::new(0.0, 6.6, 0.0),
            radii: Vec3::new(1.8, 2.8, 1.8),
        },
        cards: 220,
        card_size: 1.05,
        leaves: leaf_cluster(Leaves {
            count: 14,
            size: (0.22, 0.12),
            colours: ([0.5, 0.62, 0.2], [0.32, 0.46, 0.12]),
            seed: 13,
        }),
        leaf_tint: [1.0, 1.0, 1.0, 1.0],
        seed: 3,
    }
}

/// A trunk standing on the origin up to `height`, tapering to 45 % of `radius`, with UVs
/// that repeat the bark every 1.5 m up and twice round.
pub fn trunk(radius: f32, height: f32, sides: u32) -> Mesh {
    let (mut positions, mut normals, mut uvs, mut indices) = (vec![], vec![], vec![], vec![]);
    let rings = 4u32;
    for j in 0..=rings {
        let t = j as f32 / rings as f32;
        let r = radius * (1.0 - 0.55 * t) * if j == 0 { 1.25 } else { 1.0 };
        for i in 0..=sides {
            let around = Vec2::from_angle(i as f32 / sides as f32 * std::f32::consts::TAU);
            positions.push([around.x * r, t * height, around.y * r]);
            normals.push([around.x, 0.12, around.y]);
            uvs.push([2.0 * i as f32 / sides as f32, -t * height / 1.5]);
        }
    }
    for j in 0..rings {
        for i in 0..sides {
            let a = j * (sides + 1) + i;
            let b = a + sides + 1;
            indices.extend([a, b, a + 1, a + 1, b, b + 1]);
        }
    }
    crate::foliage::uv_mesh(positions, normals, uvs, indices)
}

/// The glTF file of `tree`.
pub fn tree(tree: &TreeSpec) -> Glb {
    let mut file = Glb::default();
    let bark_albedo = file.add_image(tree.bark.albedo.clone());
    let bark_normal = file.add_image(tree.bark.normal.clone());
    let bark = file.add_material(GlbMaterial {
        base_color_texture: Some(bark_albedo),
        normal_texture: Some(bark_normal),
        roughness: 0.95,
        ..GlbMaterial::colored([1.0, 1.0, 1.0, 1.0])
    });
    let leaf_image = file.add_image(tree.leaves.clone());
    let leaves = file.add_material(GlbMaterial {
        base_color_texture: Some(leaf_image),
        alpha: GlbAlpha::Mask(0.5),
        roughness: 0.8,
        ..GlbMaterial::colored(tree.leaf_tint)
    });
    let top = tree.crown.top();
    let primitive = |mesh: Mesh, material| GlbPrimitive::from_mesh(&mesh, material).unwrap();
    let level = |sides: u32, cards: u32, size: f32, seed: u32| {
        let mut trunk = trunk(tree.trunk_radius, top * 0.85, sides);
        trunk
            .generate_tangents()
            .expect("a trunk has UVs and normals");
        let crown = crown_cards(&tree.crown, cards, size, seed);
        vec![
            primitive(trunk, bark),
            primitive(cards_mesh(&crown), leaves),
        ]
    };
    let near = file.add_mesh(level(10, tree.cards, tree.card_size, tree.seed));
    let far = file.add_mesh(level(
        5,
        tree.cards / 4,
        tree.card_size * 1.9,
        tree.seed + 100,
    ));
    let hull = Cylinder::new(tree.trunk_radius * HULL, top * 0.8)
        .mesh()
        .resolution(8)
        .build()
        .translated_by(Vec3::Y * top * 0.4);
    let hull = file.add_mesh(vec![primitive(hull, bark)]);
    let lod0 = file.add_node(GlbNode::named(format!("{}_LOD0", tree.name)).with_mesh(near));
    let lod1 = file.add_node(GlbNode::named(format!("{}_LOD1", tree.name)).with_mesh(far));
    let ucx = file.add_node(GlbNode::named(format!("UCX_{}", tree.name)).with_mesh(hull));
    let root = file.add_node(GlbNode::named(tree.name).with_children([lod0, lod1, ucx]));
    file.add_root(root);
    file
}

/// `count` cards of side `size` filling `crown`, each facing out and tilted at random.
fn crown_cards(crown: &Crown, count: u32, size: f32, seed: u32) -> Vec<Card> {
    let hash = Hash(seed);
    (0..count)
        .map(|i| {
            let (at, out) = crown.point([hash.get(i, 0), hash.get(i, 1), hash.get(i, 2)]);
            let along = match crown {
                // A spruce's sprays hang outwards and down from its tiers.
                Crown::Cone { .. } => {
                    let turn = Quat::from_axis_angle(out, (hash.get(i, 3) - 0.5) * 2.5);
                    turn * (out - Vec3::Y * 0.6).normalize()
                }
                // A round crown's twigs point every way, mostly level: a mass of leaves,
                // not a star.
                Crown::Round { .. } => {
                    let heading = Vec2::from_angle(hash.get(i, 3) * std::f32::consts::TAU);
                    let dip = hash.get(i, 5) * 0.9 - 0.6;
                    (Vec3::new(heading.x, dip, heading.y) + out * 0.3).normalize()
                }
            };
            let side = along.cross(Vec3::Y).normalize_or(Vec3::X);
            let scale = size * (0.8 + 0.4 * hash.get(i, 4));
            Card {
                centre: at,
                up: along * scale,
                right: side * scale,
                normal: (out + Vec3::Y * 0.5).normalize(),
            }
        })
        .collect()
}
