//! Query rectangles: half-open, finite, never inverted.

use super::QueryError;
use glam::DVec2;
use serde::{Deserialize, Serialize};

/// A half-open rectangle `[min, max)` in world units. Always finite with `min <= max` on
/// both axes (it may be empty): [`Rect::new`] checks it, and so does deserializing.
///
/// With `bevy_reflect`, an opaque value, so that reflection cannot invert it.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "Corners", into = "Corners")]
#[cfg_attr(
    feature = "bevy_reflect",
    derive(bevy_reflect::Reflect),
    reflect(opaque, Clone, Debug, PartialEq)
)]
pub struct Rect {
    min: DVec2,
    max: DVec2,
}

/// The serialized form of a [`Rect`].
#[derive(Clone, Copy, Serialize, Deserialize)]
struct Corners {
    min: DVec2,
    max: DVec2,
}

impl TryFrom<Corners> for Rect {
    type Error = QueryError;
    fn try_from(c: Corners) -> Result<Self, QueryError> {
        Rect::new(c.min, c.max)
    }
}

impl From<Rect> for Corners {
    fn from(r: Rect) -> Self {
        Corners {
            min: r.min,
            max: r.max,
        }
    }
}

impl Rect {
    /// The empty rectangle at the origin.
    pub const EMPTY: Rect = Rect {
        min: DVec2::ZERO,
        max: DVec2::ZERO,
    };

    /// A rectangle; it may be empty, but not inverted or non-finite.
    pub fn new(min: DVec2, max: DVec2) -> Result<Self, QueryError> {
        if !(min.is_finite() && max.is_finite()) {
            return Err(QueryError::NonFiniteRect);
        }
        if max.x < min.x || max.y < min.y {
            return Err(QueryError::InvertedRect);
        }
        Ok(Self { min, max })
    }

    /// A rectangle from corners the caller knows to be finite and ordered.
    #[inline]
    pub(crate) fn from_ordered(min: DVec2, max: DVec2) -> Self {
        Self { min, max }
    }

    /// Inclusive lower corner.
    #[inline]
    pub fn min(&self) -> DVec2 {
        self.min
    }

    /// Exclusive upper corner.
    #[inline]
    pub fn max(&self) -> DVec2 {
        self.max
    }

    /// Width and height.
    pub fn size(&self) -> DVec2 {
        self.max - self.min
    }

    /// Whether `p` is inside (half-open).
    #[inline]
    pub fn contains(&self, p: DVec2) -> bool {
        p.x >= self.min.x && p.y >= self.min.y && p.x < self.max.x && p.y < self.max.y
    }

    /// Area.
    pub fn area(&self) -> f64 {
        (self.max.x - self.min.x) * (self.max.y - self.min.y)
    }

    /// Whether the rectangle has no area (it contains no point).
    #[inline]
    pub fn is_empty(&self) -> bool {
        !(self.max.x > self.min.x && self.max.y > self.min.y)
    }

    /// The common part of two rectangles, or `None` when it has no area.
    #[inline]
    pub fn intersect(&self, other: &Rect) -> Option<Rect> {
        let r = Rect {
            min: self.min.max(other.min),
            max: self.max.min(other.max),
        };
        (!r.is_empty()).then_some(r)
    }

    /// Whether the two rectangles share some area.
    pub fn overlaps(&self, other: &Rect) -> bool {
        self.intersect(other).is_some()
    }
}
