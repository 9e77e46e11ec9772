//! Meadow flowers: one file holding three, each a root node named by its colour (`red`,
//! `yellow`, `blue`; a layer names one as `"flowers.glb#red"`) with two levels: a stem under
//! a star of petals, every vertex mapped to one small texture whose columns hold each
//! flower's colours (a shared material: the three draw alike and cost one texture).

use super::plants::levels;
use super::textures::png;
use crate::foliage::uv_mesh;
use bevy::prelude::*;
use bevy_rwt::testing::glb::{Glb, GlbMaterial};

/// The flowers: root node name, petal colour and heart colour (sRGB).
pub const FLOWERS: [(&str, [u8; 3], [u8; 3]); 3] = [
    ("red", [191, 20, 15], [235, 200, 60]),
    ("yellow", [242, 191, 31], [215, 120, 25]),
    ("blue", [77, 89, 230], [240, 225, 120]),
];

/// A flower's height (metres).
const HEIGHT: f32 = 0.62;
/// Texels across a flower's column of the texture.
const COLUMN: u32 = 4;
/// Rows of the texture: the heart, petals, then the stem from its top down.
const ROWS: u32 = 16;
/// The first stem row.
const STEM: u32 = 4;

/// The texture: a column per flower, the heart on top, petals under it, the stem (darker
/// towards the ground) below.
fn texture() -> Vec<u8> {
    png(COLUMN * FLOWERS.len() as u32, ROWS, |x, y| {
        let (_, petal, heart) = FLOWERS[(x / COLUMN) as usize];
        let [r, g, b] = match y {
            0 => heart,
            y if y < STEM => petal,
            y => {
                let down = (y - STEM) as f32 / (ROWS - 1 - STEM) as f32;
                let shade = |top: f32, bottom: f32| (top + (bottom - top) * down) as u8;
                [shade(45.0, 20.0), shade(92.0, 45.0), shade(22.0, 10.0)]
            }
        };
        [r, g, b, 255]
    })
}

/// The v coordinate of the middle of texture row `row`.
fn row(row: u32) -> f32 {
    (row as f32 + 0.5) / ROWS as f32
}

/// A flower of texture column `u`: a stem (a quad, or a triangle when `thin`) under a star
/// of `points` petals.
fn flower(points: u32, thin: bool, u: f32) -> Mesh {
    let (mut positions, mut uvs, mut indices) = (Vec::new(), Vec::new(), Vec::new());
    let stem_top = HEIGHT * 0.9;
    let w = HEIGHT * 0.025;
    let mut stem = vec![([-w, 0.0], ROWS - 1), ([w, 0.0], ROWS - 1)];
    if thin {
        stem.push(([0.0, stem_top], STEM));
        indices.extend([0, 1, 2]);
    } else {
        stem.extend([([-w * 0.6, stem_top], STEM), ([w * 0.6, stem_top], STEM)]);
        indices.extend([0, 1, 3, 0, 3, 2]);
    }
    for ([x, y], r) in &stem {
        positions.push([*x, *y, 0.0]);
        uvs.push([u, row(*r)]);
    }
    let mut normals = vec![Vec3::new(0.0, 0.3, 1.0).normalize().to_array(); stem.len()];
    let centre = positions.len() as u32;
    positions.push([0.0, HEIGHT, 0.0]);
    uvs.push([u, row(0)]);
    let petal = HEIGHT * 0.22;
    let ring = 2 * points;
    for i in 0..ring {
        let a = i as f32 / ring as f32 * std::f32::consts::TAU;
        let r = if i % 2 == 0 { petal } else { petal * 0.45 };
        positions.push([a.cos() * r, HEIGHT * 0.94, a.sin() * r]);
        uvs.push([u, row(2)]);
    }
    normals.resize(positions.len(), [0.0, 1.0, 0.0]);
    for i in 0..ring {
        indices.extend([centre, centre + 1 + (i + 1) % ring, centre + 1 + i]);
    }
    uv_mesh(positions, normals, uvs, indices)
}

/// The file: the three flowers, each `<colour>` over `<colour>_LOD0` (six petals) and
/// `<colour>_LOD1` (three, on a thinner stem).
pub fn flowers() -> Glb {
    let mut file = Glb::default();
    let image = file.add_image(texture());
    let material = file.add_material(GlbMaterial {
        base_color_texture: Some(image),
        roughness: 0.8,
        double_sided: true,
        ..GlbMaterial::colored([1.0, 1.0, 1.0, 1.0])
    });
    let width = (COLUMN * FLOWERS.len() as u32) as f32;
    for (i, (name, _, _)) in FLOWERS.iter().enumerate() {
        let u = (i as u32 * COLUMN) as f32 / width + 0.5 * COLUMN as f32 / width;
        let near = (flower(6, false, u), material);
        levels(&mut file, name, vec![near, (flower(3, true, u), material)]);
    }
    file
}
