//! The ground instances stand on: one trait, [`Ground`], answers where the surface is above
//! a point of a layer's plane (its height, its normal, the entity it belongs to) and what a
//! rectangle's surfaces are bounded by (height range, steepest slope, how many lie above one
//! another), so that generation places points on it and the query's density bounds stay
//! tight.
//!
//! Ground described in code ([`FlatGround`], [`FunctionGround`], [`HeightmapGround`]) and
//! the game's own meshes ([`SurfaceMesh`] for one entity, combined for a layer by
//! [`SurfaceGround`]) are implementations; a terrain crate implements it for its terrain and
//! hands it to a layer as [`crate::HeightSource::Custom`].
//!
//! Heights and normals are in the plane's frame: `y` is up from the plane (the world's y on
//! the x-z ground of a 3-D world, z on the x-y plane of a 2-D one), `x` and `z` follow the
//! plane's two ground axes.

mod code;
mod mesh;
mod rule;
mod surfaces;

pub use code::{FlatGround, FunctionGround, HeightmapGround};
pub use mesh::{MeshGroundError, MeshTriangles, SurfaceMesh};
pub(crate) use rule::Stands;
pub use rule::{GroundRule, GroundSettings, MAX_AREA_FACTOR};
pub use surfaces::{ScatterSurface, SurfaceGround};

use bevy::prelude::*;
use std::sync::Arc;

/// A surface above a point of the plane.
#[derive(Clone, Copy, Debug, PartialEq, Reflect)]
#[reflect(Clone, Debug, PartialEq)]
pub struct SurfaceHit {
    /// Height of the surface above the plane.
    pub height: f32,
    /// Unit normal, in the plane's frame (`y` up from the plane).
    pub normal: Vec3,
    /// The entity whose mesh this surface is; `None` for ground described in code.
    pub entity: Option<Entity>,
    /// Whether the layer grows on it (otherwise it only covers what lies under it: a mesh
    /// that is ground for other layers).
    pub grows: bool,
}

impl SurfaceHit {
    /// A horizontal surface at `height`.
    pub fn flat(height: f32) -> Self {
        Self {
            height,
            normal: Vec3::Y,
            entity: None,
            grows: true,
        }
    }

    /// A surface at `height` whose height rises by `gradient` (per unit along the plane's
    /// two axes).
    pub fn with_gradient(height: f32, gradient: Vec2) -> Self {
        Self {
            height,
            normal: Vec3::new(-gradient.x, 1.0, -gradient.y).normalize_or(Vec3::Y),
            entity: None,
            grows: true,
        }
    }

    /// Its slope, rise over run (`tan` of its angle to the plane); infinite for a wall or a
    /// surface facing down.
    pub fn slope(&self) -> f32 {
        if self.normal.y <= 0.0 {
            return f32::INFINITY;
        }
        self.normal.xz().length() / self.normal.y
    }

    /// Surface area over a unit of plane area (`1 / cos` of its angle); infinite for a wall
    /// or a surface facing down.
    pub fn area_factor(&self) -> f32 {
        if self.normal.y <= 0.0 {
            return f32::INFINITY;
        }
        1.0 / self.normal.y
    }
}

/// What the surfaces over a rectangle of the plane are bounded by. Conservative: no
/// surface over the rectangle lies outside `min_height..=max_height`, is steeper than
/// `max_slope`, or has more than `max_surfaces` others above the same point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GroundBounds {
    /// Lowest height of any surface.
    pub min_height: f32,
    /// Highest height of any surface.
    pub max_height: f32,
    /// Steepest slope (rise over run) of any surface.
    pub max_slope: f32,
    /// Most surfaces above one point (0: no surface over the rectangle).
    pub max_surfaces: u32,
    /// Whether every point of the rectangle has a surface.
    pub covered: bool,
}

impl GroundBounds {
    /// Bounds that say nothing: one surface everywhere, of any height and slope.
    pub const UNKNOWN: Self = Self {
        min_height: f32::NEG_INFINITY,
        max_height: f32::INFINITY,
        max_slope: f32::INFINITY,
        max_surfaces: 1,
        covered: true,
    };

    /// No surface over the rectangle.
    pub const EMPTY: Self = Self {
        min_height: f32::INFINITY,
        max_height: f32::NEG_INFINITY,
        max_slope: 0.0,
        max_surfaces: 0,
        covered: false,
    };

    /// Bounds covering both.
    pub fn union(self, other: Self) -> Self {
        Self {
            min_height: self.min_height.min(other.min_height),
            max_height: self.max_height.max(other.max_height),
            max_slope: self.max_slope.max(other.max_slope),
            max_surfaces: self.max_surfaces.max(other.max_surfaces),
            covered: self.covered || other.covered,
        }
    }
}

/// The ground of a layer: where its instances stand.
///
/// ```
/// use bevy::prelude::*;
/// use bevy_rwt::ground::{Ground, GroundBounds, SurfaceHit};
///
/// /// A tilted plane, rising 0.5 per unit along x.
/// struct Ramp;
///
/// impl Ground for Ramp {
///     fn top(&self, p: Vec2) -> Option<SurfaceHit> {
///         Some(SurfaceHit::with_gradient(0.5 * p.x, Vec2::new(0.5, 0.0)))
///     }
///     fn bounds(&self, min: Vec2, max: Vec2) -> GroundBounds {
///         GroundBounds {
///             min_height: 0.5 * min.x,
///             max_height: 0.5 * max.x,
///             max_slope: 0.5,
///             max_surfaces: 1,
///             covered: true,
///         }
///     }
/// }
///
/// assert_eq!(Ramp.top(Vec2::new(2.0, 7.0)).unwrap().height, 1.0);
/// ```
pub trait Ground: Send + Sync + 'static {
    /// The top-most surface above `p` that the layer grows on; `None` where there is none
    /// (a hole, or a surface that is not the layer's ground lies on top).
    fn top(&self, p: Vec2) -> Option<SurfaceHit>;

    /// Every surface above `p`, in any order: the layer's ground (a bridge's deck and the
    /// ground under it) and what covers it ([`SurfaceHit::grows`] false). The default is
    /// [`Ground::top`] alone.
    fn hits(&self, p: Vec2, visit: &mut dyn FnMut(SurfaceHit)) {
        if let Some(hit) = self.top(p) {
            visit(hit);
        }
    }

    /// What the surfaces over the rectangle `min..=max` are bounded by. The default,
    /// [`GroundBounds::UNKNOWN`], is always right but keeps nothing tight.
    fn bounds(&self, min: Vec2, max: Vec2) -> GroundBounds {
        let _ = (min, max);
        GroundBounds::UNKNOWN
    }
}

/// A ground shared with generation tasks.
pub type SharedGround = Arc<dyn Ground>;

/// Which surfaces above a point a layer grows on.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize, Reflect)]
#[reflect(Clone, Debug, Default, PartialEq)]
pub enum SurfacePolicy {
    /// The top-most surface only (grass on a terrain, not under the rocks on it).
    #[default]
    TopMost,
    /// Every upward-facing surface within the layer's slope limit (grass on a bridge and
    /// under it, moss on a cave floor). Each point grows on one of them, chosen by a hash of
    /// its identity weighted by their areas, so every surface gets its share of the density.
    Every,
}
