//! What grows and lies under the trees: a bush of leaf cards, a fern of cut-out fronds, a
//! rock with a normal map, each at two levels of detail where it pays.

use super::cards::{Card, Hash, cards_mesh};
use super::textures::{Leaves, leaf_cluster, png, rock as rock_maps};
use bevy::prelude::*;
use bevy_rwt::testing::glb::{Glb, GlbAlpha, GlbMaterial, GlbNode, GlbPrimitive};
use noise::{NoiseFn, Perlin};

/// A cut-out leaf material of `texture` (cards carry both faces).
fn leaf_material(file: &mut Glb, texture: Vec<u8>) -> usize {
    let image = file.add_image(texture);
    file.add_material(GlbMaterial {
        base_color_texture: Some(image),
        alpha: GlbAlpha::Mask(0.5),
        roughness: 0.8,
        ..GlbMaterial::colored([1.0, 1.0, 1.0, 1.0])
    })
}

/// Levels of one primitive each under a root named `name` (`<name>_LOD0`, …).
pub(super) fn levels(file: &mut Glb, name: &str, meshes: Vec<(Mesh, usize)>) {
    let nodes: Vec<usize> = meshes
        .into_iter()
        .enumerate()
        .map(|(i, (mesh, material))| {
            let primitive = GlbPrimitive::from_mesh(&mesh, material).unwrap();
            let mesh = file.add_mesh(vec![primitive]);
            file.add_node(GlbNode::named(format!("{name}_LOD{i}")).with_mesh(mesh))
        })
        .collect();
    let root = file.add_node(GlbNode::named(name).with_children(nodes));
    file.add_root(root);
}

/// A bush: a low dome of leaf cards.
pub fn bush() -> Glb {
    let mut file = Glb::default();
    let leaves = leaf_material(
        &mut file,
        leaf_cluster(Leaves {
            count: 12,
            size: (0.3, 0.12),
            colours: ([0.34, 0.52, 0.15], [0.22, 0.38, 0.1]),
            seed: 21,
        }),
    );
    let dome = |count: u32, size: f32, seed: u32| {
        let hash = Hash(seed);
        let cards: Vec<Card> = (0..count)
            .map(|i| {
                let around = Vec2::from_angle(hash.get(i, 0) * std::f32::consts::TAU);
                let up = hash.get(i, 1).sqrt();
                let ring = (1.0 - up * up).sqrt();
                let out = Vec3::new(around.x * ring, up, around.y * ring);
                let at = out * Vec3::new(1.1, 0.8, 1.1) * (0.5 + 0.5 * hash.get(i, 2));
                let along = (out + Vec3::Y * 0.3).normalize();
                let side = along.cross(Vec3::Y).normalize_or(Vec3::X);
                let turn = Quat::from_axis_angle(along, (hash.get(i, 3) - 0.5) * 2.0);
                Card {
                    centre: at + Vec3::Y * 0.1,
                    up: along * size,
                    right: turn * side * size,
                    normal: (out + Vec3::Y * 0.4).normalize(),
                }
            })
            .collect();
        cards_mesh(&cards)
    };
    levels(
        &mut file,
        "bush",
        vec![(dome(46, 0.9, 5), leaves), (dome(14, 1.5, 6), leaves)],
    );
    file
}

/// A fern: a ring of fronds, each a card of the frond texture.
pub fn fern() -> Glb {
    let mut file = Glb::default();
    let texture = crate::foliage::fern_texture();
    let (w, h) = (texture.width(), texture.height());
    let data = texture.data.clone().unwrap_or_default();
    let fronds = png(w, h, |x, y| {
        let k = ((y * w + x) * 4) as usize;
        // The frond texture is grey for tinting: green it here.
        let grey = data.get(k..k + 4).unwrap_or(&[0; 4]);
        let tint = |c: u8, f: f32| (c as f32 * f) as u8;
        [
            tint(grey[0], 0.42),
            tint(grey[1], 0.62),
            tint(grey[2], 0.25),
            grey[3],
        ]
    });
    let material = leaf_material(&mut file, fronds);
    levels(
        &mut file,
        "fern",
        vec![(crate::foliage::fern(7, 1.6), material)],
    );
    file
}

/// A boulder: a lumpy, flattened sphere with a rock texture and its normal map, near and
/// far.
pub fn rock() -> Glb {
    let mut file = Glb::default();
    let maps = rock_maps(9);
    let albedo = file.add_image(maps.albedo);
    let normal = file.add_image(maps.normal);
    let stone = file.add_material(GlbMaterial {
        base_color_texture: Some(albedo),
        normal_texture: Some(normal),
        roughness: 0.85,
        ..GlbMaterial::colored([1.0, 1.0, 1.0, 1.0])
    });
    let lumpy = |subdivisions: u32| {
        let perlin = Perlin::new(31);
        let mut mesh = Sphere::new(1.0)
            .mesh()
            .ico(subdivisions)
            .expect("a small ico sphere");
        if let Some(bevy::mesh::VertexAttributeValues::Float32x3(p)) =
            mesh.attribute_mut(Mesh::ATTRIBUTE_POSITION)
        {
            for v in p.iter_mut() {
                let d = Vec3::from_array(*v);
                let bump = perlin.get([d.x as f64 * 1.3, d.y as f64 * 1.3, d.z as f64 * 1.3]);
                let at = d * (1.0 + 0.3 * bump as f32) * Vec3::new(1.3, 0.7, 1.0);
                *v = (at + Vec3::Y * 0.25).to_array();
            }
        }
        mesh.compute_smooth_normals();
        mesh.generate_tangents().expect("an ico sphere has UVs");
        mesh
    };
    levels(
        &mut file,
        "rock",
        vec![(lumpy(4), stone), (lumpy(1), stone)],
    );
    file
}
