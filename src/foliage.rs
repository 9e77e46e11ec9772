//! Meshes generated in code: three tree species (each with a cheap far mesh) for the
//! benchmarks and checks that draw trees as entities, a stump, a cabin, and a flower for
//! instanced classes. Low-poly and faceted (flat
//! normals), coloured per vertex, so that one white material per species is enough. The
//! fern is a ring of textured fronds instead: cards whose texture's alpha cuts out the
//! leaflets.

use bevy::asset::RenderAssetUsages;
use bevy::mesh::{Indices, PrimitiveTopology, VertexAttributeValues};
use bevy::prelude::*;
use noise::{NoiseFn, Perlin};

/// A tree species: its near and far mesh.
pub struct TreeMeshes {
    /// Full detail.
    pub near: Mesh,
    /// A few dozen triangles, for the distance.
    pub far: Mesh,
}

/// A spruce: a trunk under four jagged tiers of needles.
pub fn conifer() -> TreeMeshes {
    let bark = Color::srgb(0.22, 0.15, 0.09);
    let needles = Color::srgb(0.06, 0.17, 0.09);
    let mut near = vec![painted(trunk(0.28, 3.0, 7), bark)];
    for (i, (radius, height, y)) in [
        (2.7, 3.4, 1.6),
        (2.2, 3.0, 3.5),
        (1.6, 2.7, 5.2),
        (1.0, 2.3, 6.8),
    ]
    .into_iter()
    .enumerate()
    {
        let tier = Cone::new(radius, height).mesh().resolution(12).build();
        let tier =
            lumpy(tier, 10 + i as u32, 0.22, 1.3).translated_by(Vec3::Y * (y + height / 2.0));
        near.push(shaded(tier, needles, 0.25, 20 + i as u32));
    }
    let far_cone = Cone::new(2.6, 7.6).mesh().resolution(6).build();
    let far = vec![
        painted(trunk(0.3, 2.0, 4), bark),
        painted(far_cone.translated_by(Vec3::Y * 5.3), needles),
    ];
    TreeMeshes {
        near: faceted(merged(near)),
        far: faceted(merged(far)),
    }
}

/// A broadleaf tree: a tapered trunk with two limbs under a cluster of leafy lumps.
pub fn broadleaf() -> TreeMeshes {
    let bark = Color::srgb(0.25, 0.19, 0.13);
    let leaves = Color::srgb(0.16, 0.3, 0.07);
    let mut near = vec![painted(trunk(0.38, 4.6, 8), bark)];
    for (angle, tilt) in [(0.4f32, 0.7f32), (2.8, 0.6)] {
        let limb = Cylinder::new(0.14, 2.4).mesh().resolution(5).build();
        let limb = limb
            .translated_by(Vec3::Y * 1.2)
            .rotated_by(Quat::from_rotation_y(angle) * Quat::from_rotation_z(tilt))
            .translated_by(Vec3::Y * 3.4);
        near.push(painted(limb, bark));
    }
    let lumps = [
        (Vec3::new(0.0, 6.6, 0.0), 2.5),
        (Vec3::new(1.6, 5.9, 0.6), 1.9),
        (Vec3::new(-1.5, 6.0, -0.8), 2.0),
        (Vec3::new(0.3, 5.6, -1.7), 1.7),
        (Vec3::new(-0.5, 7.7, 0.9), 1.6),
    ];
    for (i, (at, radius)) in lumps.into_iter().enumerate() {
        let lump = Sphere::new(radius).mesh().ico(1).expect("small ico sphere");
        let lump = lumpy(lump, 40 + i as u32, 0.35, 0.9).translated_by(at);
        near.push(shaded(lump, leaves, 0.3, 50 + i as u32));
    }
    let blob = Sphere::new(3.0).mesh().ico(1).expect("small ico sphere");
    let far = vec![
        painted(trunk(0.38, 4.0, 4), bark),
        painted(
            lumpy(blob, 60, 0.4, 0.6)
                .scaled_by(Vec3::new(1.1, 0.9, 1.1))
                .translated_by(Vec3::Y * 6.5),
            leaves,
        ),
    ];
    TreeMeshes {
        near: faceted(merged(near)),
        far: faceted(merged(far)),
    }
}

/// A birch: a slender white trunk with dark marks under narrow, light crowns.
pub fn birch() -> TreeMeshes {
    let leaves = Color::srgb(0.3, 0.42, 0.1);
    let mut stem = trunk(0.17, 7.5, 7);
    marked_bark(&mut stem);
    let mut near = vec![stem];
    for (i, (at, r)) in [
        (Vec3::new(0.0, 7.2, 0.0), 1.5),
        (Vec3::new(0.7, 5.8, 0.3), 1.2),
        (Vec3::new(-0.6, 6.2, -0.4), 1.2),
    ]
    .into_iter()
    .enumerate()
    {
        let crown = Sphere::new(r).mesh().ico(1).expect("small ico sphere");
        let crown = lumpy(crown, 70 + i as u32, 0.3, 1.1)
            .scaled_by(Vec3::new(1.0, 1.7, 1.0))
            .translated_by(at);
        near.push(shaded(crown, leaves, 0.25, 80 + i as u32));
    }
    let crown = Sphere::new(1.6).mesh().ico(1).expect("small ico sphere");
    let mut far_stem = trunk(0.18, 5.0, 4);
    marked_bark(&mut far_stem);
    let far = vec![
        far_stem,
        painted(
            crown
                .scaled_by(Vec3::new(1.0, 1.9, 1.0))
                .translated_by(Vec3::Y * 6.6),
            leaves,
        ),
    ];
    TreeMeshes {
        near: faceted(merged(near)),
        far: faceted(merged(far)),
    }
}

/// What a chopped tree leaves: a short stump with a pale cut face.
pub fn stump() -> Mesh {
    let bark = Color::srgb(0.24, 0.17, 0.1);
    let wood = Color::srgb(0.72, 0.6, 0.42);
    let face = Cylinder::new(0.3, 0.04)
        .mesh()
        .resolution(9)
        .build()
        .translated_by(Vec3::Y * 0.62);
    faceted(merged(vec![
        painted(trunk(0.36, 0.62, 9), bark),
        painted(face, wood),
    ]))
}

/// A log cabin, 6 m by 4 m, standing on its origin, with a pitched roof along x.
pub fn cabin() -> Mesh {
    let logs = Color::srgb(0.42, 0.28, 0.16);
    let roof = Color::srgb(0.3, 0.12, 0.1);
    let door = Color::srgb(0.2, 0.13, 0.08);
    let walls = Cuboid::new(6.0, 2.6, 4.0)
        .mesh()
        .build()
        .translated_by(Vec3::Y * 1.3);
    let slab = |side: f32| {
        Cuboid::new(6.6, 0.16, 2.7)
            .mesh()
            .build()
            .rotated_by(Quat::from_rotation_x(side * 0.62))
            .translated_by(Vec3::new(0.0, 3.25, side * 1.08))
    };
    let attic = prism(Vec3::new(6.0, 1.35, 4.0)).translated_by(Vec3::Y * 2.6);
    let entrance = Cuboid::new(0.05, 1.9, 1.0)
        .mesh()
        .build()
        .translated_by(Vec3::new(3.01, 0.95, 0.0));
    let parts = vec![
        painted(walls, logs),
        painted(attic, logs),
        painted(slab(-1.0), roof),
        painted(slab(1.0), roof),
        painted(entrance, door),
    ];
    faceted(merged(parts))
}

/// A triangular prism along x: `size.x` long, `size.z` wide at its base (y = 0), `size.y`
/// high at its ridge.
fn prism(size: Vec3) -> Mesh {
    let (x, y, z) = (size.x / 2.0, size.y, size.z / 2.0);
    let positions = vec![
        [-x, 0.0, -z],
        [-x, 0.0, z],
        [-x, y, 0.0],
        [x, 0.0, -z],
        [x, 0.0, z],
        [x, y, 0.0],
    ];
    let indices = vec![0, 1, 2, 3, 5, 4, 0, 2, 5, 0, 5, 3, 1, 4, 5, 1, 5, 2];
    Mesh::new(
        PrimitiveTopology::TriangleList,
        RenderAssetUsages::default(),
    )
    .with_inserted_attribute(Mesh::ATTRIBUTE_POSITION, positions)
    .with_inserted_attribute(Mesh::ATTRIBUTE_NORMAL, vec![[0.0, 1.0, 0.0]; 6])
    .with_inserted_attribute(Mesh::ATTRIBUTE_UV_0, vec![[0.0, 0.0]; 6])
    .with_inserted_indices(Indices::U32(indices))
}

/// A flower for an instanced class: a thin stem under a flat star of six petals. With
/// [`bevy_rwt::InstancedShading::tip_from`] at about 0.85 the stem takes the base colour
/// and the head the tip colour.
pub fn flower(height: f32) -> Mesh {
    let mut positions: Vec<[f32; 3]> = Vec::new();
    let mut normals: Vec<[f32; 3]> = Vec::new();
    let mut indices: Vec<u32> = Vec::new();
    let stem_top = height * 0.9;
    let w = height * 0.025;
    for (x, y) in [
        (-w, 0.0),
        (w, 0.0),
        (-w * 0.6, stem_top),
        (w * 0.6, stem_top),
    ] {
        positions.push([x, y, 0.0]);
        normals.push([0.0, 0.3, 1.0]);
    }
    indices.extend([0, 1, 3, 0, 3, 2]);
    let centre = positions.len() as u32;
    positions.push([0.0, height, 0.0]);
    normals.push([0.0, 1.0, 0.0]);
    let petal = height * 0.22;
    for i in 0..12 {
        let a = i as f32 / 12.0 * std::f32::consts::TAU;
        let r = if i % 2 == 0 { petal } else { petal * 0.45 };
        positions.push([a.cos() * r, height * 0.94, a.sin() * r]);
        normals.push([0.0, 1.0, 0.0]);
    }
    for i in 0..12 {
        indices.extend([centre, centre + 1 + i, centre + 1 + (i + 1) % 12]);
    }
    Mesh::new(
        PrimitiveTopology::TriangleList,
        RenderAssetUsages::default(),
    )
    .with_inserted_attribute(Mesh::ATTRIBUTE_POSITION, positions)
    .with_inserted_attribute(Mesh::ATTRIBUTE_NORMAL, normals)
    .with_inserted_indices(Indices::U32(indices))
}

/// A fern for a textured instanced class: `fronds` cards of `length` metres (and a third of
/// that wide) rising steeply from the centre and arching over, each mapped to the whole of
/// [`fern_texture`] (v from the stem to the tip). About half `length` tall.
pub fn fern(fronds: u32, length: f32) -> Mesh {
    const SEGMENTS: u32 = 6;
    let (mut positions, mut normals, mut uvs) = (Vec::new(), Vec::new(), Vec::new());
    let mut indices: Vec<u32> = Vec::new();
    let half_width = length / 6.0;
    for f in 0..fronds {
        // Evenly around, each frond turned a little off the even spacing.
        let turn = (f as f32 + 0.3 * (f as f32 * 2.4).sin()) / fronds as f32;
        let out = Vec2::from_angle(turn * std::f32::consts::TAU);
        let side = Vec3::new(-out.y, 0.0, out.x);
        let first = positions.len() as u32;
        let mut at = Vec2::new(0.0, 0.02); // (outwards, up)
        for j in 0..=SEGMENTS {
            let s = j as f32 / SEGMENTS as f32;
            // Rises at 80 degrees, arches over to -10 at the tip.
            let angle = (80.0 - 90.0 * s).to_radians();
            let along = Vec3::new(out.x * angle.cos(), angle.sin(), out.y * angle.cos());
            let centre = Vec3::new(out.x * at.x, at.y, out.y * at.x);
            let normal = side.cross(along).normalize();
            // The stem is narrow; the frond is widest a third of the way up.
            let width = half_width * (s * 3.0).min(1.0);
            for (u, k) in [(0.0, -1.0), (1.0, 1.0)] {
                positions.push((centre + side * (k * width)).to_array());
                normals.push(normal.to_array());
                // Image rows run top-down: the texture's stem is its bottom row.
                uvs.push([u, 1.0 - s]);
            }
            at += Vec2::new(angle.cos(), angle.sin()) * (length / SEGMENTS as f32);
        }
        for j in 0..SEGMENTS {
            let a = first + 2 * j;
            indices.extend([a, a + 1, a + 3, a, a + 3, a + 2]);
        }
    }
    uv_mesh(positions, normals, uvs, indices)
}

/// A triangle list of these positions, normals, texture coordinates and indices.
pub fn uv_mesh(
    positions: Vec<[f32; 3]>,
    normals: Vec<[f32; 3]>,
    uvs: Vec<[f32; 2]>,
    indices: Vec<u32>,
) -> Mesh {
    Mesh::new(
        PrimitiveTopology::TriangleList,
        RenderAssetUsages::default(),
    )
    .with_inserted_attribute(Mesh::ATTRIBUTE_POSITION, positions)
    .with_inserted_attribute(Mesh::ATTRIBUTE_NORMAL, normals)
    .with_inserted_attribute(Mesh::ATTRIBUTE_UV_0, uvs)
    .with_inserted_indices(Indices::U32(indices))
}

/// A fern frond (stem along v, from the bottom edge up): slanted leaflets on both sides of
/// a dark midrib, longest near the base, serrated, opaque; transparent (alpha 0) between
/// them. Light grey with darker veins: the class's colours tint it.
pub fn fern_texture() -> Image {
    const WIDTH: u32 = 128;
    const HEIGHT: u32 = 256;
    const LEAFLETS: f32 = 15.0;
    let mut data = Vec::with_capacity((WIDTH * HEIGHT * 4) as usize);
    for y in 0..HEIGHT {
        // Image rows run top-down; v runs from the stem (bottom) to the tip.
        let v = 1.0 - (y as f32 + 0.5) / HEIGHT as f32;
        for x in 0..WIDTH {
            let u = (x as f32 + 0.5) / WIDTH as f32;
            let off = (u - 0.5).abs() * 2.0; // 0 at the midrib, 1 at the card's edge
            // Leaflets slant towards the tip; `w` is where this pixel's leaflet leaves the
            // midrib.
            let w = v - 0.35 * off;
            let reach = if w < 0.08 { 0.0 } else { (1.0 - w).powf(0.6) };
            let phase = (w * LEAFLETS).fract() - 0.5;
            let serrated = 0.85 + 0.15 * (off * 40.0).sin();
            let half = 0.36 * (1.0 - off / reach.max(1e-3)).max(0.0).sqrt() * serrated;
            let leaflet = off < reach && phase.abs() < half;
            let midrib = off < 0.03 && v < 0.99;
            let (rgba, alpha) = if midrib {
                ([150, 140, 110], 255)
            } else if leaflet {
                // Darker along each leaflet's own vein, lighter towards its edges.
                let shade = 200.0 + 55.0 * (phase.abs() / half.max(1e-3));
                let s = shade.min(255.0) as u8;
                ([s, s, (shade * 0.9) as u8], 255)
            } else {
                ([200, 200, 180], 0)
            };
            data.extend_from_slice(&[rgba[0], rgba[1], rgba[2], alpha]);
        }
    }
    srgba_image(WIDTH, HEIGHT, data)
}

/// A 2-D sRGB colour image with alpha of `width` x `height` texels, `data` row by row
/// from the top, 4 bytes a texel.
pub fn srgba_image(width: u32, height: u32, data: Vec<u8>) -> Image {
    Image::new(
        bevy::render::render_resource::Extent3d {
            width,
            height,
            depth_or_array_layers: 1,
        },
        bevy::render::render_resource::TextureDimension::D2,
        data,
        bevy::render::render_resource::TextureFormat::Rgba8UnormSrgb,
        RenderAssetUsages::default(),
    )
}

/// A trunk standing on the origin, tapering to 60 % of its radius.
fn trunk(radius: f32, height: f32, sides: u32) -> Mesh {
    let mut mesh = Cylinder::new(radius, height)
        .mesh()
        .resolution(sides)
        .build()
        .translated_by(Vec3::Y * height / 2.0);
    if let Some(VertexAttributeValues::Float32x3(p)) = mesh.attribute_mut(Mesh::ATTRIBUTE_POSITION)
    {
        for v in p.iter_mut() {
            let taper = 1.0 - 0.4 * (v[1] / height).clamp(0.0, 1.0);
            v[0] *= taper;
            v[2] *= taper;
        }
    }
    painted(mesh, Color::WHITE)
}

/// White bark with dark marks in bands.
fn marked_bark(mesh: &mut Mesh) {
    let noise = Perlin::new(7);
    let colors: Vec<[f32; 4]> = positions(mesh)
        .iter()
        .map(|p| {
            let mark = noise.get([p[1] as f64 * 2.5, p[0] as f64 * 3.0, p[2] as f64 * 3.0]);
            let c = if mark > 0.25 { 0.05 } else { 0.75 };
            [c, c, c * 0.95, 1.0]
        })
        .collect();
    mesh.insert_attribute(Mesh::ATTRIBUTE_COLOR, colors);
}

fn positions(mesh: &Mesh) -> Vec<[f32; 3]> {
    match mesh.attribute(Mesh::ATTRIBUTE_POSITION) {
        Some(VertexAttributeValues::Float32x3(p)) => p.clone(),
        _ => Vec::new(),
    }
}

/// Pushes each vertex out from the origin by up to `amount` of its distance, by smooth
/// noise of its position: lumps instead of spheres.
fn lumpy(mut mesh: Mesh, seed: u32, amount: f32, frequency: f32) -> Mesh {
    let noise = Perlin::new(seed);
    if let Some(VertexAttributeValues::Float32x3(p)) = mesh.attribute_mut(Mesh::ATTRIBUTE_POSITION)
    {
        for v in p.iter_mut() {
            let q = Vec3::from(*v) * frequency;
            let n = noise.get([q.x as f64, q.y as f64, q.z as f64]) as f32;
            *v = (Vec3::from(*v) * (1.0 + amount * n)).to_array();
        }
    }
    mesh
}

/// Vertex colour `color` everywhere.
fn painted(mut mesh: Mesh, color: Color) -> Mesh {
    let c = color.to_linear().to_f32_array();
    let n = mesh.count_vertices();
    mesh.insert_attribute(Mesh::ATTRIBUTE_COLOR, vec![c; n]);
    mesh
}

/// Vertex colour `color`, darker or lighter by up to `variation` by noise, and darker
/// underneath (self-shadowing of a canopy).
fn shaded(mut mesh: Mesh, color: Color, variation: f32, seed: u32) -> Mesh {
    let noise = Perlin::new(seed);
    let base = color.to_linear();
    let p = positions(&mesh);
    let (lo, hi) = p.iter().fold((f32::MAX, f32::MIN), |(lo, hi), v| {
        (lo.min(v[1]), hi.max(v[1]))
    });
    let colors: Vec<[f32; 4]> = p
        .iter()
        .map(|v| {
            let n = noise.get([v[0] as f64 * 1.7, v[1] as f64 * 1.7, v[2] as f64 * 1.7]) as f32;
            let up = ((v[1] - lo) / (hi - lo).max(1e-3)).clamp(0.0, 1.0);
            let k = (1.0 + variation * n) * (0.65 + 0.35 * up);
            [base.red * k, base.green * k, base.blue * k, 1.0]
        })
        .collect();
    mesh.insert_attribute(Mesh::ATTRIBUTE_COLOR, colors);
    mesh
}

/// One mesh of all the parts (each with positions, normals, uvs and colours).
fn merged(parts: Vec<Mesh>) -> Mesh {
    let mut parts = parts.into_iter();
    let mut mesh = parts.next().expect("at least one part");
    for part in parts {
        mesh.merge(&part).expect("parts with the same attributes");
    }
    mesh
}

/// Flat-shaded facets.
fn faceted(mut mesh: Mesh) -> Mesh {
    mesh.duplicate_vertices();
    mesh.compute_flat_normals();
    mesh
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_meshes_stand_on_their_origin_and_have_what_the_renderer_needs() {
        let trees = [conifer(), broadleaf(), birch()];
        let mut all: Vec<(Mesh, f32)> = vec![(flower(0.4), 0.4), (fern(7, 1.6), 0.8)];
        for t in trees {
            let (far, near) = (t.far.count_vertices(), t.near.count_vertices());
            assert!(far * 2 < near, "a cheaper far mesh: {far} vs {near}");
            all.push((t.near, 7.0));
            all.push((t.far, 7.0));
        }
        for (mesh, min_height) in all {
            let p = positions(&mesh);
            let n = mesh.count_vertices();
            assert!(n > 10 && p.len() == n);
            let top = p.iter().map(|v| v[1]).fold(f32::MIN, f32::max);
            let bottom = p.iter().map(|v| v[1]).fold(f32::MAX, f32::min);
            assert!(
                top >= min_height && bottom < 0.5 && bottom > -1.0,
                "{bottom}..{top}"
            );
            assert!(mesh.attribute(Mesh::ATTRIBUTE_NORMAL).is_some());
        }
    }

    #[test]
    fn the_fern_is_cut_out_between_its_leaflets_and_mapped_to_the_whole_texture() {
        let texture = fern_texture();
        let alpha = |x: u32, y: u32| texture.get_color_at(x, y).unwrap().alpha();
        let (w, h) = (texture.width(), texture.height());
        let opaque = (0..h)
            .flat_map(|y| (0..w).map(move |x| (x, y)))
            .filter(|&(x, y)| alpha(x, y) > 0.5)
            .count() as f32
            / (w * h) as f32;
        assert!((0.2..0.7).contains(&opaque), "opaque fraction {opaque}");
        // The midrib is opaque up to near the tip; the corners beside the tip are not.
        assert!(alpha(w / 2, h / 2) > 0.5 && alpha(w / 2, h - 2) > 0.5);
        assert!(alpha(0, 0) < 0.5 && alpha(w - 1, 0) < 0.5);
        let mesh = fern(7, 1.6);
        let Some(VertexAttributeValues::Float32x2(uv)) = mesh.attribute(Mesh::ATTRIBUTE_UV_0)
        else {
            panic!("a fern has UVs");
        };
        let (lo, hi) = uv.iter().fold((f32::MAX, f32::MIN), |(lo, hi), t| {
            (lo.min(t[0].min(t[1])), hi.max(t[0].max(t[1])))
        });
        assert_eq!((lo, hi), (0.0, 1.0));
    }
}
