//! Tone: how much ink dots of a given density lay down, and how far a stipple's tone is from
//! its image's.

use super::raster::Grey;
use crate::density::Constant;
use crate::query::{QueryError, Rect, Sampler};
use glam::DVec2;
use std::f64::consts::PI;

/// Ink coverage of the sampler's blue-noise dots of one radius as a function of their
/// *nominal* coverage `a = density * pi * radius^2` (the coverage if dots never overlapped),
/// measured by rendering a uniform patch (the densest level's dots, drawn in the order they
/// appear, read after each level). Dots overlap more as they crowd, so coverage falls below
/// `a`; the stippler inverts this to reach each darkness.
#[derive(Clone, Debug, PartialEq)]
pub struct CoverageCurve {
    /// Nominal coverage between samples.
    step: f64,
    /// Measured coverage at `k * step` (non-decreasing: each level adds dots to the last).
    coverage: Vec<f64>,
}

/// Patches of this many radii a side are measured (fewer where the raster would be large).
const PATCH_RADII: f64 = 160.0;
/// Largest patch raster side in pixels.
const PATCH_PIXELS: f64 = 1024.0;

/// The dots a [`CoverageCurve`] is measured for, and how large its patches may be.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Patch {
    /// Dot radius, world units.
    pub radius: f64,
    /// Raster pixels per world unit (as the stipple is rendered).
    pub scale: f64,
    /// Largest patch side, world units: the image's longer side (a patch larger than the
    /// image measures nothing the image can show; small images calibrate in microseconds).
    pub extent: f64,
}

impl CoverageCurve {
    /// Measures the curve for nominal coverages `0..=max_nominal` in `samples` steps, with
    /// dots of `patch.radius` rendered at `patch.scale` raster pixels per unit (as the
    /// stipple is), on square patches of 160 radii, at most 1024 raster pixels and at most
    /// `patch.extent` a side.
    pub fn measure(
        sampler: &Sampler,
        patch: Patch,
        max_nominal: f64,
        samples: usize,
    ) -> Result<Self, QueryError> {
        let Patch { radius, scale, .. } = patch;
        let side = (PATCH_RADII * radius)
            .min(PATCH_PIXELS / scale)
            .min(patch.extent);
        let margin = 2.0 * radius;
        let pixels = (side * scale).round().max(1.0) as usize;
        let samples = samples.max(1);
        let step = max_nominal / samples as f64;
        let density = |k: usize| k as f64 * step / (PI * radius * radius);
        // The point set only grows with the density: the densest level's points, taken in
        // the order they appear, are every level's. Each dot is drawn once, and the ink is
        // read after each level's dots.
        let rect = Rect::new(DVec2::splat(-margin), DVec2::splat(side + margin))?;
        let mut points = Vec::new();
        sampler.query(rect, &Constant(density(samples)), &mut points)?;
        points.sort_by(|a, b| a.threshold.total_cmp(&b.threshold));
        let mut raster = Grey::filled(pixels, pixels, 0.0);
        let mut coverage = vec![0.0];
        let mut drawn = points.iter().peekable();
        for k in 1..=samples {
            while let Some(p) = drawn.next_if(|p| p.threshold < density(k)) {
                raster.dot(p.position * scale, radius * scale);
            }
            coverage.push(raster.mean());
        }
        Ok(Self { step, coverage })
    }

    /// The coverage of dots of nominal coverage `a`.
    pub fn coverage(&self, a: f64) -> f64 {
        let x = (a / self.step).clamp(0.0, (self.coverage.len() - 1) as f64);
        let k = (x as usize).min(self.coverage.len() - 2);
        let t = x - k as f64;
        self.coverage[k] * (1.0 - t) + self.coverage[k + 1] * t
    }

    /// The nominal coverage that lays down `coverage` of ink; the largest measured one when
    /// no measured density reaches it.
    pub fn nominal(&self, coverage: f64) -> f64 {
        let c = &self.coverage;
        match c.iter().position(|&v| v >= coverage) {
            Some(0) => 0.0,
            Some(k) => {
                let (lo, hi) = (c[k - 1], c[k]);
                let t = if hi > lo {
                    (coverage - lo) / (hi - lo)
                } else {
                    1.0
                };
                (k as f64 - 1.0 + t) * self.step
            }
            None => (c.len() - 1) as f64 * self.step,
        }
    }

    /// The darkest coverage the curve reaches.
    pub fn max_coverage(&self) -> f64 {
        *self.coverage.last().unwrap_or(&0.0)
    }
}

/// How far a rendered stipple's tone is from its target, both blurred alike.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ToneError {
    /// Mean absolute difference of the blurred rasters (0..1).
    pub mean_abs: f64,
    /// Peak signal-to-noise ratio of the blurred stipple against the blurred target, in dB.
    pub psnr: f64,
}

impl ToneError {
    /// Compares two rasters of the same size after blurring both by `sigma` pixels.
    pub fn between(stipple: &Grey, target: &Grey, sigma: f64) -> Self {
        Self::of_blurred(&stipple.blurred(sigma), &target.blurred(sigma))
    }

    /// Compares two rasters of the same size, both already blurred.
    pub(super) fn of_blurred(a: &Grey, b: &Grey) -> Self {
        let n = a.values.len().max(1) as f64;
        let (mut abs, mut sq) = (0.0, 0.0);
        for (x, y) in a.values.iter().zip(&b.values) {
            let d = (*x - *y) as f64;
            abs += d.abs();
            sq += d * d;
        }
        let mse = (sq / n).max(1e-12);
        Self {
            mean_abs: abs / n,
            psnr: -10.0 * mse.log10(),
        }
    }
}
