//! Local models of a density: over a small patch a smooth density is a plane plus a
//! bounded curvature, which decides most of a query's points with a few multiplications
//! where evaluating the density would cost far more.

use glam::DVec2;

/// Where a query asks a density for a [`LocalModel`]: the points of the rectangle
/// `[min, max]` that lie in the parallelogram `centre + a * u + b * v` (`|a|, |b| <= 1`).
///
/// On a seeded lattice ([`crate::Lattice::Seeded`]) a query's cells are squares turned with
/// the tiling: the rectangle is a cell's box (or its part inside the query) and the
/// parallelogram the cell itself, up to half the area of the box at 45 degrees. A density
/// may bound itself over the rectangle alone (always right), or over both for a tighter
/// model; [`Patch::rect`] is a plain rectangle.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Patch {
    /// The rectangle's lower corner.
    pub min: DVec2,
    /// The rectangle's upper corner.
    pub max: DVec2,
    /// The parallelogram's centre.
    pub centre: DVec2,
    /// Half of one side of the parallelogram, as a vector.
    pub u: DVec2,
    /// Half of its other side.
    pub v: DVec2,
}

impl Patch {
    /// The rectangle `[min, max]` alone (the parallelogram is the rectangle).
    pub fn rect(min: DVec2, max: DVec2) -> Self {
        let half = (max - min) * 0.5;
        Self {
            min,
            max,
            centre: min + half,
            u: DVec2::new(half.x, 0.0),
            v: DVec2::new(0.0, half.y),
        }
    }

    /// The parallelogram's corners.
    pub fn corners(&self) -> [DVec2; 4] {
        let (c, u, v) = (self.centre, self.u, self.v);
        [c - u - v, c + u - v, c + u + v, c - u + v]
    }

    /// The squared distance from `p` to the patch's farthest point, or more: the nearer of
    /// the rectangle's and the parallelogram's farthest corners.
    pub fn farthest_squared(&self, p: DVec2) -> f64 {
        let box_far = (self.min - p)
            .abs()
            .max((self.max - p).abs())
            .length_squared();
        let far = self.corners().map(|c| (c - p).length_squared());
        box_far.min(far[0].max(far[1]).max(far[2]).max(far[3]))
    }

    /// Whether the rectangle `[lo, hi]` may hold points of the patch: false only where an
    /// axis separates them by more than `slack`.
    pub fn may_meet(&self, lo: DVec2, hi: DVec2, slack: f64) -> bool {
        let apart = lo.cmpgt(self.max + slack) | hi.cmplt(self.min - slack);
        if apart.any() {
            return false;
        }
        let (centre, half) = ((lo + hi) * 0.5, (hi - lo) * 0.5);
        let d = centre - self.centre;
        // The world's axes, then the normals of the parallelogram's sides.
        let reach = self.u.abs() + self.v.abs();
        if (d.abs() - half - reach).cmpgt(DVec2::splat(slack)).any() {
            return false;
        }
        [(self.u, self.v), (self.v, self.u)]
            .iter()
            .all(|&(side, other)| {
                let n = side.perp();
                let gap = d.dot(n).abs() - half.dot(n.abs()) - other.dot(n).abs();
                // The gap in world units is `gap / |n|`.
                gap <= slack * n.length()
            })
    }

    /// The patch mapped by `p * factor`.
    pub fn scaled(&self, factor: f64) -> Self {
        let (a, b) = (self.min * factor, self.max * factor);
        Self {
            min: a.min(b),
            max: a.max(b),
            centre: self.centre * factor,
            u: self.u * factor,
            v: self.v * factor,
        }
    }
}

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

    /// Bounds of the density over `patch` (inside the model's own): the plane's extremes
    /// at the rectangle's corners or the parallelogram's, whichever are nearer, and the bend
    /// at the patch's point farthest from the centre.
    pub fn bounds_over(&self, patch: &Patch) -> (f64, f64) {
        let (a, b) = (patch.min - self.centre, patch.max - self.centre);
        let (ga, gb) = (self.gradient * a, self.gradient * b);
        let mut low = self.value + ga.min(gb).element_sum();
        let mut high = self.value + ga.max(gb).element_sum();
        let (g, c) = (self.gradient, patch.centre - self.centre);
        let spread = g.dot(patch.u).abs() + g.dot(patch.v).abs();
        // Both hold every point of the patch: the tighter bound holds too (NaN: ignored).
        low = low.max(self.value + g.dot(c) - spread);
        high = high.min(self.value + g.dot(c) + spread);
        let bend = self.curvature * patch.farthest_squared(self.centre) + self.margin;
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

    /// A square of side 2 about (1, 2), turned by 30 degrees, in its box.
    fn turned() -> Patch {
        let u = DVec2::from_angle(30f64.to_radians());
        let (centre, v) = (DVec2::new(1.0, 2.0), u.perp());
        let reach = u.abs() + v.abs();
        Patch {
            min: centre - reach,
            max: centre + reach,
            centre,
            u,
            v,
        }
    }

    #[test]
    fn patches_meet_every_rectangle_holding_one_of_their_points() {
        let patch = turned();
        let (mut met, mut apart) = (0, 0);
        for i in 0..40 {
            for j in 0..40 {
                let lo = patch.min - 0.5 + DVec2::new(i as f64, j as f64) * 0.1;
                let hi = lo + 0.25;
                let holds = (0..=20).any(|a| {
                    (0..=20).any(|b| {
                        let p = patch.centre
                            + patch.u * (a as f64 / 10.0 - 1.0)
                            + patch.v * (b as f64 / 10.0 - 1.0);
                        p.cmpge(lo).all() && p.cmple(hi).all()
                    })
                });
                let meets = patch.may_meet(lo, hi, 0.0);
                assert!(
                    meets || !holds,
                    "{lo}..{hi} holds a point but is kept apart"
                );
                (met, apart) = (met + usize::from(meets), apart + usize::from(!meets));
            }
        }
        // The box's corners outside the square, and the world beyond the box, are apart.
        assert!(apart > 900 && met > 300, "{met} met, {apart} apart");
        // A sliver off the square is kept apart, unless within the slack.
        let corner = patch.centre + patch.u + patch.v;
        let beyond = corner + (patch.u + patch.v).normalize() * 0.01;
        assert!(!patch.may_meet(beyond, beyond + 0.001, 0.0));
        assert!(patch.may_meet(beyond, beyond + 0.001, 0.02));
    }

    #[test]
    fn a_turned_patch_bounds_a_model_tighter_than_its_box() {
        let (m, patch) = (model(), turned());
        let (low, high) = m.bounds_over(&patch);
        let (box_low, box_high) = m.bounds_over(&Patch::rect(patch.min, patch.max));
        assert!(
            low > box_low && high < box_high,
            "{low}..{high} vs {box_low}..{box_high}"
        );
        let far = patch.farthest_squared(m.centre);
        // The square's corners lie sqrt(2) from its centre, the box's 1.93 from it.
        assert!((far - 2.0).abs() < 1e-12, "{far}");
        for a in -10..=10 {
            for b in -10..=10 {
                let p = patch.centre + patch.u * (a as f64 / 10.0) + patch.v * (b as f64 / 10.0);
                let (l, h) = m.bounds_at(p);
                assert!(low <= l && h <= high, "{p}: {l}..{h} outside {low}..{high}");
            }
        }
    }

    #[test]
    fn bounds_over_a_rectangle_hold_the_bounds_at_its_points() {
        let m = model();
        let (min, max) = (DVec2::new(0.5, 1.0), DVec2::new(2.0, 2.5));
        let (low, high) = m.bounds_over(&Patch::rect(min, max));
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
