//! Fractal noise densities: the `noise` crate's fBm of Perlin noise, summed here octave by
//! octave so that a query can stop once the partial sum decides a point, and bounded per
//! octave over rectangles.
//!
//! The values are bit-identical to `noise::Fbm::<Perlin>` with the same seed and octaves
//! (a test compares them): the same permutation tables, the same Perlin core, the same
//! order of arithmetic. The core is the crate's `perlin_2d` written out with the table's
//! lookups inlined (the crate hashes through a slice), which halves its cost.

use super::{Density, sanitize};
use glam::DVec2;
use noise::permutationtable::{NoiseHasher, PermutationTable};
use noise::{Fbm, Perlin};

/// Fractal noise: `scale * max(0, base + amplitude * fbm(p * frequency))`, with fBm of
/// Perlin noise from the `noise` crate (values in [-1, 1]).
#[derive(Clone, Debug)]
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

/// The parameters of a [`NoiseDensity`], as plain (serializable) data.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
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

/// The `noise` crate's `perlin_2d` (0.9), operation for operation: its lattice corner
/// (truncation, minus one at or below zero), its gradients `(+-1, +-1)` picked by the
/// table, its quintic curve, its interpolation `b * t + a * (1 - t)` (first along y), its
/// scale and clamp.
#[inline(always)]
fn perlin(table: &[u8; 256], x: f64, y: f64) -> f64 {
    const SCALE_FACTOR: f64 = 2.0 / std::f64::consts::SQRT_2;
    let corner = |v: f64| if v <= 0.0 { v as isize - 1 } else { v as isize };
    let (cx, cy) = (corner(x), corner(y));
    let (dx, dy) = (x - cx as f64, y - cy as f64);
    let gradient = |ox: isize, oy: isize| {
        let (px, py) = (dx - ox as f64, dy - oy as f64);
        let first = table[((cx + ox) & 0xff) as usize] as usize;
        match table[first ^ ((cy + oy) & 0xff) as usize] & 0b11 {
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

    /// A proof of [`PERLIN_GRADIENT_BOUND`]: the gradient's largest magnitude over every
    /// combination of corner gradients, on a grid of spacing `h`, plus what it can gain
    /// between grid points (its own Lipschitz bound times the distance to the nearest one).
    #[test]
    fn the_perlin_gradient_bound_holds_everywhere() {
        let steps = 400;
        let h = 1.0 / steps as f64;
        let signs = [(1.0, 1.0), (-1.0, 1.0), (1.0, -1.0), (-1.0, -1.0)];
        let mut largest: f64 = 0.0;
        for combo in 0..256 {
            let grads = [0, 1, 2, 3].map(|k| signs[(combo >> (2 * k)) & 3]);
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
