//! Viewers: the entities (usually cameras) around which layers stream, laid on the ground
//! as a position and a view wedge.

mod plugin;

pub use plugin::RwtViewersPlugin;

use crate::look::GroundPlane;
use crate::settings::RwtSettings;
use bevy::prelude::*;
use glam::DVec2;
use rwt_core::streaming::Viewer;

/// Which directions a viewer streams in.
#[derive(Clone, Copy, Debug, PartialEq, Reflect)]
#[reflect(Clone, Debug, PartialEq)]
pub enum ViewCone {
    /// Every direction (top-down views, or to be ready for any turn).
    All,
    /// A wedge of this half-angle (radians) around the view direction.
    Fixed(f32),
    /// The horizontal half-angle of the entity's perspective `Projection`, plus `margin`
    /// radians for turning; every direction for other projections.
    Camera {
        /// Extra half-angle beyond the projection's.
        margin: f32,
    },
}

/// Marks an entity (usually a camera) around which layers are streamed. Chunks near it are
/// always loaded; farther ones where its view cone, laid on the ground, reaches them.
#[derive(Component, Clone, Copy, Debug, Reflect)]
#[reflect(Component, Clone, Debug)]
#[require(Transform)]
pub struct RwtViewer {
    /// Directions streamed.
    pub cone: ViewCone,
}

impl RwtViewer {
    /// A viewer that streams in every direction.
    pub fn all_around() -> Self {
        Self {
            cone: ViewCone::All,
        }
    }
}

impl Default for RwtViewer {
    /// The camera's own view cone plus 15 degrees on each side.
    fn default() -> Self {
        Self {
            cone: ViewCone::Camera {
                margin: 15f32.to_radians(),
            },
        }
    }
}

/// Where the viewers are this frame, on each ground plane.
#[derive(Resource, Default, Debug)]
pub(crate) struct Viewers {
    /// On the x-z ground of a 3-D world, with view wedges.
    pub xz: Vec<Viewer>,
    /// On the x-y plane of a 2-D world, every direction.
    pub xy: Vec<Viewer>,
}

impl Viewers {
    /// The viewers of layers lying on `plane`.
    pub fn on(&self, plane: GroundPlane) -> &[Viewer] {
        match plane {
            GroundPlane::Xz => &self.xz,
            GroundPlane::Xy => &self.xy,
        }
    }
}

fn ground(t: &GlobalTransform) -> DVec2 {
    let p = t.translation();
    DVec2::new(p.x as f64, p.z as f64)
}

/// Half-angle of a viewer's ground wedge, or `None` for every direction.
fn half_angle(cone: ViewCone, projection: Option<&Projection>) -> Option<f32> {
    let half = match cone {
        ViewCone::All => return None,
        ViewCone::Fixed(h) => h,
        ViewCone::Camera { margin } => match projection {
            Some(Projection::Perspective(p)) => {
                ((p.fov * 0.5).tan() * p.aspect_ratio).atan() + margin
            }
            _ => return None,
        },
    };
    // Wider than a half-turn is every direction.
    (half < std::f32::consts::FRAC_PI_2 * 1.9).then_some(half)
}

/// Viewer positions and view wedges on the ground plane.
pub(crate) fn collect_viewers(
    mut viewers: ResMut<Viewers>,
    query: Query<(&GlobalTransform, &RwtViewer, Option<&Projection>)>,
    settings: Res<RwtSettings>,
) {
    viewers.xz.clear();
    viewers.xy.clear();
    for (t, v, projection) in &query {
        let p = t.translation();
        viewers
            .xy
            .push(Viewer::omni(DVec2::new(p.x as f64, p.y as f64)));
        let position = ground(t);
        let forward = t.forward();
        let flat = Vec2::new(forward.x, forward.z);
        // Looking mostly down, the view covers every direction.
        let footprint = match half_angle(v.cone, projection) {
            Some(half) if flat.length() > 0.3 => {
                let dir = flat.normalize();
                let reach = settings.footprint_reach as f32;
                let side = |a: f32| {
                    let (s, c) = a.sin_cos();
                    let d = Vec2::new(dir.x * c - dir.y * s, dir.x * s + dir.y * c) * reach;
                    DVec2::new(position.x + d.x as f64, position.y + d.y as f64)
                };
                if half >= std::f32::consts::FRAC_PI_2 {
                    // A wedge wider than a half-plane is not convex: approximate it by the
                    // half-plane ahead plus the near ring, which is loaded anyway.
                    vec![
                        side(-std::f32::consts::FRAC_PI_2),
                        side(0.0),
                        side(std::f32::consts::FRAC_PI_2),
                    ]
                } else {
                    // Counter-clockwise wedge: apex, then the two far corners.
                    vec![position, side(-half), side(half)]
                }
            }
            _ => Vec::new(),
        };
        viewers.xz.push(Viewer {
            position,
            footprint,
        });
    }
}
