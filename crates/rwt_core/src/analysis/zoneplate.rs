//! The paper's anti-aliasing test (its figure 9): the zone plate `sin(x^2 + y^2)` rendered
//! with one sample per pixel and a Gaussian reconstruction filter, for several sampling
//! patterns, against the same filter applied to a supersampled signal. The plate's
//! frequency grows with the distance from its centre, to four times the pixels' Nyquist
//! frequency at the middle of its edges: a regular grid turns what it cannot resolve into
//! rings (aliasing, structured, at low frequencies), random patterns into noise. So each
//! pattern's error is measured twice: its low band (a Gaussian blur of the error) where
//! the plate is past Nyquist (aliasing), and its high band (the rest) where every pattern
//! resolves the plate (noise).

use super::reference::{dart_throwing, white_noise};
use crate::density::Constant;
use crate::query::{QueryError, Rect, Sampler};
use crate::rng::{Rng, hash_words, unit_f64};
use glam::DVec2;

/// The sampling patterns the test compares.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Pattern {
    /// rwt's points at one per pixel on average.
    Rwt,
    /// Pixel centres.
    Grid,
    /// One uniform point in each pixel.
    Jitter,
    /// Uniform points (white noise).
    White,
    /// Dart throwing (a Poisson-disk set).
    DartThrowing,
    /// The first two dimensions of Sobol's sequence, Owen-scrambled.
    Sobol,
}

impl Pattern {
    /// Every pattern, rwt first.
    pub const ALL: [Pattern; 6] = [
        Pattern::Rwt,
        Pattern::Grid,
        Pattern::Jitter,
        Pattern::White,
        Pattern::DartThrowing,
        Pattern::Sobol,
    ];

    /// The pattern's name in reports.
    pub fn name(self) -> &'static str {
        match self {
            Pattern::Rwt => "rwt",
            Pattern::Grid => "grid",
            Pattern::Jitter => "jitter",
            Pattern::White => "white",
            Pattern::DartThrowing => "dart",
            Pattern::Sobol => "sobol",
        }
    }
}

/// A zone plate test: the image's size, the filters, and the reference's supersampling.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ZonePlate {
    /// Pixels on a side (the paper: 512).
    pub size: usize,
    /// Standard deviation of the Gaussian reconstruction filter, in pixels.
    pub filter: f64,
    /// Standard deviation of the blur whose output is the low band, in pixels.
    pub band: f64,
    /// Samples per pixel and axis of the reference (stratified).
    pub reference: usize,
    /// The plate's frequency at the middle of its edges, in multiples of the pixels'
    /// Nyquist frequency.
    pub reach: f64,
}

impl Default for ZonePlate {
    fn default() -> Self {
        Self {
            size: 512,
            filter: 0.7,
            band: 4.0,
            reference: 4,
            reach: 4.0,
        }
    }
}

/// How far a pattern's image is from the reference, as PSNR (signal range 2:
/// `10 log10(4 / mean squared error)`, in dB; higher is better).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlateError {
    /// The whole error over the whole image.
    pub psnr: f64,
    /// The error's low band (blurred by `band` pixels) where the plate's frequency is past
    /// the pixels' Nyquist frequency: aliasing, what a grid turns into rings.
    pub low: f64,
    /// The error's high band (the rest) where the plate's frequency is below half the
    /// Nyquist frequency, which every pattern resolves: its noise.
    pub high: f64,
}

impl ZonePlate {
    /// Half the plate's side `h` in signal units: the frequency `r / pi` reaches `reach`
    /// times the Nyquist frequency (`size / 4h` cycles per unit) at the middle of the edges.
    pub fn half_width(&self) -> f64 {
        (self.reach * self.size as f64 * std::f64::consts::PI / 4.0).sqrt()
    }

    /// The signal at `p`, in pixel coordinates (`0..size` on each axis).
    pub fn signal(&self, p: DVec2) -> f64 {
        let h = self.half_width();
        let q = (p / self.size as f64 * 2.0 - DVec2::ONE) * h;
        (q.x * q.x + q.y * q.y).sin()
    }

    /// One sample per pixel of `pattern`, in pixel coordinates; rwt's from `sampler` (its
    /// tile size is chosen here).
    pub fn samples(
        &self,
        pattern: Pattern,
        sampler: &Sampler,
        seed: u64,
    ) -> Result<Vec<DVec2>, QueryError> {
        let n = self.size;
        let side = n as f64;
        let count = n * n;
        Ok(match pattern {
            Pattern::Rwt => {
                // A tile of 64 x 64 pixels holds 4096 points: about 2 N, blue noise.
                let rect = Rect::new(DVec2::ZERO, DVec2::splat(side))?;
                let mut points = Vec::with_capacity(count + count / 8);
                let s = sampler.clone().with_seed(seed).with_tile_size(64.0);
                s.query_with(rect, &Constant(1.0), |p| points.push(p.position))?;
                points
            }
            Pattern::Grid => (0..count)
                .map(|k| DVec2::new((k % n) as f64 + 0.5, (k / n) as f64 + 0.5))
                .collect(),
            Pattern::Jitter => {
                let mut rng = Rng::new(seed, 0x1177);
                (0..count)
                    .map(|k| {
                        let cell = DVec2::new((k % n) as f64, (k / n) as f64);
                        cell + DVec2::new(rng.next_f64(), rng.next_f64())
                    })
                    .collect()
            }
            Pattern::White => white_noise(DVec2::ZERO, side, count, seed),
            Pattern::DartThrowing => dart_throwing(DVec2::ZERO, side, count, seed),
            Pattern::Sobol => (0..count as u32)
                .map(|i| owen_sobol(i, seed) * side)
                .collect(),
        })
    }

    /// The image the Gaussian reconstruction filter makes of the signal at `samples`:
    /// each pixel the filter-weighted mean of the samples within 3 standard deviations.
    pub fn reconstruct(&self, samples: impl IntoIterator<Item = DVec2>) -> Vec<f64> {
        let n = self.size;
        let (mut sum, mut weight) = (vec![0.0; n * n], vec![0.0; n * n]);
        let reach = (3.0 * self.filter).ceil() as i64;
        let k = -0.5 / (self.filter * self.filter);
        for p in samples {
            let v = self.signal(p);
            let (cx, cy) = (p.x.floor() as i64, p.y.floor() as i64);
            for y in (cy - reach).max(0)..=(cy + reach).min(n as i64 - 1) {
                for x in (cx - reach).max(0)..=(cx + reach).min(n as i64 - 1) {
                    let d = DVec2::new(x as f64 + 0.5, y as f64 + 0.5) - p;
                    let w = (k * d.length_squared()).exp();
                    let at = y as usize * n + x as usize;
                    sum[at] += w * v;
                    weight[at] += w;
                }
            }
        }
        sum.iter()
            .zip(&weight)
            .map(|(s, w)| if *w > 0.0 { s / w } else { 0.0 })
            .collect()
    }

    /// The reference: the same filter over a stratified `reference x reference` samples
    /// per pixel.
    pub fn reference_image(&self) -> Vec<f64> {
        let (n, k) = (self.size, self.reference.max(1));
        let step = 1.0 / k as f64;
        let points = (0..n * n * k * k).map(|i| {
            let (pixel, sub) = (i / (k * k), i % (k * k));
            DVec2::new(
                (pixel % n) as f64 + ((sub % k) as f64 + 0.5) * step,
                (pixel / n) as f64 + ((sub / k) as f64 + 0.5) * step,
            )
        });
        self.reconstruct(points)
    }

    /// The plate's frequency at pixel `(x, y)`, in multiples of the Nyquist frequency.
    fn nyquists(&self, x: usize, y: usize) -> f64 {
        let n = self.size as f64;
        let c = DVec2::new(x as f64 + 0.5, y as f64 + 0.5) / n * 2.0 - DVec2::ONE;
        c.length() * self.reach
    }

    /// How far `image` is from `reference`, whole and by band.
    pub fn error(&self, image: &[f64], reference: &[f64]) -> PlateError {
        let n = self.size;
        let error: Vec<f64> = image.iter().zip(reference).map(|(a, b)| a - b).collect();
        let low = blur(&error, n, self.band);
        let region = |keep: &dyn Fn(f64) -> bool, values: &dyn Fn(usize) -> f64| {
            let kept: Vec<f64> = (0..n * n)
                .filter(|&k| keep(self.nyquists(k % n, k / n)))
                .map(values)
                .collect();
            psnr(&kept)
        };
        PlateError {
            psnr: psnr(&error),
            low: region(&|f| f > 1.0, &|k| low[k]),
            high: region(&|f| f < 0.5, &|k| error[k] - low[k]),
        }
    }
}

/// One pattern's image of the plate and its error.
#[derive(Clone, Debug, PartialEq)]
pub struct Rendering {
    /// The pattern.
    pub pattern: Pattern,
    /// The image, `size x size` values in -1..1, row 0 at the bottom.
    pub image: Vec<f64>,
    /// Its error against the reference.
    pub error: PlateError,
}

/// The reference and each pattern's rendering, all from one run.
#[derive(Clone, Debug, PartialEq)]
pub struct Comparison {
    /// The supersampled reference image.
    pub reference: Vec<f64>,
    /// The patterns' renderings, in the order of [`Pattern::ALL`].
    pub renderings: Vec<Rendering>,
}

/// The paper's claim, checked: aliasing removed as jittering removes it (rwt's low band
/// above the grid's and its error within 10 % of jittering's), at a lower noise level
/// (rwt's high band above jittering's).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Claim {
    /// rwt's low band above the grid's and at most 0.41 dB (10 % more squared error) below
    /// jittering's.
    pub aliasing_removed: bool,
    /// rwt's high band above jittering's.
    pub less_noise: bool,
    /// The errors the claim compares.
    pub rwt: PlateError,
    /// The regular grid's.
    pub grid: PlateError,
    /// Jittering's.
    pub jitter: PlateError,
}

impl ZonePlate {
    /// Renders the plate with every pattern and measures each against the reference;
    /// `go_on` is asked before each pattern, and the comparison ends early when it says no.
    pub fn compare(
        &self,
        sampler: &Sampler,
        seed: u64,
        mut go_on: impl FnMut() -> bool,
    ) -> Result<Comparison, QueryError> {
        let reference = self.reference_image();
        let mut renderings = Vec::with_capacity(Pattern::ALL.len());
        for pattern in Pattern::ALL {
            if !go_on() {
                break;
            }
            let image = self.reconstruct(self.samples(pattern, sampler, seed)?);
            let error = self.error(&image, &reference);
            renderings.push(Rendering {
                pattern,
                image,
                error,
            });
        }
        Ok(Comparison {
            reference,
            renderings,
        })
    }
}

impl Comparison {
    /// The error of `pattern`, where it was rendered.
    pub fn error(&self, pattern: Pattern) -> Option<PlateError> {
        self.renderings
            .iter()
            .find(|r| r.pattern == pattern)
            .map(|r| r.error)
    }

    /// The paper's claim, where rwt, the grid and jittering were rendered.
    pub fn claim(&self) -> Option<Claim> {
        let (rwt, grid, jitter) = (
            self.error(Pattern::Rwt)?,
            self.error(Pattern::Grid)?,
            self.error(Pattern::Jitter)?,
        );
        // PSNR in dB: 10 % more squared error is 0.41 dB less.
        Some(Claim {
            aliasing_removed: rwt.low > grid.low && rwt.low >= jitter.low - 0.41,
            less_noise: rwt.high > jitter.high,
            rwt,
            grid,
            jitter,
        })
    }
}

/// `10 log10(4 / mean squared value)`: the PSNR of an error for a signal of range 2.
fn psnr(error: &[f64]) -> f64 {
    let mse = error.iter().map(|e| e * e).sum::<f64>() / error.len().max(1) as f64;
    10.0 * (4.0 / mse).log10()
}

/// `values` (`size x size`) blurred by a Gaussian of `sigma` pixels, separably, with the
/// image's edges repeated.
fn blur(values: &[f64], size: usize, sigma: f64) -> Vec<f64> {
    let reach = (3.0 * sigma).ceil() as i64;
    let kernel: Vec<f64> = (-reach..=reach)
        .map(|d| (-0.5 * (d * d) as f64 / (sigma * sigma)).exp())
        .collect();
    let total: f64 = kernel.iter().sum();
    let pass = |src: &[f64], across: bool| -> Vec<f64> {
        let mut out = vec![0.0; src.len()];
        for y in 0..size {
            for x in 0..size {
                let mut acc = 0.0;
                for (k, w) in kernel.iter().enumerate() {
                    let d = k as i64 - reach;
                    let (sx, sy) = if across {
                        (x as i64 + d, y as i64)
                    } else {
                        (x as i64, y as i64 + d)
                    };
                    let (sx, sy) = (sx.clamp(0, size as i64 - 1), sy.clamp(0, size as i64 - 1));
                    acc += w * src[sy as usize * size + sx as usize];
                }
                out[y * size + x] = acc / total;
            }
        }
        out
    };
    pass(&pass(values, true), false)
}

/// Point `i` of the first two dimensions of Sobol's sequence, Owen-scrambled for `seed`
/// (each bit flipped by a hash of the bits above it), in `[0, 1)^2`.
pub fn owen_sobol(i: u32, seed: u64) -> DVec2 {
    // Dimension 1: the van der Corput sequence; dimension 2: direction numbers of x + 1.
    let (mut x, mut y, mut v) = (0u32, 0u32, 1u32 << 31);
    for bit in 0..32 {
        if i >> bit & 1 == 1 {
            x ^= 1 << (31 - bit);
            y ^= v;
        }
        v ^= v >> 1;
    }
    DVec2::new(
        unit_of(owen(x, hash_words(seed, &[0]))),
        unit_of(owen(y, hash_words(seed, &[1]))),
    )
}

/// `v` Owen-scrambled: bit `b` (from the top) flipped by a hash of the bits above it.
fn owen(v: u32, seed: u64) -> u32 {
    let mut out = v;
    for b in 0..32 {
        let prefix = if b == 0 { 0 } else { v >> (32 - b) };
        let flip = hash_words(seed, &[b as u64, prefix as u64]) & 1;
        out ^= (flip as u32) << (31 - b);
    }
    out
}

/// A 32-bit fraction as a number in `[0, 1)`, with a hashed offset below its last bit.
fn unit_of(v: u32) -> f64 {
    (v as f64 + unit_f64(hash_words(v as u64, &[0x50b0]))) / 4_294_967_296.0
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn owen_sobol_is_a_net_in_every_elementary_box() {
        // 256 points: one in every elementary box of area 1/256 (a (0, 8, 2)-net).
        for seed in [1, 9] {
            let points: Vec<DVec2> = (0..256).map(|i| owen_sobol(i, seed)).collect();
            for k in 0..=8 {
                let (nx, ny) = (1usize << k, 1usize << (8 - k));
                let mut seen = vec![0; 256];
                for p in &points {
                    let (i, j) = ((p.x * nx as f64) as usize, (p.y * ny as f64) as usize);
                    seen[j * nx + i] += 1;
                }
                assert!(
                    seen.iter().all(|&c| c == 1),
                    "seed {seed}, {nx} x {ny} boxes"
                );
            }
        }
        assert_ne!(owen_sobol(5, 1), owen_sobol(5, 2));
    }
}
