//! The level: an island that is not a heightfield, written as a glTF binary (`.glb`) by
//! this example itself (nothing downloaded): a hilly island with a cliff up to a plateau,
//! a bridge deck over the ground, rocks and a house. Each part is a named node, so that
//! the game can mark each as the ground it is.

use bevy::prelude::*;
use bevy_rwt::testing::glb::{Glb, GlbMaterial, GlbNode, GlbPrimitive};

/// One named part of the level: a triangle list in world space, with its colour.
pub struct Part {
    pub name: &'static str,
    pub positions: Vec<[f32; 3]>,
    pub normals: Vec<[f32; 3]>,
    pub indices: Vec<u32>,
    pub color: [f32; 4],
}

/// Island radius (the shore).
pub const SHORE: f32 = 48.0;
/// Where the cliff rises along x, and by how much.
const CLIFF_X: f32 = 16.0;
const CLIFF_RISE: f32 = 6.0;

/// Height of the island's ground at (x, z): hills falling to the sea at the shore, and a
/// plateau east of a cliff.
pub fn island_height(p: Vec2) -> f32 {
    let r = p.length();
    let land = 1.0 - smoothstep(SHORE - 12.0, SHORE + 2.0, r);
    let hills = 1.4 * (p.x * 0.11).sin() * (p.y * 0.09).cos() + 0.8 * (p.y * 0.05 + 1.0).sin();
    let plateau = smoothstep(CLIFF_X, CLIFF_X + 0.6, p.x) * smoothstep(42.0, 36.0, r);
    -2.5 + land * (6.0 + hills) + CLIFF_RISE * plateau
}

fn smoothstep(a: f32, b: f32, x: f32) -> f32 {
    let t = ((x - a) / (b - a)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

/// The island's ground: a 1 m grid over 120 x 120 m.
fn island() -> Part {
    let (n, step, half) = (120u32, 1.0f32, 60.0f32);
    let mut positions = Vec::new();
    let mut normals = Vec::new();
    for j in 0..=n {
        for i in 0..=n {
            let p = Vec2::new(i as f32 * step - half, j as f32 * step - half);
            let h = |q: Vec2| island_height(q);
            let d = 0.25;
            let gx = (h(p + Vec2::X * d) - h(p - Vec2::X * d)) / (2.0 * d);
            let gz = (h(p + Vec2::Y * d) - h(p - Vec2::Y * d)) / (2.0 * d);
            positions.push([p.x, h(p), p.y]);
            normals.push(Vec3::new(-gx, 1.0, -gz).normalize().to_array());
        }
    }
    let at = |i: u32, j: u32| j * (n + 1) + i;
    let mut indices = Vec::new();
    for j in 0..n {
        for i in 0..n {
            let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
            indices.extend([a, c, b, a, d, c]);
        }
    }
    Part {
        name: "island",
        positions,
        normals,
        indices,
        color: [0.06, 0.12, 0.035, 1.0],
    }
}

/// A Bevy mesh's triangles placed by `at`, as a part.
fn part(name: &'static str, mesh: Mesh, at: Transform, color: [f32; 4]) -> Part {
    let affine = at.compute_affine();
    let positions = match mesh.attribute(Mesh::ATTRIBUTE_POSITION) {
        Some(bevy::mesh::VertexAttributeValues::Float32x3(p)) => p.clone(),
        _ => unreachable!("primitive meshes have positions"),
    };
    let normals = match mesh.attribute(Mesh::ATTRIBUTE_NORMAL) {
        Some(bevy::mesh::VertexAttributeValues::Float32x3(n)) => n.clone(),
        _ => unreachable!("primitive meshes have normals"),
    };
    let indices: Vec<u32> = match mesh.indices() {
        Some(bevy::mesh::Indices::U16(i)) => i.iter().map(|&i| i as u32).collect(),
        Some(bevy::mesh::Indices::U32(i)) => i.clone(),
        None => (0..positions.len() as u32).collect(),
    };
    Part {
        name,
        positions: positions
            .iter()
            .map(|p| affine.transform_point3(Vec3::from_array(*p)).to_array())
            .collect(),
        normals: normals
            .iter()
            .map(|n| {
                (affine.matrix3 * Vec3::from_array(*n))
                    .normalize()
                    .to_array()
            })
            .collect(),
        indices,
        color,
    }
}

/// A box standing on the ground at `(x, z)`, sunk `sink` into it.
fn standing(size: Vec3, x: f32, z: f32, sink: f32, turn: Quat) -> Transform {
    let ground = island_height(Vec2::new(x, z));
    Transform::from_xyz(x, ground + size.y / 2.0 - sink, z).with_rotation(turn)
}

/// Every part of the level.
pub fn parts() -> Vec<Part> {
    let stone = [0.36, 0.34, 0.31, 1.0];
    let wood = [0.35, 0.24, 0.14, 1.0];
    let mut out = vec![island()];
    // A bridge deck 2.6 m above the ground, on two piers: grass grows on it and under it.
    let (deck_y, deck) = (
        island_height(Vec2::new(-22.0, -4.0)) + 3.0,
        Vec3::new(22.0, 0.8, 5.0),
    );
    let deck_at = Transform::from_xyz(-22.0, deck_y, -4.0);
    out.push(part(
        "bridge",
        Cuboid::from_size(deck).mesh().build(),
        deck_at,
        wood,
    ));
    for (name, x) in [("pier west", -32.0), ("pier east", -12.0)] {
        let pier = Cuboid::new(1.2, 6.0, 4.0).mesh().build();
        let at = Transform::from_xyz(x, deck_y - 3.3, -4.0);
        out.push(part(name, pier, at, stone));
    }
    // Rocks: tilted boxes sunk into the ground; moss grows on their tops.
    for (k, (x, z, size)) in [
        (-6.0, 8.0, 3.5),
        (5.0, -14.0, 2.6),
        (-14.0, 22.0, 4.2),
        (26.0, 10.0, 3.0),
        (8.0, 26.0, 2.2),
    ]
    .into_iter()
    .enumerate()
    {
        let size = Vec3::new(size, size * 0.55, size * 0.8);
        let turn = Quat::from_rotation_y(k as f32 * 1.3) * Quat::from_rotation_x(0.08);
        let at = standing(size, x, z, 0.4, turn);
        out.push(part(
            ROCKS[k],
            Cuboid::from_size(size).mesh().build(),
            at,
            stone,
        ));
    }
    // A house: walls under a gable roof.
    let walls = Vec3::new(6.0, 3.0, 5.0);
    let at = standing(walls, 4.0, 12.0, 0.3, Quat::from_rotation_y(0.3));
    out.push(part(
        "house walls",
        Cuboid::from_size(walls).mesh().build(),
        at,
        [0.7, 0.66, 0.58, 1.0],
    ));
    let roof = Extrusion::new(
        Triangle2d::new(
            Vec2::new(-3.4, 0.0),
            Vec2::new(3.4, 0.0),
            Vec2::new(0.0, 2.2),
        ),
        5.6,
    );
    let roof_at = at * Transform::from_xyz(0.0, walls.y / 2.0, 0.0);
    out.push(part(
        "house roof",
        roof.mesh().build(),
        roof_at,
        [0.45, 0.16, 0.12, 1.0],
    ));
    out
}

/// The rocks' node names.
pub const ROCKS: [&str; 5] = ["rock 1", "rock 2", "rock 3", "rock 4", "rock 5"];

/// The level as a glTF binary: one node and one mesh per part, each with a material of
/// its colour.
pub fn glb(parts: &[Part]) -> Vec<u8> {
    let mut file = Glb::default();
    for p in parts {
        let material = file.add_material(GlbMaterial::colored(p.color));
        let mesh = file.add_mesh(vec![GlbPrimitive {
            positions: p.positions.clone(),
            normals: p.normals.clone(),
            indices: p.indices.clone(),
            material,
            ..default()
        }]);
        let node = file.add_node(GlbNode::named(p.name).with_mesh(mesh));
        file.add_root(node);
    }
    file.to_bytes()
}
