//! Averaged periodograms and their radial statistics.

use crate::geometry::hex_spacing;
use glam::DVec2;

/// An averaged periodogram of point sets in square windows, with its radial statistics.
///
/// Frequencies are integer multiples of `1 / side`: at those, the window of a constant
/// density has no energy, so the DC term does not leak and white noise reads 1 everywhere.
#[derive(Clone, Debug)]
pub struct Spectrum {
    /// Frequencies per axis (`size x size`, zero at `size / 2`).
    pub size: usize,
    /// Power, row-major, `v` rows of `u`; 1 is the level of white noise.
    pub power: Vec<f64>,
    /// Mean power of each annulus `[r, r + 1)` (in units of `1 / side`).
    pub radial_mean: Vec<f64>,
    /// Anisotropy of each annulus, `10 log10(variance / mean^2)` in dB. Averaging `m`
    /// periodograms puts isotropic noise at about `-10 log10(m)`; spikes stand out above.
    pub anisotropy_db: Vec<f64>,
    /// Number of periodograms averaged.
    pub windows: usize,
}

impl Spectrum {
    /// Averages the periodograms of point sets, each in its own square window
    /// `[origin, origin + side)` (points outside are ignored).
    pub fn averaged(windows: &[(DVec2, Vec<DVec2>)], side: f64, size: usize) -> Spectrum {
        let size = size.max(4) & !1;
        let half = size / 2;
        let mut power = vec![0.0f64; size * size];
        let mut used = 0;
        for (origin, pts) in windows {
            let inside: Vec<DVec2> = pts
                .iter()
                .map(|p| (*p - *origin) / side)
                .filter(|q| q.x >= 0.0 && q.y >= 0.0 && q.x < 1.0 && q.y < 1.0)
                .collect();
            if !inside.is_empty() {
                add_periodogram(&mut power, &inside, size);
                used += 1;
            }
        }
        let m = used.max(1) as f64;
        for p in &mut power {
            *p /= m;
        }
        power[half * size + half] = 0.0;
        let (radial_mean, anisotropy_db) = radial_statistics(&power, size);
        Spectrum {
            size,
            power,
            radial_mean,
            anisotropy_db,
            windows: used,
        }
    }

    /// Mean radial power below `fraction` of the principal frequency of `density` points per
    /// unit area (`1 / hex_spacing`), for windows of side `side`: the blue-noise "hole".
    pub fn low_frequency_power(&self, side: f64, density: f64, fraction: f64) -> f64 {
        let cutoff = fraction * side / hex_spacing(density);
        let bins: Vec<f64> = (1..self.radial_mean.len())
            .filter(|&r| (r as f64) < cutoff)
            .map(|r| self.radial_mean[r])
            .collect();
        if bins.is_empty() {
            f64::NAN
        } else {
            bins.iter().sum::<f64>() / bins.len() as f64
        }
    }

    /// Mean anisotropy (dB) over the annuli from `from` to the end, ignoring empty ones.
    pub fn mean_anisotropy(&self, from: usize) -> f64 {
        let v: Vec<f64> = self
            .anisotropy_db
            .iter()
            .skip(from)
            .copied()
            .filter(|x| x.is_finite())
            .collect();
        v.iter().sum::<f64>() / v.len().max(1) as f64
    }

    /// Largest anisotropy (dB) over the annuli from `from` on.
    pub fn max_anisotropy(&self, from: usize) -> f64 {
        self.anisotropy_db
            .iter()
            .skip(from)
            .copied()
            .filter(|x| x.is_finite())
            .fold(f64::NEG_INFINITY, f64::max)
    }
}

/// Adds the periodogram `|sum exp(-2 pi i f.q)|^2 / n` of the points `inside` the unit
/// window to `power` (`size x size` frequencies, `-size/2..size/2` on each axis).
fn add_periodogram(power: &mut [f64], inside: &[DVec2], size: usize) {
    let half = (size / 2) as f64;
    let mut re = vec![0.0f64; size * size];
    let mut im = vec![0.0f64; size * size];
    let mut ex = vec![(0.0f64, 0.0f64); size];
    let mut ey = vec![(0.0f64, 0.0f64); size];
    for q in inside {
        for (axis, table) in [(q.x, &mut ex), (q.y, &mut ey)] {
            // exp(-2 pi i u x) for u = -half..half by rotation from u = -half.
            let step = (-std::f64::consts::TAU * axis).sin_cos();
            let start = (std::f64::consts::TAU * axis * half).sin_cos();
            let (mut c, mut s) = (start.1, start.0);
            for slot in table.iter_mut() {
                *slot = (c, s);
                let (nc, ns) = (c * step.1 - s * step.0, c * step.0 + s * step.1);
                c = nc;
                s = ns;
            }
        }
        for (v, &(cy, sy)) in ey.iter().enumerate() {
            let row = v * size;
            for (u, &(cx, sx)) in ex.iter().enumerate() {
                re[row + u] += cx * cy - sx * sy;
                im[row + u] += cx * sy + sx * cy;
            }
        }
    }
    let n = inside.len() as f64;
    for i in 0..size * size {
        power[i] += (re[i] * re[i] + im[i] * im[i]) / n;
    }
}

/// The mean power per integer radius of a `size x size` spectrum, and its anisotropy
/// (variance over squared mean, in dB; NaN where a ring has fewer than two cells).
fn radial_statistics(power: &[f64], size: usize) -> (Vec<f64>, Vec<f64>) {
    let half = (size / 2) as f64;
    let bins = size / 2;
    let (mut sum, mut sum2, mut count) = (vec![0.0; bins], vec![0.0; bins], vec![0usize; bins]);
    for v in 0..size {
        for u in 0..size {
            let (fu, fv) = (u as f64 - half, v as f64 - half);
            let r = (fu * fu + fv * fv).sqrt() as usize;
            if r == 0 || r >= bins {
                continue;
            }
            let p = power[v * size + u];
            sum[r] += p;
            sum2[r] += p * p;
            count[r] += 1;
        }
    }
    let radial_mean: Vec<f64> = (0..bins)
        .map(|r| {
            if count[r] > 0 {
                sum[r] / count[r] as f64
            } else {
                0.0
            }
        })
        .collect();
    let anisotropy_db = (0..bins)
        .map(|r| {
            if count[r] < 2 || radial_mean[r] <= 0.0 {
                return f64::NAN;
            }
            let mean = radial_mean[r];
            let var = (sum2[r] / count[r] as f64 - mean * mean).max(1e-300);
            10.0 * (var / (mean * mean)).log10()
        })
        .collect();
    (radial_mean, anisotropy_db)
}
