//! Densities made of densities: scaling, sums, products, masks, exclusions and distance
//! fall-off. Each keeps its inputs' bounds conservative.

use super::{Density, LocalModel, Patch, sanitize};
use glam::DVec2;

/// `inner * factor` (a negative inner density counts as 0 first).
#[derive(Clone, Debug)]
pub struct Scale<D>(pub D, pub f64);

impl<D: Density> Density for Scale<D> {
    // The inner density is sanitized first: a negative one times a negative factor must
    // stay 0, not turn positive behind the bounds' back.
    #[inline]
    fn density(&self, p: DVec2) -> f64 {
        sanitize(self.0.density(p)) * self.1
    }
    fn max_over(&self, min: DVec2, max: DVec2) -> f64 {
        sanitize(self.0.max_over(min, max)) * self.1.max(0.0)
    }
    fn min_over(&self, min: DVec2, max: DVec2) -> f64 {
        if self.1 >= 0.0 {
            sanitize(self.0.min_over(min, max)) * self.1
        } else {
            0.0
        }
    }
    fn local_model(&self, patch: &Patch) -> Option<LocalModel> {
        let factor = self.1;
        (factor >= 0.0 && factor.is_finite())
            .then(|| self.0.local_model(patch))
            .flatten()
            .map(|m| m.scaled(factor))
    }
}

/// `a + b`.
#[derive(Clone, Debug)]
pub struct Sum<A, B>(pub A, pub B);

impl<A: Density, B: Density> Density for Sum<A, B> {
    #[inline]
    fn density(&self, p: DVec2) -> f64 {
        sanitize(self.0.density(p)) + sanitize(self.1.density(p))
    }
    fn max_over(&self, min: DVec2, max: DVec2) -> f64 {
        sanitize(self.0.max_over(min, max)) + sanitize(self.1.max_over(min, max))
    }
    fn min_over(&self, min: DVec2, max: DVec2) -> f64 {
        sanitize(self.0.min_over(min, max)) + sanitize(self.1.min_over(min, max))
    }
}

/// The sum of a slice of densities (the total density of a layer's classes).
#[derive(Clone, Copy, Debug)]
pub struct SumOf<'a, D>(pub &'a [D]);

impl<D: Density> Density for SumOf<'_, D> {
    #[inline]
    fn density(&self, p: DVec2) -> f64 {
        self.0.iter().map(|d| sanitize(d.density(p))).sum()
    }
    fn max_over(&self, min: DVec2, max: DVec2) -> f64 {
        self.0.iter().map(|d| sanitize(d.max_over(min, max))).sum()
    }
    fn min_over(&self, min: DVec2, max: DVec2) -> f64 {
        self.0.iter().map(|d| sanitize(d.min_over(min, max))).sum()
    }
}

/// `a * b`.
#[derive(Clone, Debug)]
pub struct Product<A, B>(pub A, pub B);

impl<A: Density, B: Density> Density for Product<A, B> {
    #[inline]
    fn density(&self, p: DVec2) -> f64 {
        sanitize(self.0.density(p)) * sanitize(self.1.density(p))
    }
    fn max_over(&self, min: DVec2, max: DVec2) -> f64 {
        sanitize(self.0.max_over(min, max)) * sanitize(self.1.max_over(min, max))
    }
    fn min_over(&self, min: DVec2, max: DVec2) -> f64 {
        sanitize(self.0.min_over(min, max)) * sanitize(self.1.min_over(min, max))
    }
}

/// `inner` where `mask >= threshold`, zero elsewhere (exclusion zones, paths, water).
#[derive(Clone, Debug)]
pub struct Mask<D, M> {
    /// The density kept.
    pub inner: D,
    /// The mask density.
    pub mask: M,
    /// Mask values below this remove the density.
    pub threshold: f64,
}

impl<D: Density, M: Density> Density for Mask<D, M> {
    #[inline]
    fn density(&self, p: DVec2) -> f64 {
        if self.mask.density(p) >= self.threshold {
            self.inner.density(p)
        } else {
            0.0
        }
    }
    fn max_over(&self, min: DVec2, max: DVec2) -> f64 {
        if self.mask.max_over(min, max) >= self.threshold {
            self.inner.max_over(min, max)
        } else {
            0.0
        }
    }
    fn min_over(&self, min: DVec2, max: DVec2) -> f64 {
        if self.mask.min_over(min, max) >= self.threshold {
            self.inner.min_over(min, max)
        } else {
            0.0
        }
    }
}

/// `inner` except where `mask >= threshold` (painted exclusion zones: roads, clearings).
/// Its bound is `inner`'s: an exclusion can only remove points, so the bound stays
/// conservative without a minimum of the mask.
#[derive(Clone, Debug)]
pub struct Exclude<D, M> {
    /// The density kept outside the exclusion.
    pub inner: D,
    /// The exclusion mask.
    pub mask: M,
    /// Mask values at or above this remove the density.
    pub threshold: f64,
}

impl<D: Density, M: Density> Density for Exclude<D, M> {
    #[inline]
    fn density(&self, p: DVec2) -> f64 {
        if sanitize(self.mask.density(p)) >= self.threshold {
            0.0
        } else {
            self.inner.density(p)
        }
    }
    fn max_over(&self, min: DVec2, max: DVec2) -> f64 {
        self.inner.max_over(min, max)
    }
    fn min_over(&self, min: DVec2, max: DVec2) -> f64 {
        // Only where nothing can be excluded.
        if self.threshold > 0.0 && self.mask.max_over(min, max) < self.threshold {
            self.inner.min_over(min, max)
        } else {
            0.0
        }
    }
}

/// `inner` fading linearly from full at `near` to zero at `far` from `centre` (level of
/// detail by density around a viewer).
#[derive(Clone, Debug)]
pub struct DistanceFalloff<D> {
    /// The density faded.
    pub inner: D,
    /// Centre of the fall-off.
    pub centre: DVec2,
    /// Distance up to which the density is unchanged.
    pub near: f64,
    /// Distance from which the density is zero.
    pub far: f64,
}

impl<D> DistanceFalloff<D> {
    #[inline]
    fn factor(&self, distance: f64) -> f64 {
        if distance <= self.near {
            1.0
        } else if distance >= self.far {
            0.0
        } else {
            (self.far - distance) / (self.far - self.near)
        }
    }
}

impl<D: Density> Density for DistanceFalloff<D> {
    #[inline]
    fn density(&self, p: DVec2) -> f64 {
        self.inner.density(p) * self.factor(p.distance(self.centre))
    }
    fn max_over(&self, min: DVec2, max: DVec2) -> f64 {
        let nearest = self.centre.clamp(min, max);
        self.inner.max_over(min, max) * self.factor(nearest.distance(self.centre))
    }
    fn min_over(&self, min: DVec2, max: DVec2) -> f64 {
        let farthest = (min - self.centre).abs().max((max - self.centre).abs());
        sanitize(self.inner.min_over(min, max)) * self.factor(farthest.length())
    }
}
