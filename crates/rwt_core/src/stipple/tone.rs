//! Tone: how much ink dots of a given density lay down, and how far a stipple's tone is from
//! its image's.

use super::raster::Grey;
use crate::density::Constant;
use crate::query::{QueryError, Rect, Sampler};
use glam::DVec2;
use std::f64::consts::PI;

/// Ink coverage of the sampler's blue-noise dots of one radius as a function of their
/// *nominal* coverage `a = density * pi * radius^2` (the coverage if dots never overlapped),
/// measured by rendering uniform patches. Dots overlap more as they crowd, so coverage falls
/// below `a`; the stippler inverts this to reach each darkness.
#[derive(Clone, Debug, PartialEq)]
pub struct CoverageCurve {
    /// Nominal coverage between samples.
    step: f64,
    /// Measured coverage at `k * step`, made non-decreasing.
    coverage: Vec<f64>,
}

/// Patches of this many radii a side are measured (fewer where the raster would be large).
const PATCH_RADII: f64 = 160.0;
/// Largest patch raster side in pixels.
const PATCH_PIXELS: f64 = 1024.0;

impl CoverageCurve {
    /// Measures the curve for nominal coverages `0..=max_nominal` in `samples` steps, with
    /// dots of `radius` rendered at `scale` raster pixels per unit (as the stipple is).
    pub fn measure(
        sampler: &Sampler,
        radius: f64,
        scale: f64,
        max_nominal: f64,
        samples: usize,
    ) -> Result<Self, QueryError> {
        let side = (PATCH_RADII * radius).min(PATCH_PIXELS / scale);
        let margin = 2.0 * radius;
        let pixels = (side * scale).round().max(1.0) as usize;
        let step = max_nominal / samples.max(1) as f64;
        let mut coverage = vec![0.0];
        let mut points = Vec::new();
        for k in 1..=samples.max(1) {
            let density = Constant(k as f64 * step / (PI * radius * radius));
            // Each patch elsewhere in the plane, so that they are independent samples.
            let origin = DVec2::new(k as f64 * (side + 4.0 * margin), 0.0);
            let rect = Rect::new(origin - margin, origin + side + margin)?;
            points.clear();
            sampler.query(rect, &density, &mut points)?;
            let mut raster = Grey::filled(pixels, pixels, 0.0);
            for p in &points {
                raster.dot((p.position - origin) * scale, radius * scale);
            }
            let last = *coverage.last().unwrap_or(&0.0);
            coverage.push(raster.mean().max(last));
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
