//! Every number of a layer file checked at load against what it is used as: sizes and
//! distances that bound loops and allocations, densities, mesh dimensions, colours. A file
//! that would stream nothing, stream without end or draw garbage is refused, naming the
//! field, instead of loading as a silent blank or a default.

use super::{
    AssetDescription, ClassDescription, DensityDescription, InstancedShadingDescription,
    InvalidLayer, LayerDescription, MapDescription, MaterialDescription, MeshDescription,
};

/// Tile sizes a layer may have: within them every subdivision level of a tile has a finite,
/// normal area (beyond them queries refuse the tile size).
pub const TILE_SIZES: (f64, f64) = (1e-9, 1e12);

/// Chunk sizes a layer may have.
pub const CHUNK_SIZES: (f64, f64) = (1e-6, 1e9);

/// The largest dimension of a mesh a layer file describes.
pub const MAX_MESH_SIZE: f32 = 1e6;

/// Most noise octaves (as `rwt points --density noise:...` takes).
pub const MAX_OCTAVES: usize = 16;

/// A number as an error shows it, to 6 significant digits: `1e300`, not its 301 digits,
/// and `0.1` for an `f32` 0.1.
pub fn short(v: f64) -> String {
    let trim = |digits: &str| {
        if digits.contains('.') {
            digits
                .trim_end_matches('0')
                .trim_end_matches('.')
                .to_string()
        } else {
            digits.to_string()
        }
    };
    if !v.is_finite() {
        format!("{v}")
    } else if v != 0.0 && !(1e-4..1e6).contains(&v.abs()) {
        let text = format!("{v:.5e}");
        let (mantissa, exponent) = text.split_once('e').unwrap_or((&text, "0"));
        format!("{}e{exponent}", trim(mantissa))
    } else {
        let places = 5usize.saturating_sub(v.abs().log10().floor().max(0.0) as usize);
        trim(&format!("{v:.places$}"))
    }
}

/// Where a number must lie.
#[derive(Clone, Copy)]
enum Rule {
    /// Finite.
    Finite,
    /// Finite and at least 0.
    NonNegative,
    /// Finite and above 0, at most this.
    Positive(f64),
    /// Finite, in `lo..=hi`.
    Between(f64, f64),
}

impl Rule {
    fn holds(self, v: f64) -> bool {
        v.is_finite()
            && match self {
                Rule::Finite => true,
                Rule::NonNegative => v >= 0.0,
                Rule::Positive(max) => v > 0.0 && v <= max,
                Rule::Between(lo, hi) => (lo..=hi).contains(&v),
            }
    }

    fn words(self) -> String {
        match self {
            Rule::Finite => "finite".into(),
            Rule::NonNegative => "finite and at least 0".into(),
            Rule::Positive(f64::MAX) => "positive and finite".into(),
            Rule::Positive(max) => format!("positive and at most {}", short(max)),
            Rule::Between(lo, f64::MAX) => format!("finite and at least {}", short(lo)),
            Rule::Between(lo, hi) => format!("between {} and {}", short(lo), short(hi)),
        }
    }
}

/// The numbers of a file, each with its field's name and its rule.
#[derive(Default)]
struct Numbers(Vec<(String, f64, Rule)>);

impl Numbers {
    fn add(&mut self, field: impl Into<String>, value: impl Into<f64>, rule: Rule) {
        self.0.push((field.into(), value.into(), rule));
    }

    fn first_broken(self) -> Result<(), InvalidLayer> {
        match self.0.into_iter().find(|(_, v, rule)| !rule.holds(*v)) {
            Some((field, value, rule)) => Err(InvalidLayer::Number {
                field,
                value,
                rule: rule.words(),
            }),
            None => Ok(()),
        }
    }
}

/// Checks every number of `d` (the streaming distances are checked with their own errors).
pub(super) fn check(d: &LayerDescription) -> Result<(), InvalidLayer> {
    let mut n = Numbers::default();
    n.add(
        "tile_size",
        d.tile_size,
        Rule::Between(TILE_SIZES.0, TILE_SIZES.1),
    );
    if let Some(c) = d.chunk_size {
        n.add("chunk_size", c, Rule::Between(CHUNK_SIZES.0, CHUNK_SIZES.1));
    }
    if let Some(v) = d.near_distance {
        n.add("near_distance", v, Rule::NonNegative);
    }
    if let Some((near, far)) = d.falloff {
        n.add("falloff start", near, Rule::NonNegative);
        n.add("falloff end", far, Rule::Between(near.max(0.0), f64::MAX));
    }
    n.add("falloff_floor", d.falloff_floor, Rule::Between(0.0, 1.0));
    n.add("height", d.height, Rule::Finite);
    if let Some((lo, hi)) = d.height_range {
        n.add("height_range low", lo, Rule::Finite);
        n.add("height_range high", hi, Rule::Between(lo as f64, f64::MAX));
    }
    if let Some(s) = d.max_slope {
        // Rise over run.
        n.add("max_slope", s, Rule::NonNegative);
    }
    if let Some(e) = &d.exclusion {
        density(&mut n, "exclusion", e);
    }
    for k in &d.keep_out {
        for (i, r) in k.radii.iter().enumerate() {
            n.add(
                format!("keep_out {}: radius {i}", k.layer),
                *r,
                Rule::NonNegative,
            );
        }
    }
    for (i, c) in d.classes.iter().enumerate() {
        class(&mut n, &format!("class {i}"), c);
    }
    n.first_broken()
}

fn class(n: &mut Numbers, at: &str, c: &ClassDescription) {
    density(n, at, &c.density);
    if let Some(m) = &c.mesh {
        mesh(n, at, m);
    }
    if let Some(m) = &c.material {
        material(n, at, m);
    }
    if let Some(a) = &c.asset {
        asset(n, at, a);
    }
    n.add(
        format!("{at}: scale"),
        c.scale,
        Rule::Positive(MAX_MESH_SIZE as f64),
    );
    n.add(
        format!("{at}: scale_variation"),
        c.scale_variation,
        Rule::Between(0.0, 1.0),
    );
    n.add(format!("{at}: stance align"), c.stance.align, Rule::Finite);
    n.add(format!("{at}: stance sink"), c.stance.sink, Rule::Finite);
    if let Some(lod) = &c.lod {
        mesh(n, &format!("{at}: lod"), &lod.mesh);
        material(n, &format!("{at}: lod"), &lod.material);
        if let Some(f) = lod.crossfade {
            n.add(format!("{at}: lod crossfade"), f, Rule::NonNegative);
        }
    }
    if let Some(p) = &c.promotion {
        n.add(
            format!("{at}: promotion distance"),
            p.distance,
            Rule::NonNegative,
        );
    }
    if let Some(i) = &c.impostor {
        n.add(
            format!("{at}: impostor distance"),
            i.distance,
            Rule::NonNegative,
        );
        n.add(
            format!("{at}: impostor crossfade"),
            i.crossfade,
            Rule::NonNegative,
        );
    }
    if let Some((lo, hi)) = c.pick_bounds {
        for (axis, v) in lo.to_array().into_iter().chain(hi.to_array()).enumerate() {
            n.add(format!("{at}: pick_bounds {axis}"), v, Rule::Finite);
        }
    }
}

fn density(n: &mut Numbers, at: &str, d: &DensityDescription) {
    match d {
        DensityDescription::Constant(v) => n.add(format!("{at}: density"), *v, Rule::NonNegative),
        DensityDescription::Noise(p) => {
            n.add(
                format!("{at}: noise frequency"),
                p.frequency,
                Rule::Positive(f64::MAX),
            );
            n.add(
                format!("{at}: noise octaves"),
                p.octaves as f64,
                Rule::Between(1.0, MAX_OCTAVES as f64),
            );
            n.add(format!("{at}: noise base"), p.base, Rule::Finite);
            n.add(format!("{at}: noise amplitude"), p.amplitude, Rule::Finite);
            n.add(format!("{at}: noise scale"), p.scale, Rule::NonNegative);
        }
        DensityDescription::Image(m) => map(n, at, m),
        // Checked by `Clumps::new`.
        DensityDescription::Clumps(_) => {}
    }
}

fn map(n: &mut Numbers, at: &str, m: &MapDescription) {
    n.add(format!("{at}: map min x"), m.min.0, Rule::Finite);
    n.add(format!("{at}: map min y"), m.min.1, Rule::Finite);
    n.add(
        format!("{at}: map size x"),
        m.size.0,
        Rule::Positive(f32::MAX as f64),
    );
    n.add(
        format!("{at}: map size y"),
        m.size.1,
        Rule::Positive(f32::MAX as f64),
    );
    n.add(format!("{at}: map scale"), m.scale, Rule::NonNegative);
}

fn mesh(n: &mut Numbers, at: &str, m: &MeshDescription) {
    let size = Rule::Positive(MAX_MESH_SIZE as f64);
    let mut dim = |name: &str, v: f32| n.add(format!("{at}: mesh {name}"), v, size);
    match m {
        MeshDescription::Path(_) | MeshDescription::Named(_) => {}
        MeshDescription::Sphere { radius } => dim("radius", *radius),
        MeshDescription::Cone { radius, height } => {
            dim("radius", *radius);
            dim("height", *height);
        }
        MeshDescription::Cuboid { size } => {
            dim("size x", size.0);
            dim("size y", size.1);
            dim("size z", size.2);
        }
        MeshDescription::Blade {
            width,
            height,
            bend,
        } => {
            dim("width", *width);
            dim("height", *height);
            n.add(format!("{at}: mesh bend"), *bend, Rule::Finite);
        }
    }
}

fn material(n: &mut Numbers, at: &str, m: &MaterialDescription) {
    match m {
        MaterialDescription::Path(_) | MaterialDescription::Named(_) => {}
        MaterialDescription::Color(r, g, b) => colour(n, &format!("{at}: colour"), (*r, *g, *b)),
        MaterialDescription::Instanced(s) => shading(n, at, s),
    }
}

fn shading(n: &mut Numbers, at: &str, s: &InstancedShadingDescription) {
    colour(n, &format!("{at}: base"), s.base);
    colour(n, &format!("{at}: tip"), s.tip);
    for (name, v) in [
        ("color_variation", s.color_variation),
        ("roughness", s.roughness),
        ("wind_response", s.wind_response),
        ("fade_band", s.fade_band),
        ("tip_from", s.tip_from),
        ("bend_response", s.bend_response),
        ("alpha_cutoff", s.alpha_cutoff),
    ] {
        n.add(format!("{at}: {name}"), v, Rule::Finite);
    }
    if let crate::look::InstancedShadows::Within(d) = s.shadows {
        n.add(format!("{at}: shadows within"), d, Rule::NonNegative);
    }
}

fn asset(n: &mut Numbers, at: &str, a: &AssetDescription) {
    for (i, d) in a.lods.iter().enumerate() {
        n.add(format!("{at}: asset lod {i}"), *d, Rule::Positive(f64::MAX));
    }
    n.add(
        format!("{at}: asset crossfade"),
        a.crossfade,
        Rule::Between(0.0, 1.0),
    );
    for (name, v) in [
        ("color_variation", a.color_variation),
        ("wind_response", a.wind_response),
        ("bend_response", a.bend_response),
        ("fade_band", a.fade_band),
    ] {
        n.add(format!("{at}: asset {name}"), v, Rule::Finite);
    }
    if let crate::look::InstancedShadows::Within(d) = a.shadows {
        n.add(format!("{at}: asset shadows within"), d, Rule::NonNegative);
    }
}

fn colour(n: &mut Numbers, at: &str, (r, g, b): (f32, f32, f32)) {
    for v in [r, g, b] {
        n.add(at, v, Rule::NonNegative);
    }
}
