//! Target densities: how many points per unit area a query should produce, everywhere.
//!
//! A [`Density`] answers two questions: the density at a point, and a *conservative*
//! maximum over a rectangle. The query descends into finer tiles only where that maximum
//! asks for it, so the maximum must never be below any value inside the rectangle (or thin
//! features would be missed), and should be tight (or time is wasted).
//!
//! Values are sanitized by the query: NaN and negative densities count as 0. An infinite
//! density asks for infinitely many points, which the query's point budget turns into
//! [`crate::query::QueryError::BudgetExceeded`]; it never panics or allocates for it.

mod combinators;
mod image;
mod local;
mod noise;
#[cfg(test)]
mod tests;

pub use self::combinators::{DistanceFalloff, Exclude, Mask, Product, Scale, Sum, SumOf};
pub use self::image::{
    DENSITY_BYTES_PER_PIXEL, ImageDensity, ImageDensityError, MAX_DENSITY_BYTES, MAX_IMAGE_PIXELS,
    Placement, decode_image, decode_image_with_limit, open_image, open_image_with_limit,
};
pub use self::local::{LocalModel, Patch};
pub use self::noise::{NoiseDensity, NoiseParams};

use glam::DVec2;

/// A density function over the plane, in points per unit area.
pub trait Density {
    /// Density at `p`.
    fn density(&self, p: DVec2) -> f64;
    /// An upper bound of [`Density::density`] over the rectangle `[min, max]`.
    fn max_over(&self, min: DVec2, max: DVec2) -> f64;
    /// A lower bound of [`Density::density`] over the rectangle `[min, max]`. Queries take
    /// points whose threshold lies below it without evaluating the density, so it must never
    /// exceed the density anywhere in the rectangle; the default, 0, is always right.
    fn min_over(&self, min: DVec2, max: DVec2) -> f64 {
        let _ = (min, max);
        0.0
    }
    /// Whether a point at `p` with rank `threshold` appears, that is whether
    /// `sanitize(density(p)) * factor` exceeds `threshold`: the question a query asks of
    /// every point its bounds leave open. A density may override it to answer sooner, never
    /// differently.
    #[inline]
    fn exceeds(&self, p: DVec2, factor: f64, threshold: f64) -> bool {
        sanitize(self.density(p)) * factor > threshold
    }
    /// [`Density::exceeds`] for a point a [`LocalModel`] left open: its density lies close
    /// to the threshold, where bounds from partial evaluations rarely decide, so a density
    /// whose `exceeds` tries them may skip them here. Must answer exactly as `exceeds`; the
    /// default calls it.
    #[inline]
    fn exceeds_near(&self, p: DVec2, factor: f64, threshold: f64) -> bool {
        self.exceeds(p, factor, threshold)
    }
    /// A [`LocalModel`] of the density valid over `patch`, where the density has one
    /// cheaper than evaluating it at the patch's points: queries decide the points of a cell
    /// by it and evaluate only those it leaves open. The default, `None`, is always right.
    fn local_model(&self, patch: &Patch) -> Option<LocalModel> {
        let _ = patch;
        None
    }
}

/// A density behind a pointer is that density: references, boxes and shared pointers (the
/// form generation tasks hand between threads) all forward every method.
macro_rules! forward_density {
    ($($pointer:ty),*) => {$(
        impl<D: Density + ?Sized> Density for $pointer {
            #[inline]
            fn density(&self, p: DVec2) -> f64 {
                (**self).density(p)
            }
            #[inline]
            fn max_over(&self, min: DVec2, max: DVec2) -> f64 {
                (**self).max_over(min, max)
            }
            #[inline]
            fn min_over(&self, min: DVec2, max: DVec2) -> f64 {
                (**self).min_over(min, max)
            }
            #[inline]
            fn exceeds(&self, p: DVec2, factor: f64, threshold: f64) -> bool {
                (**self).exceeds(p, factor, threshold)
            }
            #[inline]
            fn exceeds_near(&self, p: DVec2, factor: f64, threshold: f64) -> bool {
                (**self).exceeds_near(p, factor, threshold)
            }
            #[inline]
            fn local_model(&self, patch: &Patch) -> Option<LocalModel> {
                (**self).local_model(patch)
            }
        }
    )*};
}

forward_density!(&D, Box<D>, std::sync::Arc<D>);

/// The same density everywhere.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Constant(pub f64);

impl Density for Constant {
    #[inline]
    fn density(&self, _: DVec2) -> f64 {
        self.0
    }
    #[inline]
    fn max_over(&self, _: DVec2, _: DVec2) -> f64 {
        self.0
    }
    #[inline]
    fn min_over(&self, _: DVec2, _: DVec2) -> f64 {
        self.0
    }
}

/// A closure density with a closure bound: `bound(min, max)` must be at least every value of
/// `f` in the rectangle.
#[derive(Clone, Copy)]
pub struct FnDensity<F, B> {
    f: F,
    bound: B,
}

impl<F: Fn(DVec2) -> f64, B: Fn(DVec2, DVec2) -> f64> FnDensity<F, B> {
    /// A density from a function and a rectangle bound.
    pub fn new(f: F, bound: B) -> Self {
        Self { f, bound }
    }
}

/// A closure density whose values never exceed `max` (a constant bound).
pub fn from_fn(
    f: impl Fn(DVec2) -> f64,
    max: f64,
) -> FnDensity<impl Fn(DVec2) -> f64, impl Fn(DVec2, DVec2) -> f64> {
    FnDensity::new(f, move |_, _| max)
}

impl<F: Fn(DVec2) -> f64, B: Fn(DVec2, DVec2) -> f64> Density for FnDensity<F, B> {
    #[inline]
    fn density(&self, p: DVec2) -> f64 {
        (self.f)(p)
    }
    #[inline]
    fn max_over(&self, min: DVec2, max: DVec2) -> f64 {
        (self.bound)(min, max)
    }
}
/// NaN and negative densities count as zero.
#[inline]
pub fn sanitize(v: f64) -> f64 {
    if v > 0.0 { v } else { 0.0 }
}
