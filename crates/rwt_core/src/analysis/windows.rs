//! Square windows over a rectangle of points, for averaged spectra and the minimum distance.

use super::{Spectrum, rho};
use glam::DVec2;

/// Most points of one analysis window: a window's periodogram costs its points times the
/// spectrum's size squared, so larger sets are analysed in windows of about this many
/// points (memory and time stay bounded however many points there are).
pub const MAX_WINDOW_POINTS: f64 = 20_000.0;

/// A spectrum's side over the frequencies it must reach in cycles per window: twice blue
/// noise's principal peak (`2 x 1.2 sqrt(n)`), on both sides of zero.
const SPECTRUM_PEAK_ROOM: f64 = 4.8;

/// Most windows per axis of [`WindowGrid::for_spectrum`].
const MAX_SPECTRUM_WINDOWS: usize = 8;

/// Up to 4 x 4 square windows laid from a rectangle's lower corner, each with at least
/// about 500 of its points and at most about [`MAX_WINDOW_POINTS`]: what an analysis of the
/// rectangle's points averages over.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WindowGrid {
    /// The rectangle's lower corner, the first window's origin.
    pub origin: DVec2,
    /// Windows per axis.
    pub per_axis: usize,
    /// Distance between window origins.
    pub cell: f64,
    /// Side of each window (at most `cell`).
    pub side: f64,
    /// Points per unit area over the whole rectangle.
    pub density: f64,
}

/// Why points cannot be laid in windows.
#[derive(Clone, Copy, Debug, PartialEq, thiserror::Error)]
pub enum WindowError {
    /// Fewer points than an analysis needs.
    #[error("{count} points, need at least {needed}")]
    TooFew {
        /// Points given.
        count: usize,
        /// Points needed.
        needed: usize,
    },
    /// The rectangle has no area, or one whose density or windows `f64` cannot hold (the
    /// figures would be NaN or infinite).
    #[error(
        "points span {width:e} x {height:e}: no area an analysis can measure (every point \
         on a line or one spot, or spread past what f64 densities hold)"
    )]
    Extent {
        /// Width of the rectangle.
        width: f64,
        /// Height of the rectangle.
        height: f64,
    },
}

impl WindowGrid {
    /// The windows for `count` points over `min..max`: an error when the rectangle has no
    /// area or no points, or when its density, cell or window side is not a normal number.
    pub fn new(min: DVec2, max: DVec2, count: usize) -> Result<Self, WindowError> {
        if count == 0 {
            return Err(WindowError::TooFew { count, needed: 1 });
        }
        let extent = max - min;
        let square = extent.min_element();
        let per_axis = ((count as f64 / 500.0).sqrt().floor() as usize).clamp(1, 4);
        let cell = square / per_axis as f64;
        let density = count as f64 / (extent.x * extent.y);
        let side = cell.min((MAX_WINDOW_POINTS / density).sqrt());
        // A window's coordinates relative to its origin must resolve its points, too.
        let resolvable = side > 1e-9 * min.abs().max(max.abs()).max_element();
        if !(square > 0.0 && [cell, density, side].iter().all(|v| v.is_normal()) && resolvable) {
            return Err(WindowError::Extent {
                width: extent.x,
                height: extent.y,
            });
        }
        Ok(Self {
            origin: min,
            per_axis,
            cell,
            side,
            density,
        })
    }

    /// Windows for a periodogram of `size x size` frequencies over `count` points on
    /// `min..max`: each holds at most about `(size / 4.8)^2` points, so that its
    /// frequencies (up to `size / 2` cycles per window) reach twice the principal peak of
    /// blue noise (about `1.2 sqrt(n)` cycles per window of `n` points), and up to 8 x 8 of
    /// them spread over the rectangle average the spectrum. Errors as [`WindowGrid::new`].
    pub fn for_spectrum(
        min: DVec2,
        max: DVec2,
        count: usize,
        size: usize,
    ) -> Result<Self, WindowError> {
        let grid = Self::new(min, max, count)?;
        let most = (size as f64 / SPECTRUM_PEAK_ROOM).powi(2).max(1.0);
        let side = (most / grid.density).sqrt();
        if side >= grid.side {
            return Ok(grid);
        }
        let square = (max - min).min_element();
        let per_axis = ((square / side).ceil() as usize).clamp(1, MAX_SPECTRUM_WINDOWS);
        let cell = square / per_axis as f64;
        Ok(Self {
            per_axis,
            cell,
            side: side.min(cell),
            ..grid
        })
    }

    /// The window holding `p` (row-major from the origin), if any.
    pub fn window_of(&self, p: DVec2) -> Option<usize> {
        let k = ((p - self.origin) / self.cell).floor();
        if !(k.x >= 0.0 && k.y >= 0.0) {
            return None;
        }
        let (i, j) = (k.x as usize, k.y as usize);
        if i >= self.per_axis || j >= self.per_axis {
            return None;
        }
        let o = self.origin + DVec2::new(i as f64, j as f64) * self.cell;
        (p.x < o.x + self.side && p.y < o.y + self.side).then_some(j * self.per_axis + i)
    }

    /// Every window's origin, with the points of `points` that fall in it.
    pub fn split(&self, points: impl IntoIterator<Item = DVec2>) -> Vec<(DVec2, Vec<DVec2>)> {
        let n = self.per_axis;
        let mut windows: Vec<(DVec2, Vec<DVec2>)> = (0..n * n)
            .map(|k| {
                let at = DVec2::new((k % n) as f64, (k / n) as f64);
                (self.origin + at * self.cell, Vec::new())
            })
            .collect();
        for p in points {
            if let Some(k) = self.window_of(p) {
                windows[k].1.push(p);
            }
        }
        windows
    }
}

/// The blue-noise figures of one point set, over the windows of a [`WindowGrid`].
#[derive(Clone, Debug)]
pub struct WindowAnalysis {
    /// The smallest normalized minimum distance of any window (each at its own density);
    /// NaN when no window holds two points.
    pub rho: f64,
    /// The averaged periodogram and its radial statistics.
    pub spectrum: Spectrum,
    /// The window side the spectrum's frequencies are in units of (`1 / side`).
    pub side: f64,
}

impl WindowAnalysis {
    /// Analyses `windows` of side `side` with a `size x size` periodogram.
    pub fn of(windows: &[(DVec2, Vec<DVec2>)], side: f64, size: usize) -> Self {
        let rho = windows
            .iter()
            .filter_map(|(_, p)| rho(p, p.len() as f64 / (side * side)))
            .reduce(f64::min)
            .unwrap_or(f64::NAN);
        Self {
            rho,
            spectrum: Spectrum::averaged(windows, side, size),
            side,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn windows_hold_only_their_own_points() {
        let grid = WindowGrid::new(DVec2::ZERO, DVec2::new(20.0, 10.0), 8_000).unwrap();
        assert_eq!(grid.per_axis, 4);
        assert_eq!(grid.cell, 2.5);
        let points = (0..200).map(|i| DVec2::splat(i as f64 * 0.05));
        let windows = grid.split(points);
        assert_eq!(windows.len(), 16);
        for (origin, pts) in &windows {
            for p in pts {
                assert!(
                    p.x >= origin.x && p.x < origin.x + grid.side,
                    "{p} {origin}"
                );
                assert!(
                    p.y >= origin.y && p.y < origin.y + grid.side,
                    "{p} {origin}"
                );
            }
        }
        // The diagonal runs through the windows i == j only.
        let used: Vec<usize> = (0..16).filter(|&k| !windows[k].1.is_empty()).collect();
        assert_eq!(used, vec![0, 5, 10, 15]);
        assert_eq!(grid.window_of(DVec2::new(-0.1, 1.0)), None);
        assert_eq!(grid.window_of(DVec2::new(10.0, 1.0)), None);
        assert!(WindowGrid::new(DVec2::ZERO, DVec2::new(0.0, 1.0), 10).is_err());
        // Extents whose density or window f64 cannot hold (NaN, inf and -1756 dB before).
        for (lo, hi) in [
            (DVec2::ZERO, DVec2::splat(1e-300)),
            (DVec2::splat(-1e300), DVec2::splat(1e300)),
            (DVec2::splat(1e15), DVec2::splat(1e15 + 1e-3)),
        ] {
            assert!(
                matches!(
                    WindowGrid::new(lo, hi, 100),
                    Err(WindowError::Extent { .. })
                ),
                "{lo} {hi}"
            );
        }
    }

    #[test]
    fn spectral_windows_hold_what_their_frequencies_resolve() {
        let (min, max) = (DVec2::ZERO, DVec2::splat(100.0));
        // 100 000 points: windows of at most (128 / 4.8)^2 = 711 points, 8 x 8 of them.
        let grid = WindowGrid::for_spectrum(min, max, 100_000, 128).unwrap();
        assert_eq!(grid.per_axis, 8);
        assert!(grid.side * grid.side * grid.density <= 712.0, "{grid:?}");
        assert!(grid.side <= grid.cell);
        // Few points: the analysis windows as they are.
        let few = WindowGrid::for_spectrum(min, max, 600, 128).unwrap();
        assert_eq!(few, WindowGrid::new(min, max, 600).unwrap());
    }
}
