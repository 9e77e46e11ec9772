//! Fractal noise densities (fBm of Perlin noise from the `noise` crate), with Lipschitz
//! rectangle bounds.

use super::Density;
use glam::DVec2;
use noise::{Fbm, MultiFractal, NoiseFn, Perlin};

/// Fractal noise: `scale * max(0, base + amplitude * fbm(p * frequency))`, with fBm of
/// Perlin noise from the `noise` crate (values in [-1, 1]).
#[derive(Clone, Debug)]
pub struct NoiseDensity {
    fbm: Fbm<Perlin>,
    params: NoiseParams,
    /// Bound of the fBm's gradient per world unit, for rectangle maxima.
    lipschitz: f64,
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

/// Bound of the gradient of the `noise` crate's fBm per unit of its input: the octaves'
/// gradients add up, and the crate rescales the sum into [-1, 1] by `1 / amplitude_sum`.
fn fbm_lipschitz(fbm: &Fbm<Perlin>, octaves: usize) -> f64 {
    let (mut attenuation, mut freq, mut gradient) = (fbm.persistence, 1.0, 0.0);
    let mut amplitude_sum = 0.0;
    for _ in 0..octaves {
        gradient += attenuation * freq;
        amplitude_sum += attenuation;
        attenuation *= fbm.persistence;
        freq *= fbm.lacunarity;
    }
    PERLIN_GRADIENT_BOUND * gradient / amplitude_sum
}

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
        let octaves = params.octaves.clamp(1, 16);
        let fbm = Fbm::<Perlin>::new(params.seed).set_octaves(octaves);
        let lipschitz = fbm_lipschitz(&fbm, octaves) * params.frequency.abs();
        Self {
            fbm,
            params: NoiseParams { octaves, ..params },
            lipschitz,
        }
    }

    /// Its parameters.
    pub fn params(&self) -> NoiseParams {
        self.params
    }

    /// The fBm at `p`: 0 where `p * frequency` is not finite, and wrapped by Perlin noise's
    /// period (256 lattice cells) beyond 2^40 cells, where the `noise` crate would panic
    /// converting coordinates to `isize` (and has no precision left anyway).
    #[inline]
    fn noise(&self, p: DVec2) -> f64 {
        const WRAP: f64 = (1u64 << 40) as f64;
        let mut q = p * self.params.frequency;
        if !q.is_finite() {
            return 0.0;
        }
        if q.abs().max_element() >= WRAP {
            q = DVec2::new(q.x.rem_euclid(256.0), q.y.rem_euclid(256.0));
        }
        self.fbm.get([q.x, q.y])
    }
}

impl Density for NoiseDensity {
    #[inline]
    fn density(&self, p: DVec2) -> f64 {
        self.params.scale * (self.params.base + self.params.amplitude * self.noise(p)).max(0.0)
    }

    fn max_over(&self, min: DVec2, max: DVec2) -> f64 {
        let (_, hi) = self.range_over(min, max);
        self.params.scale * hi.max(0.0)
    }

    fn min_over(&self, min: DVec2, max: DVec2) -> f64 {
        let (lo, _) = self.range_over(min, max);
        // A hair under, for the rounding of the noise crate's own arithmetic.
        self.params.scale * (lo - 1e-9).max(0.0)
    }
}

impl NoiseDensity {
    /// Bounds of `base + amplitude * noise` over the rectangle, before clamping and
    /// scaling: the noise at the centre plus or minus its Lipschitz reach, within [-1, 1].
    fn range_over(&self, min: DVec2, max: DVec2) -> (f64, f64) {
        let centre = (min + max) * 0.5;
        let reach = (max - min).length() * 0.5 * self.lipschitz;
        let at_centre = self.noise(centre);
        let a = self.params.base + self.params.amplitude * (at_centre + reach).min(1.0);
        let b = self.params.base + self.params.amplitude * (at_centre - reach).max(-1.0);
        (a.min(b), a.max(b))
    }
}
