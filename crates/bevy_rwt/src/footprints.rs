//! Footprints: shapes on the ground that clear every instance under them (a building, a
//! road, a camp placed at run time). Put a [`Footprint`] on any entity with a `Transform`;
//! adding, moving or removing it generates again only the chunks it covers (before and
//! after), and the cleared instances come back when it goes.
//!
//! ```
//! use bevy::prelude::*;
//! use bevy_rwt::footprints::Footprint;
//!
//! /// A cabin, 6 x 4 units, with a metre of clearance; grass still grows to its walls.
//! fn place_cabin(mut commands: Commands, layers: Query<Entity, With<bevy_rwt::ScatterLayer>>) {
//!     let trees_and_bushes: Vec<Entity> = layers.iter().collect();
//!     commands.spawn((
//!         Transform::from_xyz(12.0, 0.0, -3.0).with_rotation(Quat::from_rotation_y(0.4)),
//!         Footprint::rectangle(Vec2::new(3.0, 2.0))
//!             .with_margin(1.0)
//!             .on_layers(trees_and_bushes),
//!     ));
//! }
//! # let mut app = App::new();
//! # app.add_plugins((MinimalPlugins, bevy::asset::AssetPlugin::default(), bevy_rwt::RwtPlugins::default()));
//! # app.add_systems(Startup, place_cabin);
//! # app.finish();
//! # app.cleanup();
//! # app.update();
//! ```

use crate::look::GroundPlane;
use bevy::prelude::*;
use glam::DVec2;
use rwt_core::Rect;

/// The shape of a [`Footprint`], in the ground coordinates of its entity (x and z of its
/// `Transform` on the default plane, x and y on [`GroundPlane::Xy`]); the entity's
/// translation, turn and scale place it in the world. Serializable, for a game that sends
/// footprints across a network or saves them (`bevy_rwt_net` replicates them).
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize, Reflect)]
#[reflect(Clone, Debug, PartialEq)]
pub enum FootprintShape {
    /// A disc around the entity's origin.
    Circle {
        /// Its radius.
        radius: f32,
    },
    /// A rectangle centred on the entity's origin.
    Rectangle {
        /// Half its width (x) and depth.
        half_size: Vec2,
    },
    /// The convex hull of these points (any order; points inside it change nothing).
    Convex(Vec<Vec2>),
}

/// Clears every instance whose point lies under the shape or within `margin` of it.
#[derive(Component, Clone, Debug, PartialEq, Reflect)]
#[reflect(Component, Clone, Debug, PartialEq)]
#[require(Transform)]
pub struct Footprint {
    /// The shape.
    pub shape: FootprintShape,
    /// Clearance around the shape, in world units.
    pub margin: f32,
    /// The layers it clears (`None`: every layer).
    pub layers: Option<Vec<Entity>>,
    /// The classes it clears, by index in each cleared layer (`None`: every class).
    pub classes: Option<Vec<u16>>,
}

impl Footprint {
    /// A footprint of `shape` clearing every class of every layer, without margin.
    pub fn new(shape: FootprintShape) -> Self {
        Self {
            shape,
            margin: 0.0,
            layers: None,
            classes: None,
        }
    }

    /// A disc of `radius`.
    pub fn circle(radius: f32) -> Self {
        Self::new(FootprintShape::Circle { radius })
    }

    /// A rectangle of `half_size` around the origin.
    pub fn rectangle(half_size: Vec2) -> Self {
        Self::new(FootprintShape::Rectangle { half_size })
    }

    /// The convex hull of `points`.
    pub fn convex(points: impl IntoIterator<Item = Vec2>) -> Self {
        Self::new(FootprintShape::Convex(points.into_iter().collect()))
    }

    /// Clears `margin` more around the shape.
    pub fn with_margin(mut self, margin: f32) -> Self {
        self.margin = margin;
        self
    }

    /// Clears these layers only.
    pub fn on_layers(mut self, layers: impl IntoIterator<Item = Entity>) -> Self {
        self.layers = Some(layers.into_iter().collect());
        self
    }

    /// Clears these classes only (by index, in every layer it clears).
    pub fn on_classes(mut self, classes: impl IntoIterator<Item = u16>) -> Self {
        self.classes = Some(classes.into_iter().collect());
        self
    }

    /// Whether it clears layer `layer`.
    pub(crate) fn clears_layer(&self, layer: Entity) -> bool {
        self.layers.as_ref().is_none_or(|l| l.contains(&layer))
    }

    /// The footprint placed by `transform` on `plane`, in world ground coordinates.
    pub fn on_ground(&self, transform: &GlobalTransform, plane: GroundPlane) -> GroundFootprint {
        let to_ground = |local: Vec2| -> DVec2 {
            let w = transform.transform_point(plane.point_at(local, 0.0));
            plane.ground_of(w).as_dvec2()
        };
        let margin = self.margin.max(0.0) as f64;
        let shape = match &self.shape {
            FootprintShape::Circle { radius } => {
                let centre = to_ground(Vec2::ZERO);
                let edge = to_ground(Vec2::X * *radius).distance(centre);
                let other = to_ground(Vec2::Y * *radius).distance(centre);
                GroundShape::Circle {
                    centre,
                    radius: edge.max(other),
                }
            }
            FootprintShape::Rectangle { half_size } => {
                let h = half_size.abs();
                let corners = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)];
                let ground = corners.map(|(sx, sy)| to_ground(Vec2::new(sx * h.x, sy * h.y)));
                GroundShape::Convex(convex_hull(ground.to_vec()))
            }
            FootprintShape::Convex(points) => {
                GroundShape::Convex(convex_hull(points.iter().map(|p| to_ground(*p)).collect()))
            }
        };
        GroundFootprint {
            bounds: shape.bounds(margin),
            shape,
            margin,
            classes: self.classes.clone(),
        }
    }
}

/// A footprint in world ground coordinates, as generation tasks test points against it.
#[derive(Clone, Debug, PartialEq)]
pub struct GroundFootprint {
    shape: GroundShape,
    margin: f64,
    classes: Option<Vec<u16>>,
    /// Everything it may clear (shape and margin), `None` for a degenerate shape.
    bounds: Option<Rect>,
}

/// A shape on the ground.
#[derive(Clone, Debug, PartialEq)]
enum GroundShape {
    Circle {
        centre: DVec2,
        radius: f64,
    },
    /// Counter-clockwise vertices of a convex polygon (at least one).
    Convex(Vec<DVec2>),
}

impl GroundFootprint {
    /// Everything it may clear; `None` when it clears nothing (no finite shape).
    pub fn bounds(&self) -> Option<Rect> {
        self.bounds
    }

    /// Whether it clears a point of `class` at `p`.
    pub fn clears(&self, p: DVec2, class: u16) -> bool {
        self.bounds.is_some_and(|b| b.contains(p) || on_edge(&b, p))
            && self.classes.as_ref().is_none_or(|c| c.contains(&class))
            && self.shape.distance(p) <= self.margin
    }
}

/// Whether `p` lies on the max edges of `b` (a half-open rectangle that a closed shape
/// touches there).
fn on_edge(b: &Rect, p: DVec2) -> bool {
    p.cmpge(b.min()).all() && p.cmple(b.max()).all()
}

impl GroundShape {
    /// Distance from `p` to the shape (0 inside).
    fn distance(&self, p: DVec2) -> f64 {
        match self {
            GroundShape::Circle { centre, radius } => (p.distance(*centre) - radius).max(0.0),
            GroundShape::Convex(v) => {
                let n = v.len();
                let mut inside = n >= 3;
                let mut nearest = f64::INFINITY;
                for i in 0..n {
                    let (a, b) = (v[i], v[(i + 1) % n]);
                    inside &= (b - a).perp_dot(p - a) >= 0.0;
                    nearest = nearest.min(segment_distance(p, a, b));
                }
                if inside { 0.0 } else { nearest }
            }
        }
    }

    /// Bounds of the shape grown by `margin`; `None` when not finite.
    fn bounds(&self, margin: f64) -> Option<Rect> {
        let (lo, hi) = match self {
            GroundShape::Circle { centre, radius } => (
                *centre - DVec2::splat(*radius),
                *centre + DVec2::splat(*radius),
            ),
            GroundShape::Convex(v) => v.iter().fold(
                (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY)),
                |(lo, hi), p| (lo.min(*p), hi.max(*p)),
            ),
        };
        let (lo, hi) = (lo - DVec2::splat(margin), hi + DVec2::splat(margin));
        if !(lo.is_finite() && hi.is_finite()) {
            return None;
        }
        Rect::new(lo, hi).ok()
    }
}

/// Distance from `p` to the segment `a..b`.
fn segment_distance(p: DVec2, a: DVec2, b: DVec2) -> f64 {
    let ab = b - a;
    let t = if ab.length_squared() > 0.0 {
        ((p - a).dot(ab) / ab.length_squared()).clamp(0.0, 1.0)
    } else {
        0.0
    };
    p.distance(a + ab * t)
}

/// The convex hull of `points`, counter-clockwise (Andrew's monotone chain); non-finite
/// points are left out.
fn convex_hull(mut points: Vec<DVec2>) -> Vec<DVec2> {
    points.retain(|p| p.is_finite());
    points.sort_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)));
    points.dedup();
    if points.len() < 3 {
        return points;
    }
    let mut hull: Vec<DVec2> = Vec::with_capacity(2 * points.len());
    for pass in [
        &points[..],
        &points.iter().rev().copied().collect::<Vec<_>>()[..],
    ] {
        let start = hull.len();
        for &p in pass {
            while hull.len() >= start + 2 {
                let (a, b) = (hull[hull.len() - 2], hull[hull.len() - 1]);
                if (b - a).perp_dot(p - a) > 0.0 {
                    break;
                }
                hull.pop();
            }
            hull.push(p);
        }
        hull.pop();
    }
    hull
}

#[cfg(test)]
mod tests {
    use super::*;

    fn at(x: f32, z: f32, yaw: f32) -> GlobalTransform {
        GlobalTransform::from(
            Transform::from_xyz(x, 0.0, z).with_rotation(Quat::from_rotation_y(yaw)),
        )
    }

    #[test]
    fn shapes_clear_what_lies_under_them() {
        let circle = Footprint::circle(2.0)
            .with_margin(0.5)
            .on_ground(&at(10.0, 0.0, 0.0), GroundPlane::Xz);
        assert!(circle.clears(DVec2::new(12.4, 0.0), 0));
        assert!(!circle.clears(DVec2::new(12.6, 0.0), 0));
        // A quarter turn about y puts the rectangle's long side along z.
        let rect = Footprint::rectangle(Vec2::new(3.0, 1.0))
            .on_ground(&at(0.0, 0.0, std::f32::consts::FRAC_PI_2), GroundPlane::Xz);
        assert!(rect.clears(DVec2::new(0.0, 2.9), 0));
        assert!(!rect.clears(DVec2::new(2.9, 0.0), 0));
        let triangle = Footprint::convex([
            Vec2::ZERO,
            Vec2::new(4.0, 0.0),
            Vec2::new(0.0, 4.0),
            Vec2::new(1.0, 1.0),
        ])
        .on_classes([1])
        .on_ground(&GlobalTransform::IDENTITY, GroundPlane::Xz);
        assert!(triangle.clears(DVec2::new(1.9, 1.9), 1));
        assert!(!triangle.clears(DVec2::new(2.1, 2.1), 1));
        assert!(!triangle.clears(DVec2::new(1.0, 1.0), 0), "another class");
        let b = triangle.bounds().unwrap();
        assert_eq!((b.min(), b.max()), (DVec2::ZERO, DVec2::splat(4.0)));
    }

    #[test]
    fn degenerate_shapes_clear_at_most_their_margin() {
        let point = Footprint::convex([Vec2::ONE]).with_margin(1.0);
        let g = point.on_ground(&GlobalTransform::IDENTITY, GroundPlane::Xz);
        assert!(g.clears(DVec2::new(1.5, 1.5), 0));
        assert!(!g.clears(DVec2::new(2.5, 1.0), 0));
        let none =
            Footprint::convex([Vec2::NAN]).on_ground(&GlobalTransform::IDENTITY, GroundPlane::Xz);
        assert_eq!(none.bounds(), None);
        assert!(!none.clears(DVec2::ZERO, 0));
    }
}
