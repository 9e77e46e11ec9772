//! Clumped densities: instances gathered into patches (a Neyman-Scott process, as Thomas's
//! and Matérn's cluster processes): sparse parents, and around each a kernel holding a
//! mean number of instances. The parents are rwt's own blue-noise points, so a clump's
//! place is random access like everything else, and patches never overlap by chance as
//! often as they would with white-noise parents.
//!
//! ```
//! use rwt_core::clumps::{ClumpKernel, ClumpParams, Clumps};
//! use rwt_core::{Density, Rect, Sampler, TileSet};
//!
//! // One patch per 100 square units, 12 flowers in each, 3 units across.
//! let params = ClumpParams { seed: 9, clumps: 0.01, per_clump: 12.0, radius: 1.5, kernel: ClumpKernel::Thomas };
//! let flowers = Clumps::new(params).unwrap();
//! let sampler = Sampler::new(&TileSet::embedded(), 4).with_tile_size(2.0);
//! let rect = Rect::new([0.0, 0.0].into(), [200.0, 200.0].into()).unwrap();
//! let mut points = Vec::new();
//! sampler.query(rect, &flowers, &mut points).unwrap();
//! // About 12 x 0.01 x 40 000 = 4 800 flowers, in patches.
//! assert!((points.len() as f64 - flowers.integral(&rect).unwrap()).abs() < 300.0);
//! ```

use crate::density::{Constant, Density};
use crate::query::{QueryError, Rect, Sampler};
use crate::tileset::TileSet;
use glam::DVec2;
use std::sync::OnceLock;

/// The shape of one clump.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[cfg_attr(feature = "bevy_reflect", derive(bevy_reflect::Reflect))]
pub enum ClumpKernel {
    /// A Gaussian of standard deviation `radius / 3`, cut off at `radius` (Thomas): dense
    /// in the middle, thinning out.
    #[default]
    Thomas,
    /// Uniform over a disc of `radius` (Matérn): patches with sharp edges.
    Matern,
}

/// The parameters of [`Clumps`], as plain (serializable) data.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[cfg_attr(feature = "bevy_reflect", derive(bevy_reflect::Reflect))]
pub struct ClumpParams {
    /// Seed of the parents' tiling.
    pub seed: u64,
    /// Clumps (parents) per unit area.
    pub clumps: f64,
    /// Mean instances in one clump.
    pub per_clump: f64,
    /// Radius of one clump.
    pub radius: f64,
    /// The clump's shape.
    pub kernel: ClumpKernel,
}

/// Why clump parameters cannot make a density.
#[derive(Clone, Copy, Debug, PartialEq, thiserror::Error)]
pub enum ClumpError {
    /// A parameter that must be finite and positive is not.
    #[error("clump parameter {field} is {value}, not a finite positive number")]
    NotPositive {
        /// The field.
        field: &'static str,
        /// Its value.
        value: f64,
    },
    /// A clump's peak density (`per_clump` over its area) is not finite.
    #[error("clumps of {per_clump} instances within radius {radius} are too dense")]
    TooDense {
        /// Instances per clump.
        per_clump: f64,
        /// Clump radius.
        radius: f64,
    },
}

/// A density of clumps (see the module's documentation).
///
/// With `bevy_reflect`, an opaque value: its parents are derived from its [`ClumpParams`].
#[derive(Clone, Debug)]
#[cfg_attr(
    feature = "bevy_reflect",
    derive(bevy_reflect::Reflect),
    reflect(opaque, Clone, Debug)
)]
pub struct Clumps {
    params: ClumpParams,
    parents: Sampler,
    /// Density at a clump's centre.
    peak: f64,
    /// `1 / (2 sigma^2)` of the Thomas kernel.
    falloff: f64,
}

/// Points a parent tile holds at most, about: the parents' tile size follows from it.
const PARENTS_PER_TILE: f64 = 64.0;

/// The shipped tile set's sampler, made once.
fn embedded() -> &'static Sampler {
    static SAMPLER: OnceLock<Sampler> = OnceLock::new();
    SAMPLER.get_or_init(|| Sampler::new(&TileSet::embedded(), 0))
}

impl Clumps {
    /// Clumps over the shipped tile set's points.
    pub fn new(params: ClumpParams) -> Result<Self, ClumpError> {
        Self::with_sampler(params, embedded())
    }

    /// Clumps whose parents are points of `sampler`'s tile set.
    pub fn with_sampler(params: ClumpParams, sampler: &Sampler) -> Result<Self, ClumpError> {
        for (field, value) in [
            ("clumps", params.clumps),
            ("per_clump", params.per_clump),
            ("radius", params.radius),
        ] {
            if !(value.is_finite() && value > 0.0) {
                return Err(ClumpError::NotPositive { field, value });
            }
        }
        let r = params.radius;
        let (peak, falloff) = match params.kernel {
            ClumpKernel::Matern => (params.per_clump / (std::f64::consts::PI * r * r), 0.0),
            ClumpKernel::Thomas => {
                let sigma = r / 3.0;
                // The mass beyond 3 sigma is cut off: the rest is scaled up to hold it.
                let mass = 1.0 - (-4.5f64).exp();
                let peak = params.per_clump / (std::f64::consts::TAU * sigma * sigma * mass);
                (peak, 1.0 / (2.0 * sigma * sigma))
            }
        };
        if !peak.is_finite() {
            let (per_clump, radius) = (params.per_clump, r);
            return Err(ClumpError::TooDense { per_clump, radius });
        }
        let tile = (PARENTS_PER_TILE / params.clumps).sqrt();
        let parents = sampler.clone().with_seed(params.seed).with_tile_size(tile);
        Ok(Self {
            params,
            parents,
            peak,
            falloff,
        })
    }

    /// Its parameters.
    pub fn params(&self) -> ClumpParams {
        self.params
    }

    /// The kernel's density at squared distance `d2` from a clump's centre.
    fn kernel(&self, d2: f64) -> f64 {
        let r = self.params.radius;
        if d2 >= r * r {
            return 0.0;
        }
        match self.params.kernel {
            ClumpKernel::Matern => self.peak,
            ClumpKernel::Thomas => self.peak * (-d2 * self.falloff).exp(),
        }
    }

    /// Calls `f` with every clump centre within `[min, max]`; an error where the parents'
    /// query is refused (a rectangle beyond its budget, coordinates it cannot hold).
    fn each_parent(
        &self,
        min: DVec2,
        max: DVec2,
        mut f: impl FnMut(DVec2),
    ) -> Result<(), QueryError> {
        let rect = Rect::new(min, max)?;
        self.parents
            .query_with(rect, &Constant(self.params.clumps), |p| f(p.position))?;
        Ok(())
    }

    /// The mean number of instances over `rect`: the instances of the clumps whose
    /// kernels lie wholly inside it, plus a share of those across its border (integrated
    /// on a grid of a tenth of the radius).
    pub fn integral(&self, rect: &Rect) -> Result<f64, QueryError> {
        let r = self.params.radius;
        let grow = DVec2::splat(r);
        let step = r / 10.0;
        let mut total = 0.0;
        let outer = Rect::new(rect.min() - grow, rect.max() + grow)?;
        self.parents
            .query_with(outer, &Constant(self.params.clumps), |c| {
                let p = c.position;
                let inside = p.cmpge(rect.min() + grow).all() && p.cmple(rect.max() - grow).all();
                if inside {
                    total += self.params.per_clump;
                    return;
                }
                for i in 0..20 {
                    for j in 0..20 {
                        let q = p - grow + DVec2::new(i as f64 + 0.5, j as f64 + 0.5) * step;
                        if rect.contains(q) {
                            total += self.kernel(q.distance_squared(p)) * step * step;
                        }
                    }
                }
            })?;
        Ok(total)
    }
}

impl Density for Clumps {
    fn density(&self, p: DVec2) -> f64 {
        let r = DVec2::splat(self.params.radius);
        let mut sum = 0.0;
        match self.each_parent(p - r, p + r, |c| sum += self.kernel(c.distance_squared(p))) {
            Ok(()) => sum,
            // No density where the parents cannot be found (a point at infinity).
            Err(_) => 0.0,
        }
    }

    fn max_over(&self, min: DVec2, max: DVec2) -> f64 {
        let r = DVec2::splat(self.params.radius);
        let mut sum = 0.0;
        let found = self.each_parent(min - r, max + r, |c| {
            // The kernel's largest value over the rectangle: at its point nearest the centre.
            let nearest = c.clamp(min, max);
            sum += self.kernel(nearest.distance_squared(c));
        });
        match found {
            Ok(()) => sum,
            // Parents beyond the budget: no bound but the trivial one.
            Err(_) => f64::INFINITY,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::query::Point;

    fn params(kernel: ClumpKernel) -> ClumpParams {
        ClumpParams {
            seed: 5,
            clumps: 0.004,
            per_clump: 15.0,
            radius: 3.0,
            kernel,
        }
    }

    fn sampler() -> Sampler {
        Sampler::new(&TileSet::embedded(), 11).with_tile_size(3.0)
    }

    fn points(density: &Clumps, rect: Rect) -> Vec<Point> {
        let mut out = Vec::new();
        sampler().query(rect, density, &mut out).unwrap();
        out.sort_by_key(|p| p.id);
        out
    }

    fn rect(min: [f64; 2], max: [f64; 2]) -> Rect {
        Rect::new(min.into(), max.into()).unwrap()
    }

    #[test]
    fn counts_follow_the_integral_and_chunks_union_exactly() {
        for kernel in [ClumpKernel::Thomas, ClumpKernel::Matern] {
            let clumps = Clumps::new(params(kernel)).unwrap();
            let whole = rect([-200.0, -100.0], [200.0, 300.0]);
            let all = points(&clumps, whole);
            let integral = clumps.integral(&whole).unwrap();
            let ratio = all.len() as f64 / integral;
            assert!(
                (ratio - 1.0).abs() < 0.03,
                "{kernel:?}: {} for {integral}",
                all.len()
            );
            // Four chunks give exactly the whole's points, and a second density the same.
            let again = Clumps::new(params(kernel)).unwrap();
            let mut parts: Vec<Point> = [
                rect([-200.0, -100.0], [0.0, 100.0]),
                rect([0.0, -100.0], [200.0, 100.0]),
                rect([-200.0, 100.0], [0.0, 300.0]),
                rect([0.0, 100.0], [200.0, 300.0]),
            ]
            .into_iter()
            .flat_map(|r| points(&again, r))
            .collect();
            parts.sort_by_key(|p| p.id);
            assert_eq!(all, parts);
        }
    }

    #[test]
    fn instances_gather_in_patches() {
        let clumps = Clumps::new(params(ClumpKernel::Thomas)).unwrap();
        let all = points(&clumps, rect([0.0, 0.0], [300.0, 300.0]));
        // Every point lies within a clump's radius of a clump centre.
        let mut centres = Vec::new();
        clumps
            .each_parent(DVec2::splat(-3.0), DVec2::splat(303.0), |c| centres.push(c))
            .unwrap();
        for p in &all {
            let near = centres.iter().any(|c| c.distance(p.position) < 3.0);
            assert!(near, "{:?} outside every clump", p.position);
        }
        // The patches cover a small part of the area: 360 clumps of 28 square units each.
        assert!(
            centres.len() > 300 && all.len() > 4_000,
            "{} {}",
            centres.len(),
            all.len()
        );
    }

    #[test]
    fn bounds_hold_over_rectangles() {
        let clumps = Clumps::new(params(ClumpKernel::Thomas)).unwrap();
        for k in 0..200 {
            let min = DVec2::new((k * 37 % 300) as f64, (k * 53 % 300) as f64) * 0.7;
            let max = min + DVec2::new(1.0 + (k % 7) as f64, 0.5 + (k % 5) as f64);
            let bound = clumps.max_over(min, max);
            for i in 0..=8 {
                for j in 0..=8 {
                    let p = min + (max - min) * DVec2::new(i as f64, j as f64) / 8.0;
                    assert!(clumps.density(p) <= bound + 1e-12, "{p} over {bound}");
                }
            }
        }
    }

    #[test]
    fn bad_parameters_are_typed_errors() {
        let mut p = params(ClumpKernel::Matern);
        p.radius = f64::NAN;
        assert!(matches!(
            Clumps::new(p),
            Err(ClumpError::NotPositive {
                field: "radius",
                ..
            })
        ));
        p.radius = 1e-200;
        assert!(matches!(Clumps::new(p), Err(ClumpError::TooDense { .. })));
        p = params(ClumpKernel::Thomas);
        p.clumps = -1.0;
        assert!(Clumps::new(p).is_err());
    }
}
