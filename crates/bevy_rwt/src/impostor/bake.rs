//! Baking an impostor atlas on the CPU: the class's mesh (or an asset's primitives), coloured
//! by its material (base colour, vertex colours, base-colour texture, alpha cut-out), rasterized orthographically
//! from every view into one sRGB image: albedo and coverage on the left half, normals in
//! the mesh's frame on the right half, with a mip chain whose cut-out coverage stays that of
//! the full-size views. Deterministic: the same mesh and material bake the same bytes.

use super::atlas::{Level, Texel, atlas_image};
pub use super::frames::{ImpostorFrames, card_axes};
use crate::look::Impostor;
use bevy::mesh::{Indices, PrimitiveTopology, VertexAttributeValues};
use bevy::prelude::*;

/// Supersampling of the raster along each axis (coverage in steps of a quarter).
const SUPERSAMPLE: u32 = 2;

/// Why a class's impostor cannot be baked (its instances are then drawn as meshes only).
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum BakeError {
    /// The mesh's data stayed in the render world only (`RenderAssetUsages::RENDER_WORLD`).
    #[error("the mesh's vertices are not readable in the main world")]
    Unreadable,
    /// The mesh has no `Mesh::ATTRIBUTE_POSITION` in `Float32x3`.
    #[error("the mesh has no vertex positions")]
    NoPositions,
    /// Points and lines have no surface to bake.
    #[error("the mesh's topology is {0:?}; impostors bake triangle lists or strips")]
    Topology(PrimitiveTopology),
    /// The mesh covers no area.
    #[error("the mesh has no triangle of any size")]
    Empty,
}

/// What a class looks like, as the bake reads it.
pub struct BakeSource<'a> {
    /// The mesh (positions; normals, colours and UVs where it has them).
    pub mesh: &'a Mesh,
    /// The material's base colour (linear), or an instanced class's colours from root to
    /// tip.
    pub color: BakeColor,
    /// Whether the mesh's vertex colours tint it (a `StandardMaterial` reads them; the
    /// instanced shading does not).
    pub vertex_colors: bool,
    /// How far normals lean towards the sky (0..1; the instanced shading leans its blades'
    /// by 0.45 so that they read as blades).
    pub lean: f32,
    /// The material's base-colour texture, where it has one that loaded.
    pub texture: Option<&'a Image>,
    /// Alpha below which the material is cut out (`None`: opaque).
    pub alpha_cutoff: Option<f32>,
}

/// The colour a bake gives the mesh before its texture.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum BakeColor {
    /// One colour (linear).
    Plain(LinearRgba),
    /// As the instanced shading blends it: the base colour below `tip_from` of the height
    /// (from 0 up to the mesh's top), the tip colour blending in above it.
    Gradient {
        /// At the root.
        base: LinearRgba,
        /// At the top.
        tip: LinearRgba,
        /// Height fraction where the tip colour starts.
        tip_from: f32,
    },
}

impl BakeColor {
    /// The colour at height `y` of a mesh whose top is `top`.
    fn at(&self, y: f32, top: f32) -> Vec4 {
        match *self {
            BakeColor::Plain(c) => Vec4::from(c.to_f32_array()),
            BakeColor::Gradient {
                base,
                tip,
                tip_from,
            } => {
                let t = (y / top.max(1e-3)).clamp(0.0, 1.0);
                let from = tip_from.clamp(0.0, 0.99);
                let k = ((t - from) / (1.0 - from)).clamp(0.0, 1.0);
                Vec4::from(base.to_f32_array()).lerp(Vec4::from(tip.to_f32_array()), k)
            }
        }
    }
}

/// A baked atlas and where its views lie.
pub struct BakedImpostor {
    /// `Rgba8UnormSrgb`, with mips: albedo and coverage, then normals (encoded so that the
    /// sampler's sRGB decoding gives `n * 0.5 + 0.5`).
    pub image: Image,
    /// Where the views lie.
    pub frames: ImpostorFrames,
}

/// One vertex as the raster reads it.
#[derive(Clone, Copy)]
struct BakeVertex {
    position: Vec3,
    normal: Vec3,
    color: Vec4,
    uv: Vec2,
}

/// Bakes `source` with the views of `settings`.
pub fn bake(source: &BakeSource, settings: &Impostor) -> Result<BakedImpostor, BakeError> {
    bake_parts(std::slice::from_ref(source), settings)
}

/// Bakes the parts of one look together (an asset's primitives, each with its material):
/// every view shows them all, the nearer hiding the farther, framed by their joint bounds.
pub fn bake_parts(parts: &[BakeSource], settings: &Impostor) -> Result<BakedImpostor, BakeError> {
    let meshes = parts
        .iter()
        .map(|p| read_mesh(p.mesh))
        .collect::<Result<Vec<_>, _>>()?;
    if meshes.is_empty() {
        return Err(BakeError::Empty);
    }
    let every = || meshes.iter().flat_map(|(vertices, _)| vertices);
    let (lo, hi) = every().fold(
        (Vec3::splat(f32::MAX), Vec3::splat(f32::MIN)),
        |(lo, hi), v| (lo.min(v.position), hi.max(v.position)),
    );
    let center = 0.5 * (lo + hi);
    let (views, rows, texels) = settings.clamped();
    let mut frames = ImpostorFrames {
        views,
        rows,
        texels,
        center,
        half: Vec2::ZERO,
    };
    frames.half = half_extents(&frames, every());
    if frames.half.min_element() <= 0.0 {
        return Err(BakeError::Empty);
    }
    let size = frames.size();
    let mut level = Level::new(size);
    for j in 0..rows {
        for i in 0..views {
            let mut raster = Raster::new(frames.texels * SUPERSAMPLE);
            for (part, (vertices, triangles)) in parts.iter().zip(&meshes) {
                raster.draw(&frames, (i, j, hi.y), part, (vertices, triangles));
            }
            raster.store(&mut level, (i * texels, j * texels), (views * texels, 0));
        }
    }
    level.dilate(4);
    // The mips keep the coverage of the strictest cut-out.
    let cutoff = parts
        .iter()
        .filter_map(|p| p.alpha_cutoff)
        .fold(None, |m: Option<f32>, c| Some(m.map_or(c, |m| m.max(c))));
    let image = atlas_image(&frames, level, cutoff.unwrap_or(0.5));
    Ok(BakedImpostor { image, frames })
}

/// The half width and height every view must cover: the mesh's farthest reach across the
/// vertical axis through the centre, and the largest half height over the rows.
fn half_extents<'a>(
    frames: &ImpostorFrames,
    vertices: impl Iterator<Item = &'a BakeVertex>,
) -> Vec2 {
    let (across, up) = vertices.fold((0.0f32, 0.0f32), |(a, u), v| {
        let d = v.position - frames.center;
        (a.max(d.xz().length()), u.max(d.y.abs()))
    });
    let tallest = (0..frames.rows)
        .map(|j| {
            let e = frames.elevation(j);
            up * e.cos() + across * e.sin()
        })
        .fold(0.0f32, f32::max);
    // A texel's margin, so that the outline never touches the view's edge.
    let margin = 1.0 + 2.0 / frames.texels as f32;
    Vec2::new(across, tallest) * margin
}

/// The vertices and triangles of a mesh.
fn read_mesh(mesh: &Mesh) -> Result<(Vec<BakeVertex>, Vec<[usize; 3]>), BakeError> {
    let attribute = |id| {
        mesh.try_attribute_option(id)
            .map_err(|_| BakeError::Unreadable)
    };
    let positions = attribute(Mesh::ATTRIBUTE_POSITION)?
        .and_then(VertexAttributeValues::as_float3)
        .ok_or(BakeError::NoPositions)?;
    let normals = attribute(Mesh::ATTRIBUTE_NORMAL)?.and_then(VertexAttributeValues::as_float3);
    let colors = match attribute(Mesh::ATTRIBUTE_COLOR)? {
        Some(VertexAttributeValues::Float32x4(c)) => Some(c.as_slice()),
        _ => None,
    };
    let uvs = match attribute(Mesh::ATTRIBUTE_UV_0)? {
        Some(VertexAttributeValues::Float32x2(uv)) => Some(uv.as_slice()),
        _ => None,
    };
    let n = positions.len();
    let at = |values: Option<&[[f32; 3]]>, i: usize| values.and_then(|v| v.get(i)).copied();
    let vertices = (0..n)
        .map(|i| BakeVertex {
            position: Vec3::from(positions[i]),
            normal: at(normals, i).map_or(Vec3::ZERO, Vec3::from),
            color: colors
                .and_then(|c| c.get(i))
                .map_or(Vec4::ONE, |c| Vec4::from(*c)),
            uv: uvs
                .and_then(|u| u.get(i))
                .map_or(Vec2::ZERO, |u| Vec2::from(*u)),
        })
        .collect();
    let indices: Vec<usize> = match mesh
        .try_indices_option()
        .map_err(|_| BakeError::Unreadable)?
    {
        Some(Indices::U16(i)) => i.iter().map(|&i| i as usize).collect(),
        Some(Indices::U32(i)) => i.iter().map(|&i| i as usize).collect(),
        None => (0..n).collect(),
    };
    let triangles: Vec<[usize; 3]> = match mesh.primitive_topology() {
        PrimitiveTopology::TriangleList => indices
            .chunks_exact(3)
            .map(|t| [t[0], t[1], t[2]])
            .collect(),
        PrimitiveTopology::TriangleStrip => {
            indices.windows(3).map(|t| [t[0], t[1], t[2]]).collect()
        }
        other => return Err(BakeError::Topology(other)),
    };
    let triangles: Vec<[usize; 3]> = triangles
        .into_iter()
        .filter(|t| t.iter().all(|&i| i < n))
        .collect();
    if triangles.is_empty() {
        return Err(BakeError::Empty);
    }
    Ok((vertices, triangles))
}

/// One view rasterized at the supersampled size.
struct Raster {
    side: u32,
    depth: Vec<f32>,
    texels: Vec<Texel>,
}

impl Raster {
    /// An empty view `side` texels wide.
    fn new(side: u32) -> Self {
        Self {
            side,
            depth: vec![f32::MIN; (side * side) as usize],
            texels: vec![Texel::default(); (side * side) as usize],
        }
    }

    /// Draws a mesh seen in view `i` of row `j`, nearer than what is there (`top`: the
    /// look's top, where a gradient reaches its tip colour).
    fn draw(
        &mut self,
        frames: &ImpostorFrames,
        (i, j, top): (u32, u32, f32),
        source: &BakeSource,
        (vertices, triangles): (&[BakeVertex], &[[usize; 3]]),
    ) {
        let side = self.side;
        let direction = frames.direction(i, j);
        let (right, up) = card_axes(direction);
        let project = |p: Vec3| {
            let d = p - frames.center;
            let u = d.dot(right) / frames.half.x;
            let v = d.dot(up) / frames.half.y;
            Vec3::new(
                (u * 0.5 + 0.5) * side as f32,
                (0.5 - v * 0.5) * side as f32,
                d.dot(direction),
            )
        };
        let projected: Vec<Vec3> = vertices.iter().map(|v| project(v.position)).collect();
        for t in triangles {
            let corners = t.map(|k| projected[k]);
            let attributes = t.map(|k| vertices[k]);
            self.triangle(corners, attributes, source, (direction, top));
        }
    }

    /// Fills the texels a triangle covers where it is nearer than what is there.
    fn triangle(
        &mut self,
        [a, b, c]: [Vec3; 3],
        attributes: [BakeVertex; 3],
        source: &BakeSource,
        (direction, top): (Vec3, f32),
    ) {
        let area = (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
        if area.abs() < 1e-12 {
            return;
        }
        let lo = a.min(b).min(c).floor().max(Vec3::ZERO);
        let hi = a.max(b).max(c).ceil().min(Vec3::splat(self.side as f32));
        let flat = (attributes[1].position - attributes[0].position)
            .cross(attributes[2].position - attributes[0].position)
            .normalize_or_zero();
        for y in lo.y as u32..hi.y as u32 {
            for x in lo.x as u32..hi.x as u32 {
                let p = Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
                let edge = |s: Vec3, e: Vec3| (e.x - s.x) * (p.y - s.y) - (e.y - s.y) * (p.x - s.x);
                let w = Vec3::new(edge(b, c), edge(c, a), edge(a, b)) / area;
                if w.min_element() < 0.0 {
                    continue;
                }
                let depth = w.x * a.z + w.y * b.z + w.z * c.z;
                let k = (y * self.side + x) as usize;
                if depth <= self.depth[k] {
                    continue;
                }
                let mix = |f: fn(&BakeVertex) -> Vec4| {
                    w.x * f(&attributes[0]) + w.y * f(&attributes[1]) + w.z * f(&attributes[2])
                };
                let y = mix(|v| v.position.extend(0.0)).y;
                let mut color = source.color.at(y, top);
                if source.vertex_colors {
                    color *= mix(|v| v.color);
                }
                if let Some(texture) = source.texture {
                    color *= sample(texture, mix(|v| v.uv.extend(0.0).extend(0.0)).xy());
                }
                if source.alpha_cutoff.is_some_and(|cut| color.w < cut) {
                    continue;
                }
                let normal = mix(|v| v.normal.extend(0.0)).truncate().normalize_or(flat);
                let normal = normal.lerp(Vec3::Y, source.lean).normalize_or(normal);
                // Seen from the side the view looks from (leaves are seen from both).
                let normal = if normal.dot(direction) < 0.0 {
                    -normal
                } else {
                    normal
                };
                self.depth[k] = depth;
                self.texels[k] = Texel {
                    albedo: color.truncate(),
                    coverage: 1.0,
                    normal,
                };
            }
        }
    }

    /// Averages the supersamples into `level`: albedo at `albedo`, normals at `albedo` +
    /// `normals` (texel offsets).
    fn store(&self, level: &mut Level, albedo: (u32, u32), normals: (u32, u32)) {
        let out = self.side / SUPERSAMPLE;
        for y in 0..out {
            for x in 0..out {
                let mut sum = Texel::default();
                for (dx, dy) in
                    (0..SUPERSAMPLE).flat_map(|dx| (0..SUPERSAMPLE).map(move |dy| (dx, dy)))
                {
                    let t = self.texels
                        [((y * SUPERSAMPLE + dy) * self.side + x * SUPERSAMPLE + dx) as usize];
                    sum.albedo += t.albedo * t.coverage;
                    sum.normal += t.normal * t.coverage;
                    sum.coverage += t.coverage;
                }
                let n = (SUPERSAMPLE * SUPERSAMPLE) as f32;
                let texel = if sum.coverage > 0.0 {
                    Texel {
                        albedo: sum.albedo / sum.coverage,
                        coverage: sum.coverage / n,
                        normal: sum.normal.normalize_or(Vec3::Z),
                    }
                } else {
                    Texel::default()
                };
                level.set(albedo.0 + x, albedo.1 + y, texel);
                level.set_normal(albedo.0 + normals.0 + x, albedo.1 + normals.1 + y, texel);
            }
        }
    }
}

/// A texture's colour at `uv` (nearest texel, repeating), linear; white where it cannot
/// be read.
fn sample(image: &Image, uv: Vec2) -> Vec4 {
    let size = image.size();
    if size.x == 0 || size.y == 0 {
        return Vec4::ONE;
    }
    let wrap = |t: f32, n: u32| ((t.rem_euclid(1.0) * n as f32) as u32).min(n - 1);
    image
        .get_color_at(wrap(uv.x, size.x), wrap(uv.y, size.y))
        .map_or(Vec4::ONE, |c| Vec4::from(c.to_linear().to_f32_array()))
}

#[cfg(test)]
mod tests {
    use super::*;
    use bevy::asset::RenderAssetUsages;

    fn settings(views: u32, rows: u32, texels: u32) -> Impostor {
        Impostor {
            views,
            rows,
            texels,
            ..Impostor::at(100.0)
        }
    }

    fn source(mesh: &Mesh) -> BakeSource<'_> {
        BakeSource {
            mesh,
            color: BakeColor::Plain(LinearRgba::rgb(0.5, 0.25, 1.0)),
            vertex_colors: true,
            lean: 0.0,
            texture: None,
            alpha_cutoff: None,
        }
    }

    /// A box 2 wide (x), 4 tall (y) and 1 deep (z), standing on the origin.
    fn tall_box() -> Mesh {
        Cuboid::new(2.0, 4.0, 1.0)
            .mesh()
            .build()
            .translated_by(Vec3::Y * 2.0)
    }

    /// The level-0 texel (albedo half) of view `i`, row `j`, at (x, y) in it: RGBA bytes.
    fn texel(
        baked: &BakedImpostor,
        (i, j): (u32, u32),
        (x, y): (u32, u32),
        normals: bool,
    ) -> [u8; 4] {
        let f = baked.frames;
        let width = f.size().x;
        let column = i * f.texels + x + if normals { f.views * f.texels } else { 0 };
        let k = (((j * f.texels + y) * width + column) * 4) as usize;
        let data = baked.image.data.as_ref().unwrap();
        [data[k], data[k + 1], data[k + 2], data[k + 3]]
    }

    /// The covered texels (alpha at least half) of view `(i, j)`.
    fn silhouette(baked: &BakedImpostor, view: (u32, u32)) -> Vec<bool> {
        let t = baked.frames.texels;
        (0..t * t)
            .map(|k| texel(baked, view, (k % t, k / t), false)[3] >= 128)
            .collect()
    }

    /// Which texels of a view the box `half` (x, z half sizes) at height 0..4 covers, seen
    /// from the front (view 0) or the side (a quarter turn), computed exactly.
    fn box_outline(frames: &ImpostorFrames, half_width: f32) -> Vec<bool> {
        let t = frames.texels;
        (0..t * t)
            .map(|k| {
                let (x, y) = ((k % t) as f32 + 0.5, (k / t) as f32 + 0.5);
                let u = (x / t as f32 * 2.0 - 1.0) * frames.half.x;
                let v = (1.0 - y / t as f32 * 2.0) * frames.half.y + frames.center.y;
                u.abs() < half_width && (0.0..4.0).contains(&v)
            })
            .collect()
    }

    fn iou(a: &[bool], b: &[bool]) -> f32 {
        let both = a.iter().zip(b).filter(|(x, y)| **x && **y).count();
        let either = a.iter().zip(b).filter(|(x, y)| **x || **y).count();
        both as f32 / either.max(1) as f32
    }

    #[test]
    fn each_view_shows_the_mesh_from_its_direction() {
        let mesh = tall_box();
        let baked = bake(&source(&mesh), &settings(4, 1, 64)).unwrap();
        let f = baked.frames;
        assert!((f.center - Vec3::new(0.0, 2.0, 0.0)).length() < 1e-5);
        // Across: the box's farthest corner from the axis; up: its half height.
        assert!(
            (f.half.x / 1.25f32.sqrt() - 1.0).abs() < 0.05,
            "{:?}",
            f.half
        );
        assert!((f.half.y / 2.0 - 1.0).abs() < 0.05, "{:?}", f.half);
        // View 0 looks along -z (the box's 2 m face), view 1 along -x (its 1 m side).
        let front = iou(&silhouette(&baked, (0, 0)), &box_outline(&f, 1.0));
        let side = iou(&silhouette(&baked, (1, 0)), &box_outline(&f, 0.5));
        assert!(front > 0.95 && side > 0.95, "front {front}, side {side}");
        assert!(iou(&silhouette(&baked, (0, 0)), &box_outline(&f, 0.5)) < 0.6);
    }

    #[test]
    fn albedo_is_the_material_times_the_vertex_colours_and_normals_face_the_view() {
        let mut mesh = tall_box();
        let count = mesh.count_vertices();
        mesh.insert_attribute(Mesh::ATTRIBUTE_COLOR, vec![[0.5, 1.0, 1.0, 1.0]; count]);
        let baked = bake(&source(&mesh), &settings(4, 1, 64)).unwrap();
        let middle = (32, 32);
        let albedo = texel(&baked, (0, 0), middle, false);
        let expected = Srgba::from(LinearRgba::rgb(0.25, 0.25, 1.0)).to_u8_array();
        for c in 0..3 {
            assert!(
                albedo[c].abs_diff(expected[c]) <= 1,
                "{albedo:?} vs {expected:?}"
            );
        }
        assert_eq!(albedo[3], 255);
        // The front face's normal, +z, encoded so that sRGB decoding gives n / 2 + 1/2.
        let normal = texel(&baked, (0, 0), middle, true);
        let decoded = LinearRgba::from(Srgba::rgb_u8(normal[0], normal[1], normal[2])).to_vec3();
        assert!(
            (decoded * 2.0 - Vec3::ONE - Vec3::Z).length() < 0.02,
            "{decoded}"
        );
        // Outside the box: nothing covered.
        assert_eq!(texel(&baked, (0, 0), (1, 1), false)[3], 0);
    }

    #[test]
    fn an_instanced_class_bakes_its_root_to_tip_colours_and_leaned_normals() {
        let mut mesh = tall_box();
        let count = mesh.count_vertices();
        // The instanced shading reads no vertex colour.
        mesh.insert_attribute(Mesh::ATTRIBUTE_COLOR, vec![[0.0, 0.0, 0.0, 1.0]; count]);
        let mut s = source(&mesh);
        s.color = BakeColor::Gradient {
            base: LinearRgba::RED,
            tip: LinearRgba::BLUE,
            tip_from: 0.0,
        };
        s.vertex_colors = false;
        s.lean = 0.45;
        let baked = bake(&s, &settings(4, 1, 64)).unwrap();
        let f = baked.frames;
        // Rows of the front view a tenth and nine tenths up the box (4 m tall).
        let row = |h: f32| ((0.5 - (h - f.center.y) / f.half.y * 0.5) * 64.0) as u32;
        let low = texel(&baked, (0, 0), (32, row(0.4)), false);
        let high = texel(&baked, (0, 0), (32, row(3.6)), false);
        assert!(low[0] > 200 && low[2] < 130, "{low:?}");
        assert!(high[2] > 200 && high[0] < 130, "{high:?}");
        // The front face's normal (+z) leaned towards the sky.
        let normal = texel(&baked, (0, 0), (32, 32), true);
        let n = LinearRgba::from(Srgba::rgb_u8(normal[0], normal[1], normal[2])).to_vec3() * 2.0
            - Vec3::ONE;
        let leaned = Vec3::Z.lerp(Vec3::Y, 0.45).normalize();
        assert!((n - leaned).length() < 0.03, "{n}");
    }

    #[test]
    fn mips_keep_the_cut_out_as_dense_as_the_full_size_views() {
        // A thin cross of leaves: coverage averaged down a plain mip chain thins out.
        let blades = [0.0f32, 0.7, 1.4, 2.1].map(|turn| {
            Cuboid::new(3.0, 0.05, 0.02)
                .mesh()
                .build()
                .rotated_by(Quat::from_rotation_z(turn))
                .translated_by(Vec3::Y * 2.0)
        });
        let mut mesh = blades[0].clone();
        for b in &blades[1..] {
            mesh.merge(b).unwrap();
        }
        let mut s = source(&mesh);
        s.alpha_cutoff = Some(0.5);
        let baked = bake(&s, &settings(3, 1, 64)).unwrap();
        let f = baked.frames;
        let (w, h) = (f.size().x as usize, f.size().y as usize);
        let data = baked.image.data.as_ref().unwrap();
        let share = |offset: usize, w: usize, h: usize| {
            let kept = (0..w * h)
                .filter(|k| data[offset + 4 * k + 3] >= 128)
                .count();
            kept as f32 / (w * h) as f32
        };
        let base = share(0, w, h);
        let mip2 = share(4 * (w * h + w * h / 4), w / 4, h / 4);
        assert!(base > 0.01, "{base}");
        assert!(
            (mip2 / base - 1.0).abs() < 0.35,
            "level 0 {base}, level 2 {mip2}"
        );
        assert_eq!(baked.image.texture_descriptor.mip_level_count, 5);
    }

    #[test]
    fn parts_bake_together_each_in_its_colour_the_nearer_hiding_the_farther() {
        let tower = |x: f32| {
            Cuboid::new(1.0, 4.0, 1.0)
                .mesh()
                .build()
                .translated_by(Vec3::new(x, 2.0, 0.0))
        };
        let (left, right) = (tower(-1.0), tower(1.0));
        let mut red = source(&left);
        red.color = BakeColor::Plain(LinearRgba::RED);
        let mut blue = source(&right);
        blue.color = BakeColor::Plain(LinearRgba::BLUE);
        let baked = bake_parts(&[red, blue], &settings(4, 1, 64)).unwrap();
        let f = baked.frames;
        // Framed by both: centred between them, wide enough for both.
        assert!((f.center - Vec3::new(0.0, 2.0, 0.0)).length() < 1e-5);
        assert!(f.half.x > 1.5, "{:?}", f.half);
        let column = |x: f32| ((x / f.half.x * 0.5 + 0.5) * 64.0) as u32;
        let is = |t: [u8; 4], red: bool| match red {
            true => t[0] > 200 && t[2] < 60,
            false => t[2] > 200 && t[0] < 60,
        };
        let (l, r) = (
            texel(&baked, (0, 0), (column(-1.0), 32), false),
            texel(&baked, (0, 0), (column(1.0), 32), false),
        );
        assert!(is(l, true) && is(r, false), "{l:?} {r:?}");
        // Seen along their row, the nearer tower hides the other.
        let blue_nearer = f.direction(1, 0).x > 0.0;
        let middle = texel(&baked, (1, 0), (32, 32), false);
        assert!(is(middle, !blue_nearer), "{middle:?}");
        assert_eq!(
            bake_parts(&[], &settings(4, 1, 64)).err(),
            Some(BakeError::Empty)
        );
    }

    #[test]
    fn the_same_mesh_bakes_the_same_bytes_and_bad_meshes_are_refused() {
        let mesh = tall_box();
        let a = bake(&source(&mesh), &settings(5, 2, 32)).unwrap();
        let b = bake(&source(&mesh), &settings(5, 2, 32)).unwrap();
        assert_eq!(a.image.data, b.image.data);
        assert_eq!(a.frames, b.frames);
        let empty = Mesh::new(
            PrimitiveTopology::TriangleList,
            RenderAssetUsages::default(),
        );
        assert_eq!(
            bake(&source(&empty), &settings(5, 2, 32)).err(),
            Some(BakeError::NoPositions)
        );
        let lines = Mesh::new(PrimitiveTopology::LineList, RenderAssetUsages::default())
            .with_inserted_attribute(Mesh::ATTRIBUTE_POSITION, vec![[0.0f32, 0.0, 0.0]; 2]);
        assert_eq!(
            bake(&source(&lines), &settings(5, 2, 32)).err(),
            Some(BakeError::Topology(PrimitiveTopology::LineList))
        );
        let flat = Mesh::new(
            PrimitiveTopology::TriangleList,
            RenderAssetUsages::default(),
        )
        .with_inserted_attribute(Mesh::ATTRIBUTE_POSITION, vec![[1.0f32, 1.0, 1.0]; 3]);
        assert_eq!(
            bake(&source(&flat), &settings(5, 2, 32)).err(),
            Some(BakeError::Empty)
        );
    }
}
