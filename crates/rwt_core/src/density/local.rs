//! Local models of a density: over a small rectangle a smooth density is a plane plus a
//! bounded curvature, which decides most of a query's points with a few multiplications
//! where evaluating the density would cost far more.

use glam::DVec2;

/// A density near `centre`, within a rectangle the density gave it for: everywhere in that
/// rectangle the density lies within `[max(0, m - e), max(0, m + e)]`, where
/// `m = value + gradient . d`, `e = curvature * |d|^2 + margin` and `d = p - centre`.
///
/// The bounds hold for the density as computed in floating point (the margin covers the
/// rounding), so a query may decide a point by them and still return exactly the points
/// evaluating the density would.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LocalModel {
    /// Where the plane is taken.
    pub centre: DVec2,
    /// The plane's value at the centre.
    pub value: f64,
    /// The plane's slope, per world unit.
    pub gradient: DVec2,
    /// How far the density can bend away from the plane, per squared distance from the
    /// centre (half the largest curvature).
    pub curvature: f64,
    /// Room for rounding, in density units.
    pub margin: f64,
}

impl LocalModel {
    /// Bounds of the density at `p` (inside the model's rectangle).
    #[inline]
    pub fn bounds_at(&self, p: DVec2) -> (f64, f64) {
        let d = p - self.centre;
        let plane = self.value + self.gradient.dot(d);
        let bend = self.curvature * d.length_squared() + self.margin;
        ((plane - bend).max(0.0), (plane + bend).max(0.0))
    }

    /// Bounds of the density over the rectangle `[min, max]` (inside the model's own): the
    /// plane's extremes at the corners, the bend at the corner farthest from the centre.
    pub fn bounds_over(&self, min: DVec2, max: DVec2) -> (f64, f64) {
        let (a, b) = (min - self.centre, max - self.centre);
        let (ga, gb) = (self.gradient * a, self.gradient * b);
        let low = self.value + ga.min(gb).element_sum();
        let high = self.value + ga.max(gb).element_sum();
        let far = a.abs().max(b.abs()).length_squared();
        let bend = self.curvature * far + self.margin;
        ((low - bend).max(0.0), (high + bend).max(0.0))
    }

    /// Whether the density at `p` times `factor` exceeds `threshold`, when the bounds
    /// decide it (`factor > 0`); `None` when only evaluating the density can tell.
    #[inline]
    pub fn decides(&self, p: DVec2, factor: f64, threshold: f64) -> Option<bool> {
        let (low, high) = self.bounds_at(p);
        if low * factor > threshold {
            Some(true)
        } else if high * factor <= threshold {
            Some(false)
        } else {
            None
        }
    }

    /// The model of the density times `factor` (finite and not negative).
    pub fn scaled(&self, factor: f64) -> Self {
        Self {
            centre: self.centre,
            value: self.value * factor,
            gradient: self.gradient * factor,
            curvature: self.curvature * factor,
            // Scaling rounds once more, well inside a margin far above rounding.
            margin: self.margin * factor,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn model() -> LocalModel {
        LocalModel {
            centre: DVec2::new(1.0, 2.0),
            value: 10.0,
            gradient: DVec2::new(2.0, -1.0),
            curvature: 0.5,
            margin: 1e-6,
        }
    }

    #[test]
    fn bounds_over_a_rectangle_hold_the_bounds_at_its_points() {
        let m = model();
        let (min, max) = (DVec2::new(0.5, 1.0), DVec2::new(2.0, 2.5));
        let (low, high) = m.bounds_over(min, max);
        for i in 0..=20 {
            for j in 0..=20 {
                let p = min + (max - min) * DVec2::new(i as f64, j as f64) / 20.0;
                let (l, h) = m.bounds_at(p);
                assert!(low <= l && h <= high, "{p}: {l}..{h} outside {low}..{high}");
            }
        }
        // The corner (2.0, 1.0) reaches the plane's highest value, 10 + 2 + 1.
        assert!((high - (13.0 + 0.5 * (1.0 + 1.0) + 1e-6)).abs() < 1e-12);
    }

    #[test]
    fn decisions_follow_the_bounds_and_leave_the_band_open() {
        let m = model();
        let p = DVec2::new(1.5, 2.0); // plane 11, bend 0.125
        assert_eq!(m.decides(p, 2.0, 21.0), Some(true));
        assert_eq!(m.decides(p, 2.0, 23.0), Some(false));
        assert_eq!(m.decides(p, 2.0, 22.0), None);
        // Below zero the density is zero: nothing exceeds a threshold of 0.
        let low = LocalModel { value: -5.0, ..m };
        assert_eq!(low.decides(m.centre, 1.0, 0.0), Some(false));
    }
}
