//! Ground described in code: a constant height, a height function, a heightmap.

use super::{Ground, GroundBounds, SurfaceHit};
use bevy::prelude::*;
use glam::DVec2;
use rwt_core::density::{Density, ImageDensity};
use std::sync::Arc;

/// Flat ground at one height.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FlatGround(pub f32);

impl Ground for FlatGround {
    fn top(&self, _: Vec2) -> Option<SurfaceHit> {
        Some(SurfaceHit::flat(self.0))
    }

    fn bounds(&self, _: Vec2, _: Vec2) -> GroundBounds {
        GroundBounds {
            min_height: self.0,
            max_height: self.0,
            max_slope: 0.0,
            max_surfaces: 1,
            covered: true,
        }
    }
}

/// Ground whose height is a function of the ground position; its normal comes from forward
/// differences over [`FunctionGround::STEP`] (three evaluations a point, exact on planes).
#[derive(Clone)]
pub struct FunctionGround {
    height: Arc<dyn Fn(Vec2) -> f32 + Send + Sync>,
    max_slope: Option<f32>,
}

impl FunctionGround {
    /// The distance of the differences that give the normal.
    pub const STEP: f32 = 0.25;

    /// Ground of height `height(p)`, of unknown bounds.
    pub fn new(height: Arc<dyn Fn(Vec2) -> f32 + Send + Sync>) -> Self {
        Self {
            height,
            max_slope: None,
        }
    }

    /// Ground whose slope never exceeds `max_slope` (rise over run): its bounds over a
    /// rectangle follow from the height at the centre, so densities stay tight.
    pub fn with_max_slope(mut self, max_slope: f32) -> Self {
        self.max_slope = Some(max_slope.abs()).filter(|s| s.is_finite());
        self
    }
}

impl Ground for FunctionGround {
    fn top(&self, p: Vec2) -> Option<SurfaceHit> {
        let h = &self.height;
        let height = h(p);
        if !height.is_finite() {
            return None;
        }
        let s = Self::STEP;
        let gradient = Vec2::new(h(p + Vec2::X * s) - height, h(p + Vec2::Y * s) - height) / s;
        Some(SurfaceHit::with_gradient(height, gradient))
    }

    fn bounds(&self, min: Vec2, max: Vec2) -> GroundBounds {
        let Some(slope) = self.max_slope else {
            return GroundBounds::UNKNOWN;
        };
        let centre = (self.height)(0.5 * (min + max));
        let reach = slope * 0.5 * (max - min).length();
        GroundBounds {
            min_height: centre - reach,
            max_height: centre + reach,
            max_slope: slope,
            max_surfaces: 1,
            covered: true,
        }
    }
}

/// A heightmap: an image's bilinear values over a ground rectangle times a height scale (0
/// outside the rectangle); its normal comes from central differences over half a texel.
#[derive(Clone)]
pub struct HeightmapGround {
    map: Arc<ImageDensity>,
    /// Ground size of one texel.
    texel: Vec2,
}

impl HeightmapGround {
    /// The heightmap of `map`, whose values (times its scale) are heights, and whose image
    /// covers `size` on the ground.
    pub fn new(map: ImageDensity, size: Vec2) -> Self {
        let (w, h) = map.dimensions();
        Self {
            texel: size / Vec2::new(w.max(1) as f32, h.max(1) as f32),
            map: Arc::new(map),
        }
    }

    fn height(&self, p: Vec2) -> f32 {
        self.map.density(p.as_dvec2()) as f32
    }
}

impl Ground for HeightmapGround {
    fn top(&self, p: Vec2) -> Option<SurfaceHit> {
        let s = 0.5 * self.texel;
        let dx = self.height(p + Vec2::X * s.x) - self.height(p - Vec2::X * s.x);
        let dz = self.height(p + Vec2::Y * s.y) - self.height(p - Vec2::Y * s.y);
        let gradient = Vec2::new(dx, dz) / (2.0 * s);
        Some(SurfaceHit::with_gradient(self.height(p), gradient))
    }

    fn bounds(&self, min: Vec2, max: Vec2) -> GroundBounds {
        // Heights lie between the map's bounds (either way round for a negative scale) and
        // 0, which it reads outside its rectangle.
        let span = |lo: DVec2, hi: DVec2| {
            let (a, b) = (self.map.max_over(lo, hi), self.map.min_over(lo, hi));
            (a.min(b).min(0.0) as f32, a.max(b).max(0.0) as f32)
        };
        let (low, high) = span(min.as_dvec2(), max.as_dvec2());
        // Bilinear patches rise at most by the spread of their texels over a texel, and the
        // central differences reach half a texel beyond the rectangle.
        let grow = self.texel.as_dvec2() * 1.5;
        let (bottom, top) = span(min.as_dvec2() - grow, max.as_dvec2() + grow);
        let run = self.texel.min_element().max(f32::MIN_POSITIVE);
        GroundBounds {
            min_height: low,
            max_height: high,
            max_slope: (top - bottom) / run * std::f32::consts::SQRT_2,
            max_surfaces: 1,
            covered: true,
        }
    }
}
