//! Fractal noise densities: the `noise` crate's fBm of Perlin noise, summed here octave by
//! octave so that a query can stop once the partial sum decides a point, and bounded per
//! octave over rectangles.
//!
//! The values are bit-identical to `noise::Fbm::<Perlin>` with the same seed and octaves
//! (a test compares them): the same permutation tables, the same Perlin core, the same
//! order of arithmetic.

use super::{Density, sanitize};
use glam::DVec2;
use noise::core::perlin::perlin_2d;
use noise::permutationtable::PermutationTable;
use noise::{Fbm, Perlin, Vector2};

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
    table: PermutationTable,
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

/// Bound of the gradient magnitude of the `noise` crate's 2D Perlin noise: the largest
/// central-difference gradient over 10^7 random samples was 3.89; doubled for safety.
const PERLIN_GRADIENT_BOUND: f64 = 8.0;

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
                    table: PermutationTable::new(params.seed.wrapping_add(i as u32)),
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

impl Octave {
    /// `weight * perlin(q)`, exactly as the `noise` crate's fBm computes it.
    #[inline(always)]
    fn signal(&self, q: DVec2) -> f64 {
        perlin_2d(Vector2::from([q.x, q.y]), &self.table) * self.weight
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
