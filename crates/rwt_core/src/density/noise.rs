//! Fractal noise densities: the `noise` crate's fBm of Perlin noise, summed here octave by
//! octave so that a query can stop once the partial sum decides a point, and bounded per
//! octave over rectangles.
//!
//! The values are bit-identical to `noise::Fbm::<Perlin>` with the same seed and octaves
//! (a test compares them): the same permutation tables, the same Perlin core, the same
//! order of arithmetic. The core is the crate's `perlin_2d` written out with the table's
//! lookups inlined (the crate hashes through a slice), which halves its cost.

use super::{Density, LocalModel, Patch, sanitize};
use glam::DVec2;
use noise::permutationtable::{NoiseHasher, PermutationTable};
use noise::{Fbm, Perlin};

/// Fractal noise: `scale * max(0, base + amplitude * fbm(p * frequency))`, with fBm of
/// Perlin noise from the `noise` crate (values in [-1, 1]).
///
/// With `bevy_reflect`, an opaque value: its tables are derived from its [`NoiseParams`].
#[derive(Clone, Debug)]
#[cfg_attr(
    feature = "bevy_reflect",
    derive(bevy_reflect::Reflect),
    reflect(opaque, Clone, Debug)
)]
pub struct NoiseDensity {
    octaves: Box<[Octave]>,
    /// The `noise` crate's `1 / sum of weights`, which rescales the sum into [-1, 1].
    normalise: f64,
    params: NoiseParams,
    /// Whether every parameter is finite, so that the value is monotone in the fBm and a
    /// partial sum may decide a point.
    finite: bool,
}

/// One octave of the sum: its permutation table, its weight and what its bounds need.
#[derive(Clone, Copy, Debug)]
struct Octave {
    /// The `noise` crate's permutation table for the octave's seed.
    table: [u8; 256],
    /// The octave's signal is `weight * perlin` (so within `[-weight, weight]`).
    weight: f64,
    /// Sum of the weights of the octaves after this one: how far they can move the sum.
    rest: f64,
    /// Bound of the signal's gradient per world unit.
    slope: f64,
}

/// The fBm sum (before normalising) near a rectangle's centre: a plane and a bend per
/// squared distance, give or take `slack` for the rounding of the inputs.
struct FbmModel {
    centre: DVec2,
    value: f64,
    gradient: DVec2,
    curvature: f64,
    slack: f64,
}

/// The parameters of a [`NoiseDensity`], as plain (serializable) data.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[cfg_attr(feature = "bevy_reflect", derive(bevy_reflect::Reflect))]
pub struct NoiseParams {
    /// Noise seed.
    pub seed: u32,
    /// Cycles per world unit.
    pub frequency: f64,
    /// Octaves (1..=16).
    pub octaves: usize,
    /// Offset of the noise value.
    pub base: f64,
    /// Gain of the noise value.
    pub amplitude: f64,
    /// Points per unit area at value 1.
    pub scale: f64,
}

/// Bound of the gradient magnitude of the `noise` crate's 2D Perlin noise: proven 4.08 by
/// `the_perlin_gradient_bound_holds_everywhere` (every corner-gradient combination on a
/// grid, plus the gradient's own Lipschitz bound between grid points; the grid's largest is
/// 3.89).
const PERLIN_GRADIENT_BOUND: f64 = 4.25;

/// Bound of the curvature (the Hessian's largest eigenvalue in magnitude) of the `noise`
/// crate's 2D Perlin noise before its clamp: proven 19.0 by
/// `the_perlin_curvature_bounds_hold_everywhere` (the grid's largest is 17.8).
const PERLIN_CURVATURE_BOUND: f64 = 19.5;

/// The `noise` crate's fBm defaults (frequency 1): each octave's weight is the previous one's
/// times the persistence, and its input the previous one's times the lacunarity.
const PERSISTENCE: f64 = Fbm::<Perlin>::DEFAULT_PERSISTENCE;
const LACUNARITY: f64 = Fbm::<Perlin>::DEFAULT_LACUNARITY;

/// Beyond `2^40` lattice cells the `noise` crate would panic converting coordinates to
/// `isize` (and has no precision left anyway): inputs are wrapped by Perlin noise's period.
const WRAP: f64 = (1u64 << 40) as f64;

/// Far more than the rounding of summing at most 16 octaves of values within [-1, 1]: the
/// margin that keeps partial-sum decisions and rectangle bounds on the safe side.
const ROUNDING_MARGIN: f64 = 1e-9;

impl Default for NoiseParams {
    /// Seed 0, one cycle per world unit, 4 octaves, values `0.5 + 0.5 * fbm` (0 to 1), one
    /// point per unit area at value 1: override what you need with struct update syntax,
    /// `NoiseParams { frequency: 0.02, scale: 40.0, ..NoiseParams::default() }`.
    fn default() -> Self {
        Self {
            seed: 0,
            frequency: 1.0,
            octaves: 4,
            base: 0.5,
            amplitude: 0.5,
            scale: 1.0,
        }
    }
}

impl From<NoiseParams> for NoiseDensity {
    fn from(params: NoiseParams) -> Self {
        Self::new(params)
    }
}

impl NoiseDensity {
    /// The fBm density described by `params` (octaves clamped to 1..=16).
    pub fn new(params: NoiseParams) -> Self {
        let count = params.octaves.clamp(1, 16);
        let params = NoiseParams {
            octaves: count,
            ..params
        };
        // The noise crate's weights and normalisation, computed in its order.
        let mut weights = Vec::with_capacity(count);
        let mut weight = PERSISTENCE;
        for _ in 0..count {
            weights.push(weight);
            weight *= PERSISTENCE;
        }
        let normalise = 1.0 / (1..=count).fold(0.0, |sum, i| sum + PERSISTENCE.powi(i as i32));
        let mut input_gain = params.frequency.abs();
        let octaves = weights
            .iter()
            .enumerate()
            .map(|(i, &weight)| {
                let octave = Octave {
                    // The crate seeds octave i with `seed + i`; wrapping, as its release
                    // builds do, instead of overflowing for seeds near the maximum.
                    table: permutation(params.seed.wrapping_add(i as u32)),
                    weight,
                    rest: weights[i + 1..].iter().sum(),
                    slope: PERLIN_GRADIENT_BOUND * weight * input_gain,
                };
                input_gain *= LACUNARITY;
                octave
            })
            .collect();
        let finite = [
            params.frequency,
            params.base,
            params.amplitude,
            params.scale,
        ]
        .iter()
        .all(|v| v.is_finite());
        Self {
            octaves,
            normalise,
            params,
            finite,
        }
    }

    /// Its parameters.
    pub fn params(&self) -> NoiseParams {
        self.params
    }

    /// The noise input of world point `p`, wrapped beyond [`WRAP`]; `None` where it is not
    /// finite (the fBm counts as 0 there).
    #[inline]
    fn input(&self, p: DVec2) -> Option<DVec2> {
        let q = p * self.params.frequency;
        if !q.is_finite() {
            return None;
        }
        if q.abs().max_element() >= WRAP {
            return Some(DVec2::new(q.x.rem_euclid(256.0), q.y.rem_euclid(256.0)));
        }
        Some(q)
    }

    /// The fBm at world point `p`, in [-1, 1].
    #[inline]
    fn fbm(&self, p: DVec2) -> f64 {
        let Some(mut q) = self.input(p) else {
            return 0.0;
        };
        let mut sum = 0.0;
        for octave in self.octaves.iter() {
            sum += octave.signal(q);
            q *= LACUNARITY;
        }
        sum * self.normalise
    }

    /// The density for fBm value `f`.
    #[inline]
    fn value(&self, f: f64) -> f64 {
        let p = &self.params;
        p.scale * (p.base + p.amplitude * f).max(0.0)
    }

    /// The smallest and largest density for fBm values in `[lo, hi]` (the value is monotone
    /// in the fBm, rising or falling with the sign of the amplitude and the scale).
    #[inline]
    fn value_range(&self, lo: f64, hi: f64) -> (f64, f64) {
        let (a, b) = (self.value(lo), self.value(hi));
        (a.min(b), a.max(b))
    }

    /// Bounds of the fBm over the rectangle, octave by octave: each octave's value at the
    /// centre plus or minus its gradient's reach, within its own range; an octave whose reach
    /// spans its whole range is not evaluated.
    fn fbm_range(&self, min: DVec2, max: DVec2) -> (f64, f64) {
        let radius = (max - min).length() * 0.5;
        let whole = (-1.0, 1.0);
        let centre = (min + max) * 0.5;
        let (Some(mut q), true) = (self.input(centre), self.within_wrap(min, max)) else {
            return whole;
        };
        let (mut lo, mut hi) = (0.0, 0.0);
        for octave in self.octaves.iter() {
            let w = octave.weight;
            let reach = octave.slope * radius;
            if reach < 2.0 * w {
                let v = octave.signal(q);
                lo += (v - reach).max(-w);
                hi += (v + reach).min(w);
            } else if reach.is_nan() {
                return whole;
            } else {
                lo -= w;
                hi += w;
            }
            q *= LACUNARITY;
        }
        let lo = ((lo - ROUNDING_MARGIN) * self.normalise).max(-1.0);
        let hi = ((hi + ROUNDING_MARGIN) * self.normalise).min(1.0);
        (lo, hi)
    }

    /// The fBm as a plane at the rectangle's centre plus a bounded bend, octave by octave:
    /// each octave's value and gradient at the centre, its curvature bound scaled by its
    /// weight and its frequency squared. Where an octave's clamp to [-1, 1] may act inside
    /// the patch (the bounds are for the noise before it), what the clamp can take off
    /// widens the slack. Curvature and clamp are bounded over the lattice cells the patch
    /// itself may touch, not all those of its rectangle. `None` where inputs wrap.
    fn fbm_model(&self, patch: &Patch) -> Option<FbmModel> {
        let (min, max) = (patch.min, patch.max);
        let centre = (min + max) * 0.5;
        let radius = patch.farthest_squared(centre).sqrt();
        let mut q = self.input(centre)?;
        if !self.within_wrap(min, max) {
            return None;
        }
        let far = min.abs().max(max.abs()).length();
        let half = (max - min) * 0.5;
        let (mut value, mut gradient, mut curvature, mut slack) = (0.0, DVec2::ZERO, 0.0, 0.0);
        let mut gain = self.params.frequency;
        let mut shape = patch.scaled(gain);
        for (k, octave) in self.octaves.iter().enumerate() {
            // A point's input is rounded once per product that made it (frequency, then
            // the lacunarity per octave): the noise can move by its slope times that.
            let rounding = (k + 2) as f64 * f64::EPSILON * far * gain.abs();
            slack += octave.weight * PERLIN_GRADIENT_BOUND * rounding;
            let (v, g) = perlin_plane(&octave.table, q.x, q.y);
            // The octave's reach within the rectangle, in its own input units.
            let r = radius * gain.abs();
            let reach = half * gain.abs() * (1.0 + ROUNDING_MARGIN) + ROUNDING_MARGIN;
            let touches = |lo, hi| shape.may_meet(lo, hi, rounding + ROUNDING_MARGIN);
            let (cells_curvature, clamp_free) =
                lattice_bounds(&octave.table, q - reach, q + reach, touches);
            if !clamp_free {
                // The clamp takes off at most how far the noise can pass 1 in magnitude.
                let peak = v.abs() + g.length() * r + 0.5 * cells_curvature * r * r;
                slack += octave.weight * (peak - 1.0 + ROUNDING_MARGIN).max(0.0);
            }
            value += octave.weight * v;
            gradient += g * (octave.weight * gain);
            curvature += 0.5 * cells_curvature * octave.weight * gain * gain;
            q *= LACUNARITY;
            gain *= LACUNARITY;
            shape = shape.scaled(LACUNARITY);
        }
        Some(FbmModel {
            centre,
            value,
            gradient,
            curvature,
            slack,
        })
    }

    /// Whether the whole rectangle lies where inputs are not wrapped (where the gradient
    /// bound holds between any two of its points).
    fn within_wrap(&self, min: DVec2, max: DVec2) -> bool {
        let f = self.params.frequency.abs();
        (min.abs().max(max.abs()) * f).max_element() < WRAP
    }
}

/// The `noise` crate's permutation table for `seed`, read through its hasher (a one-word
/// hash is the table entry).
fn permutation(seed: u32) -> [u8; 256] {
    let table = PermutationTable::new(seed);
    std::array::from_fn(|i| table.hash(&[i as isize]) as u8)
}

/// The `noise` crate's lattice corner below `v`: truncation, minus one at or below zero.
#[inline(always)]
fn lattice_corner(v: f64) -> isize {
    if v <= 0.0 { v as isize - 1 } else { v as isize }
}

/// Which of the four gradients `(+-1, +-1)` the `noise` crate's table picks at lattice
/// point `(x, y)`: 0 `(1, 1)`, 1 `(-1, 1)`, 2 `(1, -1)`, 3 `(-1, -1)`.
#[inline(always)]
fn gradient_pick(table: &[u8; 256], x: isize, y: isize) -> u8 {
    let first = table[(x & 0xff) as usize] as usize;
    table[first ^ (y & 0xff) as usize] & 0b11
}

/// The `noise` crate's `perlin_2d` (0.9), operation for operation: its lattice corner
/// (truncation, minus one at or below zero), its gradients `(+-1, +-1)` picked by the
/// table, its quintic curve, its interpolation `b * t + a * (1 - t)` (first along y), its
/// scale and clamp.
#[inline(always)]
fn perlin(table: &[u8; 256], x: f64, y: f64) -> f64 {
    const SCALE_FACTOR: f64 = 2.0 / std::f64::consts::SQRT_2;
    let (cx, cy) = (lattice_corner(x), lattice_corner(y));
    let (dx, dy) = (x - cx as f64, y - cy as f64);
    let gradient = |ox: isize, oy: isize| {
        let (px, py) = (dx - ox as f64, dy - oy as f64);
        match gradient_pick(table, cx + ox, cy + oy) {
            0 => px + py,
            1 => -px + py,
            2 => px - py,
            _ => -px - py,
        }
    };
    let quintic = |v: f64| {
        let v = v.clamp(0.0, 1.0);
        v * v * v * (v * (v * 6.0 - 15.0) + 10.0)
    };
    let (sx, sy) = (quintic(dx), quintic(dy));
    let linear = |a: f64, b: f64, t: f64| b * t + a * (1.0 - t);
    let (g00, g10, g01, g11) = (
        gradient(0, 0),
        gradient(1, 0),
        gradient(0, 1),
        gradient(1, 1),
    );
    let result = linear(linear(g00, g01, sy), linear(g10, g11, sy), sx) * SCALE_FACTOR;
    result.clamp(-1.0, 1.0)
}

/// The corner-gradient combinations (each corner's two bits, corners (0, 0), (1, 0), (0, 1),
/// (1, 1) from the lowest bits up) whose lattice cell the `noise` crate's Perlin noise never
/// leaves [-1, 1] on before its clamp: proven by `clamp_free_cells_stay_within_one`.
const CLAMP_FREE: [u64; 4] = [
    0xf5ff_ffff_31f7_f7ff,
    0xffff_efef_f7ff_f7ff,
    0xffef_ffef_f7f7_ffff,
    0xffef_ef8c_ffff_ffaf,
];

/// Each corner-gradient combination's curvature bound on its lattice cell, in tenths (the
/// noise before its clamp; at most [`PERLIN_CURVATURE_BOUND`]): proven by
/// `the_perlin_curvature_bounds_hold_everywhere`.
#[rustfmt::skip]
const CELL_CURVATURE: [u8; 256] = [
    95, 119, 119, 141, 139, 119, 158, 142, 139, 141, 119, 146, 166, 142, 150, 141,
    139, 119, 141, 146, 176, 139, 185, 174, 174, 146, 146, 119, 185, 141, 161, 146,
    139, 158, 119, 142, 174, 142, 142, 121, 176, 185, 139, 174, 185, 146, 158, 142,
    166, 150, 142, 141, 185, 158, 146, 142, 185, 161, 141, 146, 191, 159, 159, 141,
    119, 119, 119, 159, 119, 119, 150, 158, 158, 159, 150, 161, 150, 119, 119, 150,
    119, 119, 142, 141, 139, 95, 166, 139, 142, 141, 141, 146, 158, 119, 150, 119,
    141, 159, 142, 146, 146, 141, 141, 142, 185, 191, 166, 185, 161, 159, 150, 158,
    142, 119, 102, 142, 141, 119, 142, 119, 146, 159, 142, 141, 159, 119, 119, 119,
    119, 119, 119, 159, 141, 142, 159, 146, 119, 142, 119, 141, 142, 102, 119, 142,
    158, 150, 159, 161, 185, 166, 191, 185, 142, 141, 141, 146, 146, 142, 159, 141,
    119, 150, 119, 158, 146, 141, 141, 142, 139, 166, 95, 139, 141, 142, 119, 119,
    150, 119, 119, 150, 161, 150, 159, 158, 158, 150, 119, 119, 159, 119, 119, 119,
    141, 159, 159, 191, 146, 141, 161, 185, 142, 146, 158, 185, 141, 142, 150, 166,
    142, 158, 146, 185, 174, 139, 185, 176, 121, 142, 142, 174, 142, 119, 158, 139,
    146, 161, 141, 185, 119, 146, 146, 174, 174, 185, 139, 176, 146, 141, 119, 139,
    141, 150, 142, 166, 146, 119, 141, 139, 142, 158, 119, 139, 141, 119, 119, 95,
];

/// Most lattice cells per axis [`lattice_bounds`] looks at.
const LATTICE_SPAN: isize = 3;

/// The corner-gradient combination of the lattice cell at `(cx, cy)`, as `perlin` picks it.
fn corner_combination(table: &[u8; 256], cx: isize, cy: isize) -> usize {
    let pick = |ox: isize, oy: isize| {
        gradient_pick(table, cx.wrapping_add(ox), cy.wrapping_add(oy)) as usize
    };
    pick(0, 0) | pick(1, 0) << 2 | pick(0, 1) << 4 | pick(1, 1) << 6
}

/// Over the lattice cells the input rectangle `[min, max]` touches and `touches` keeps (it
/// is given each cell's corners): the largest curvature bound of the noise before its
/// clamp, and whether it stays within [-1, 1] there (so that the clamp never acts); the
/// global bounds where the rectangle spans many cells.
fn lattice_bounds(
    table: &[u8; 256],
    min: DVec2,
    max: DVec2,
    touches: impl Fn(DVec2, DVec2) -> bool,
) -> (f64, bool) {
    let (x0, y0) = (min.x.floor() as isize, min.y.floor() as isize);
    let (x1, y1) = (max.x.floor() as isize, max.y.floor() as isize);
    // Apart by the distance, not the difference: infinite corners saturate to isize::MIN
    // and MAX, whose difference overflows.
    let span = LATTICE_SPAN as usize;
    if x1.abs_diff(x0) >= span || y1.abs_diff(y0) >= span {
        return (PERLIN_CURVATURE_BOUND, false);
    }
    let (mut tenths, mut free) = (0, true);
    for cy in y0..=y1 {
        for cx in x0..=x1 {
            let corner = DVec2::new(cx as f64, cy as f64);
            if !touches(corner, corner + 1.0) {
                continue;
            }
            let combo = corner_combination(table, cx, cy);
            tenths = tenths.max(CELL_CURVATURE[combo]);
            free &= CLAMP_FREE[combo / 64] >> (combo % 64) & 1 == 1;
        }
    }
    (f64::from(tenths) / 10.0, free)
}

/// The `noise` crate's `perlin_2d` before its clamp, and its gradient, at `(x, y)`: the
/// interpolation of the corner gradients' planes by the quintic curve, differentiated.
fn perlin_plane(table: &[u8; 256], x: f64, y: f64) -> (f64, DVec2) {
    const SCALE_FACTOR: f64 = 2.0 / std::f64::consts::SQRT_2;
    let (cx, cy) = (lattice_corner(x), lattice_corner(y));
    let (dx, dy) = (x - cx as f64, y - cy as f64);
    // Each corner's gradient (+-1, +-1) and its plane's value at (dx, dy).
    let plane = |ox: isize, oy: isize| {
        let g = match gradient_pick(table, cx + ox, cy + oy) {
            0 => DVec2::new(1.0, 1.0),
            1 => DVec2::new(-1.0, 1.0),
            2 => DVec2::new(1.0, -1.0),
            _ => DVec2::new(-1.0, -1.0),
        };
        (g.dot(DVec2::new(dx - ox as f64, dy - oy as f64)), g)
    };
    let quintic = |t: f64| {
        let t = t.clamp(0.0, 1.0);
        (
            t * t * t * (t * (t * 6.0 - 15.0) + 10.0),
            30.0 * t * t * (t - 1.0) * (t - 1.0),
        )
    };
    let ((sx, dsx), (sy, dsy)) = (quintic(dx), quintic(dy));
    let ((v00, g00), (v10, g10), (v01, g01), (v11, g11)) =
        (plane(0, 0), plane(1, 0), plane(0, 1), plane(1, 1));
    // Along y first, as the crate interpolates: a on the x = 0 side, b on the x = 1 side.
    let a = v00 + (v01 - v00) * sy;
    let b = v10 + (v11 - v10) * sy;
    let da = g00 + (g01 - g00) * sy + DVec2::new(0.0, (v01 - v00) * dsy);
    let db = g10 + (g11 - g10) * sy + DVec2::new(0.0, (v11 - v10) * dsy);
    let value = a + (b - a) * sx;
    let gradient = da + (db - da) * sx + DVec2::new((b - a) * dsx, 0.0);
    (value * SCALE_FACTOR, gradient * SCALE_FACTOR)
}

impl Octave {
    /// `weight * perlin(q)`, exactly as the `noise` crate's fBm computes it.
    #[inline(always)]
    fn signal(&self, q: DVec2) -> f64 {
        perlin(&self.table, q.x, q.y) * self.weight
    }
}

impl Density for NoiseDensity {
    #[inline]
    fn density(&self, p: DVec2) -> f64 {
        self.value(self.fbm(p))
    }

    fn max_over(&self, min: DVec2, max: DVec2) -> f64 {
        let (lo, hi) = self.fbm_range(min, max);
        self.value_range(lo, hi).1
    }

    fn min_over(&self, min: DVec2, max: DVec2) -> f64 {
        let (lo, hi) = self.fbm_range(min, max);
        self.value_range(lo, hi).0
    }

    /// The fBm's plane and bend mapped through `scale * (base + amplitude * fbm)`, which is
    /// affine in the fBm: `None` for a negative or non-finite scale (its clamp at zero
    /// would not be the model's).
    fn local_model(&self, patch: &Patch) -> Option<LocalModel> {
        let p = &self.params;
        if !self.finite || p.scale < 0.0 {
            return None;
        }
        let fbm = self.fbm_model(patch)?;
        let gain = p.scale * p.amplitude * self.normalise;
        Some(LocalModel {
            centre: fbm.centre,
            value: p.scale * p.base + gain * fbm.value,
            gradient: fbm.gradient * gain,
            curvature: fbm.curvature * gain.abs(),
            margin: gain.abs() * fbm.slack
                + ROUNDING_MARGIN * p.scale * (p.base.abs() + p.amplitude.abs() + 1.0),
        })
    }

    /// The whole sum: near the threshold the partial sums' checks would only cost.
    #[inline]
    fn exceeds_near(&self, p: DVec2, factor: f64, threshold: f64) -> bool {
        sanitize(self.density(p)) * factor > threshold
    }

    /// Sums the octaves until the partial sum, give or take what the remaining octaves can
    /// add, decides the point on one side of the threshold; the last octave decides exactly
    /// as [`Density::density`] would.
    #[inline]
    fn exceeds(&self, p: DVec2, factor: f64, threshold: f64) -> bool {
        let decide = |f: f64| sanitize(self.value(f)) * factor > threshold;
        let Some(mut q) = self.input(p) else {
            return decide(0.0);
        };
        let early = self.finite && factor > 0.0 && threshold.is_finite();
        let Some((last, head)) = self.octaves.split_last() else {
            return decide(0.0);
        };
        let mut sum = 0.0;
        for octave in head {
            sum += octave.signal(q);
            q *= LACUNARITY;
            if early {
                let lo = (sum - octave.rest - ROUNDING_MARGIN) * self.normalise;
                let hi = (sum + octave.rest + ROUNDING_MARGIN) * self.normalise;
                let (low, high) = self.value_range(lo, hi);
                if sanitize(low) * factor > threshold {
                    return true;
                }
                if sanitize(high) * factor <= threshold {
                    return false;
                }
            }
        }
        sum += last.signal(q);
        decide(sum * self.normalise)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The quintic curve's value, slope and curvature at `t`.
    fn quintic(t: f64) -> (f64, f64, f64) {
        (
            t * t * t * (t * (t * 6.0 - 15.0) + 10.0),
            30.0 * t * t * (t - 1.0) * (t - 1.0),
            60.0 * t * (2.0 * t * t - 3.0 * t + 1.0),
        )
    }

    /// Gradient of the `noise` crate's 2D Perlin noise on one lattice cell at `(x, y)` in
    /// `[0, 1]^2`, for corner gradients `grads` (g00, g10, g01, g11; entries +-1, as
    /// `perlin_2d` picks them), from the crate's formula
    /// `S * lerp(lerp(g00, g01, sy), lerp(g10, g11, sy), sx)`.
    fn perlin_gradient(grads: [(f64, f64); 4], x: f64, y: f64) -> f64 {
        let corner = [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)];
        let g = |k: usize| grads[k].0 * (x - corner[k].0) + grads[k].1 * (y - corner[k].1);
        let ((sx, dsx, _), (sy, dsy, _)) = (quintic(x), quintic(y));
        let (a, b) = (g(0) * (1.0 - sy) + g(2) * sy, g(1) * (1.0 - sy) + g(3) * sy);
        let lerp = |u: f64, v: f64, t: f64| u * (1.0 - t) + v * t;
        let (dax, dbx) = (
            lerp(grads[0].0, grads[2].0, sy),
            lerp(grads[1].0, grads[3].0, sy),
        );
        let day = lerp(grads[0].1, grads[2].1, sy) + dsy * (g(2) - g(0));
        let dby = lerp(grads[1].1, grads[3].1, sy) + dsy * (g(3) - g(1));
        let dx = lerp(dax, dbx, sx) + dsx * (b - a);
        let dy = lerp(day, dby, sx);
        std::f64::consts::SQRT_2 * (dx * dx + dy * dy).sqrt()
    }

    /// The corner gradients of combination `combo` (two bits per corner, as
    /// [`corner_combination`] packs them).
    fn gradients(combo: usize) -> [(f64, f64); 4] {
        let signs = [(1.0, 1.0), (-1.0, 1.0), (1.0, -1.0), (-1.0, -1.0)];
        [0, 1, 2, 3].map(|k| signs[(combo >> (2 * k)) & 3])
    }

    /// The noise before its clamp on one lattice cell, and its Hessian's entries
    /// `(xx, xy, yy)`, from the crate's formula differentiated twice.
    fn perlin_curvature(grads: [(f64, f64); 4], x: f64, y: f64) -> (f64, [f64; 3]) {
        let corner = [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)];
        let g = |k: usize| grads[k].0 * (x - corner[k].0) + grads[k].1 * (y - corner[k].1);
        let ((sx, dsx, ddsx), (sy, dsy, ddsy)) = (quintic(x), quintic(y));
        // p on the x = 0 side (corners 0 and 2), q on the x = 1 side (corners 1 and 3).
        let side = |a: usize, b: usize| {
            let v = (1.0 - sy) * g(a) + sy * g(b);
            let vx = (1.0 - sy) * grads[a].0 + sy * grads[b].0;
            let vy = dsy * (g(b) - g(a)) + (1.0 - sy) * grads[a].1 + sy * grads[b].1;
            let vxy = dsy * (grads[b].0 - grads[a].0);
            let vyy = ddsy * (g(b) - g(a)) + 2.0 * dsy * (grads[b].1 - grads[a].1);
            (v, vx, vy, vxy, vyy)
        };
        let ((p, px, py, pxy, pyy), (q, qx, qy, qxy, qyy)) = (side(0, 2), side(1, 3));
        let s = std::f64::consts::SQRT_2;
        let value = s * ((1.0 - sx) * p + sx * q);
        let xx = ddsx * (q - p) + 2.0 * dsx * (qx - px);
        let xy = dsx * (qy - py) + (1.0 - sx) * pxy + sx * qxy;
        let yy = (1.0 - sx) * pyy + sx * qyy;
        (value, [s * xx, s * xy, s * yy])
    }

    /// A proof of [`CELL_CURVATURE`] and [`PERLIN_CURVATURE_BOUND`]: each combination of
    /// corner gradients' largest Hessian eigenvalue magnitude on a grid of spacing `h`,
    /// plus what it can gain between grid points (the third derivatives bound its change).
    #[test]
    fn the_perlin_curvature_bounds_hold_everywhere() {
        let steps = 400;
        let h = 1.0 / steps as f64;
        // Third derivatives from |g| <= 2, |g'| <= 1, the quintic's slope <= 1.875,
        // curvature <= 5.78 and third derivative <= 60: xxx and yyy below 60 * 4 + 3 * 5.78
        // * 2, xxy and xyy below 126.3; the Hessian's change per unit step is below the
        // Frobenius norm of those gradients, times S.
        let (outer, mixed): (f64, f64) = (274.7, 126.3);
        let diagonal = outer.hypot(mixed);
        let change = std::f64::consts::SQRT_2
            * (2.0 * diagonal * diagonal + 2.0 * mixed.hypot(mixed).powi(2)).sqrt();
        let between = change * h * std::f64::consts::FRAC_1_SQRT_2;
        let mut largest: f64 = 0.0;
        for (combo, &tenths) in CELL_CURVATURE.iter().enumerate() {
            let mut cell: f64 = 0.0;
            for i in 0..=steps {
                for j in 0..=steps {
                    let (_, [a, b, c]) =
                        perlin_curvature(gradients(combo), i as f64 * h, j as f64 * h);
                    let norm = ((a + c) * 0.5).abs() + (((a - c) * 0.5).powi(2) + b * b).sqrt();
                    cell = cell.max(norm);
                }
            }
            let proven = cell + between;
            assert!(
                proven <= f64::from(tenths) / 10.0,
                "combination {combo}: {proven}"
            );
            largest = largest.max(proven);
        }
        eprintln!("largest proven curvature {largest:.4}");
        assert!(largest <= PERLIN_CURVATURE_BOUND, "{largest}");
        assert!(f64::from(*CELL_CURVATURE.iter().max().unwrap()) / 10.0 <= PERLIN_CURVATURE_BOUND);
    }

    /// A proof of [`CLAMP_FREE`]: on every cell marked free, the noise's largest magnitude
    /// on a grid plus what the gradient bound lets it gain between grid points stays below 1.
    /// Most combinations are free, or local models would rarely exist.
    #[test]
    fn clamp_free_cells_stay_within_one() {
        let steps = 400;
        let h = 1.0 / steps as f64;
        let mut free = 0;
        for combo in 0..256 {
            if CLAMP_FREE[combo / 64] >> (combo % 64) & 1 == 0 {
                continue;
            }
            free += 1;
            let mut largest: f64 = 0.0;
            for i in 0..=steps {
                for j in 0..=steps {
                    let (v, _) = perlin_curvature(gradients(combo), i as f64 * h, j as f64 * h);
                    largest = largest.max(v.abs());
                }
            }
            let proven = largest + PERLIN_GRADIENT_BOUND * h * std::f64::consts::FRAC_1_SQRT_2;
            assert!(proven < 1.0, "combination {combo}: {proven}");
        }
        assert!(free >= 200, "{free}");
    }

    /// The plane and gradient of the noise are the crate's value before its clamp and its
    /// derivative (against central differences), on lattice cells of either sign.
    #[test]
    fn perlin_planes_are_the_noise_and_its_slope() {
        let table = permutation(9);
        let mut rng = crate::rng::Rng::new(9, 3);
        let step = 1e-6;
        for _ in 0..2_000 {
            let (x, y) = ((rng.next_f64() - 0.5) * 40.0, (rng.next_f64() - 0.5) * 40.0);
            let (v, g) = perlin_plane(&table, x, y);
            let clamped = perlin(&table, x, y);
            assert!((v.clamp(-1.0, 1.0) - clamped).abs() < 1e-12, "{x}, {y}");
            let dx = (perlin_plane(&table, x + step, y).0 - perlin_plane(&table, x - step, y).0)
                / (2.0 * step);
            let dy = (perlin_plane(&table, x, y + step).0 - perlin_plane(&table, x, y - step).0)
                / (2.0 * step);
            assert!(
                (g - DVec2::new(dx, dy)).length() < 1e-5,
                "{x}, {y}: {g} vs {dx}, {dy}"
            );
        }
    }

    /// A proof of [`PERLIN_GRADIENT_BOUND`]: the gradient's largest magnitude over every
    /// combination of corner gradients, on a grid of spacing `h`, plus what it can gain
    /// between grid points (its own Lipschitz bound times the distance to the nearest one).
    #[test]
    fn the_perlin_gradient_bound_holds_everywhere() {
        let steps = 400;
        let h = 1.0 / steps as f64;
        let mut largest: f64 = 0.0;
        for combo in 0..256 {
            let grads = gradients(combo);
            for i in 0..=steps {
                for j in 0..=steps {
                    largest = largest.max(perlin_gradient(grads, i as f64 * h, j as f64 * h));
                }
            }
        }
        // Second derivatives of S * lerp(..): |g| <= 2, |g' | <= 1 per axis, the quintic's
        // slope <= 1.875 and curvature <= 5.78; each entry below S * (2 * 1.875 * 2 * 2 + 5.78 * 4),
        // the Hessian's norm below twice that.
        let hessian = 2.0 * std::f64::consts::SQRT_2 * (2.0 * 1.875 * 2.0 * 2.0 + 5.78 * 4.0);
        let proven = largest + hessian * h * std::f64::consts::FRAC_1_SQRT_2;
        eprintln!("largest gradient on the grid {largest:.4}, proven bound {proven:.4}");
        assert!(proven <= PERLIN_GRADIENT_BOUND, "{proven}");
    }
}
