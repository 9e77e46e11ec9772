//! The pack's textures, drawn in code and written as PNG: bark (albedo and normal map),
//! leaf clusters cut out by their alpha, and rock (albedo and normal map). Normal maps are
//! tangent space, linear, +y up the texture (glTF's convention), from a height field.

use noise::{NoiseFn, Perlin};

/// An RGBA image of `width` x `height` as PNG bytes, each texel from `texel(x, y)` (rows
/// from the top).
pub fn png(width: u32, height: u32, texel: impl Fn(u32, u32) -> [u8; 4]) -> Vec<u8> {
    let image = image::RgbaImage::from_fn(width, height, |x, y| image::Rgba(texel(x, y)));
    let mut bytes = Vec::new();
    image
        .write_to(
            &mut std::io::Cursor::new(&mut bytes),
            image::ImageFormat::Png,
        )
        .expect("a PNG encodes in memory");
    bytes
}

/// A colour map and its normal map (PNG bytes).
#[derive(Clone, Debug)]
pub struct Maps {
    /// sRGB albedo.
    pub albedo: Vec<u8>,
    /// Linear tangent-space normals.
    pub normal: Vec<u8>,
}

/// The albedo and normal map of a height field on a `width` x `height` grid that repeats:
/// `height_at(u, v)` in 0..1 (u, v in 0..1), `colour(h, u, v)` the albedo (sRGB bytes);
/// `relief` scales the slopes.
fn mapped(
    (width, height): (u32, u32),
    height_at: impl Fn(f64, f64) -> f64,
    colour: impl Fn(f64, f64, f64) -> [u8; 3],
    relief: f64,
) -> Maps {
    let uv = |x: u32, y: u32| {
        (
            (x as f64 + 0.5) / width as f64,
            (y as f64 + 0.5) / height as f64,
        )
    };
    let albedo = png(width, height, |x, y| {
        let (u, v) = uv(x, y);
        let [r, g, b] = colour(height_at(u, v), u, v);
        [r, g, b, 255]
    });
    let normal = png(width, height, |x, y| {
        let at = |dx: i32, dy: i32| {
            let xs = (x as i32 + dx).rem_euclid(width as i32) as u32;
            let ys = (y as i32 + dy).rem_euclid(height as i32) as u32;
            let (u, v) = uv(xs, ys);
            height_at(u, v)
        };
        let sx = (at(1, 0) - at(-1, 0)) * relief;
        // Image rows run down; the map's +y runs up the texture.
        let sy = (at(0, -1) - at(0, 1)) * relief;
        let n = glam::DVec3::new(-sx, -sy, 1.0).normalize();
        let byte = |c: f64| ((c * 0.5 + 0.5) * 255.0).round() as u8;
        [byte(n.x), byte(n.y), byte(n.z), 255]
    });
    Maps { albedo, normal }
}

/// Fractal noise in 0..1 that repeats over the unit square (`cells` noise cells across).
fn tiling_noise(perlin: &Perlin, (u, v): (f64, f64), cells: f64, octaves: u32) -> f64 {
    let mut sum = 0.0;
    let (mut amplitude, mut frequency, mut total) = (1.0, cells, 0.0);
    for _ in 0..octaves {
        // Round the unit square onto a torus: the noise repeats at its edges.
        let (a, b) = (u * std::f64::consts::TAU, v * std::f64::consts::TAU);
        let r = frequency / std::f64::consts::TAU;
        let p = [r * a.cos(), r * a.sin(), r * b.cos(), r * b.sin()];
        sum += amplitude * perlin.get(p);
        total += amplitude;
        amplitude *= 0.5;
        frequency *= 2.0;
    }
    (sum / total * 0.5 + 0.5).clamp(0.0, 1.0)
}

fn mix(a: [f64; 3], b: [f64; 3], t: f64) -> [u8; 3] {
    let t = t.clamp(0.0, 1.0);
    [0, 1, 2].map(|k| {
        ((a[k] + (b[k] - a[k]) * t) * 255.0)
            .round()
            .clamp(0.0, 255.0) as u8
    })
}

/// Bark: vertical furrows between ridges, `light` on the ridges and `dark` in the furrows
/// (sRGB 0..1); u runs round the trunk, v up it.
pub fn bark(seed: u32, light: [f64; 3], dark: [f64; 3]) -> Maps {
    let perlin = Perlin::new(seed);
    let height = |u: f64, v: f64| {
        // Ridges wander across as they run up.
        let wander = tiling_noise(&perlin, (u, v), 3.0, 2) * 0.35;
        let ridges = ((u + wander) * 9.0 * std::f64::consts::TAU).sin() * 0.5 + 0.5;
        let grain = tiling_noise(&perlin, (u * 1.0, v), 24.0, 3);
        (ridges.powf(0.6) * 0.75 + grain * 0.25).clamp(0.0, 1.0)
    };
    mapped(
        (128, 256),
        height,
        |h, _, _| mix(dark, light, h * 1.2 - 0.1),
        6.0,
    )
}

/// Birch bark: white, with dark lenticels across it and a few dark patches.
pub fn birch_bark(seed: u32) -> Maps {
    let perlin = Perlin::new(seed);
    let marks = move |u: f64, v: f64| {
        let band = tiling_noise(&perlin, (u * 0.2, v), 40.0, 2);
        let across = tiling_noise(&perlin, (u, v * 0.1), 6.0, 2);
        let dash = if band > 0.72 && across > 0.45 {
            1.0
        } else {
            0.0
        };
        let patch = (tiling_noise(&perlin, (u, v), 5.0, 3) - 0.62).max(0.0) * 4.0;
        (dash + patch).min(1.0)
    };
    mapped(
        (128, 256),
        move |u, v| 1.0 - 0.6 * marks(u, v),
        move |h, _, _| mix([0.12, 0.11, 0.1], [0.9, 0.88, 0.82], (h - 0.4) / 0.6),
        3.0,
    )
}

/// Rock: lumpy grey with darker cracks and specks of lichen.
pub fn rock(seed: u32) -> Maps {
    let perlin = Perlin::new(seed);
    let height = move |u: f64, v: f64| {
        let lumps = tiling_noise(&perlin, (u, v), 4.0, 5);
        let cracks = 1.0 - (tiling_noise(&perlin, (v, u), 7.0, 2) - 0.5).abs() * 2.0;
        (lumps - cracks.powf(8.0) * 0.5).clamp(0.0, 1.0)
    };
    let lichen = Perlin::new(seed + 1);
    mapped(
        (256, 256),
        height,
        move |h, u, v| {
            let grey = mix([0.24, 0.23, 0.22], [0.62, 0.6, 0.56], h * 1.3 - 0.2);
            let l = tiling_noise(&lichen, (u, v), 9.0, 3);
            if l > 0.7 {
                mix([0.5, 0.55, 0.3], [0.65, 0.68, 0.4], (l - 0.7) * 3.0)
            } else {
                grey
            }
        },
        10.0,
    )
}

/// The shape of the leaves in a cluster texture.
#[derive(Clone, Copy, Debug)]
pub struct Leaves {
    /// How many leaves (or needle tufts) along the twig.
    pub count: u32,
    /// Length and width of a leaf, in fractions of the texture.
    pub size: (f32, f32),
    /// Colour at a leaf's middle and at its edge (sRGB 0..1).
    pub colours: ([f32; 3], [f32; 3]),
    /// Random seed.
    pub seed: u32,
}

/// A leaf cluster, 128 texels square: leaves on both sides of a twig that runs up the
/// middle, opaque on the leaves and the twig, clear elsewhere (a cut-out card).
pub fn leaf_cluster(leaves: Leaves) -> Vec<u8> {
    let n = 128u32;
    let hash = |i: u32, k: u32| {
        let x = (i.wrapping_mul(0x9E37_79B9) ^ k.wrapping_mul(0x85EB_CA6B) ^ leaves.seed)
            .wrapping_mul(0xC2B2_AE35);
        ((x >> 8) & 0xFFFF) as f32 / 65535.0
    };
    // Each leaf: its base on the twig, its direction, its size, its shade.
    let placed: Vec<(glam::Vec2, glam::Vec2, f32, f32)> = (0..leaves.count)
        .map(|i| {
            let t = (i as f32 + 0.5) / leaves.count as f32;
            let side = if i % 2 == 0 { 1.0 } else { -1.0 };
            let base = glam::Vec2::new(0.5, 0.95 - 0.8 * t);
            let angle = side * (0.6 + 0.5 * hash(i, 1)) - 0.15 * side * t;
            let dir = glam::Vec2::new(angle.sin(), -angle.cos());
            let scale = 0.75 + 0.35 * hash(i, 2) + 0.3 * (1.0 - t);
            (base, dir, scale, hash(i, 3))
        })
        .chain(std::iter::once((
            glam::Vec2::new(0.5, 0.12),
            glam::Vec2::new(0.0, -1.0),
            1.0,
            0.5,
        )))
        .collect();
    let (mid, edge) = leaves.colours;
    png(n, n, |x, y| {
        let p = glam::Vec2::new((x as f32 + 0.5) / n as f32, (y as f32 + 0.5) / n as f32);
        let twig = (p.x - 0.5).abs() < 0.012 && p.y > 0.1;
        let mut texel = [0u8, 0, 0, 0];
        if twig {
            texel = [92, 70, 45, 255];
        }
        for (base, dir, scale, shade) in &placed {
            let (length, width) = (leaves.size.0 * scale, leaves.size.1 * scale);
            let d = p - *base;
            let along = d.dot(*dir) / length;
            let across = d.perp_dot(*dir) / width;
            // A leaf: widest a third of the way out, pointed at the tip.
            let half = (along * (1.0 - along)).max(0.0).sqrt() * 2.0 * (1.15 - 0.4 * along);
            if (0.0..1.0).contains(&along) && across.abs() < half {
                let k = (across.abs() / half.max(1e-3)).powf(1.5);
                let vein = if across.abs() < 0.06 { 0.85 } else { 1.0 };
                let lift = 0.85 + 0.3 * shade;
                let c = [0, 1, 2].map(|i| {
                    let v = (mid[i] + (edge[i] - mid[i]) * k) * lift * vein;
                    (v.clamp(0.0, 1.0) * 255.0) as u8
                });
                texel = [c[0], c[1], c[2], 255];
            }
        }
        texel
    })
}
