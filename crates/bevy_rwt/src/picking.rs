//! Picking: the instance a ray hits, or the instances near a ground point, for entity and
//! instanced classes alike, without an entity per instance. Points are deterministic, so
//! the few chunks a ray crosses are generated again (the same query, level of detail, edits
//! and footprints as what they show) and each point's instance is tested by its class's
//! bounds, turned and scaled as it is drawn.
//!
//! ```
//! use bevy::prelude::*;
//! use bevy_rwt::edits::EditInstance;
//! use bevy_rwt::picking::{PickFilter, ScatterPicking};
//!
//! /// Chops the tree under the cursor on a click.
//! fn chop_on_click(
//!     buttons: Res<ButtonInput<MouseButton>>,
//!     cameras: Query<(&Camera, &GlobalTransform)>,
//!     windows: Query<&Window>,
//!     picking: ScatterPicking,
//!     mut edits: MessageWriter<EditInstance>,
//! ) {
//!     let (Ok((camera, at)), Ok(window)) = (cameras.single(), windows.single()) else { return };
//!     let Some(ray) = window
//!         .cursor_position()
//!         .and_then(|c| camera.viewport_to_world(at, c).ok())
//!     else {
//!         return;
//!     };
//!     if buttons.just_pressed(MouseButton::Left)
//!         && let Some(hit) = picking.cast_ray(ray, &PickFilter::default().classes([0]))
//!     {
//!         edits.write(EditInstance::remove(hit.layer, hit.id));
//!     }
//! }
//! # fn main() {}
//! ```

use crate::layers::ScatterLayer;
use crate::look::{ClassLook, GroundPlane};
use crate::streaming::{Changes, KnownFootprints, LayerState, ShownLayer};
use bevy::camera::primitives::MeshAabb;
use bevy::ecs::system::SystemParam;
use bevy::prelude::*;
use glam::DVec2;
use rwt_core::query::{Point, PointId, Rect};

/// An instance that a pick found.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ScatterHit {
    /// The layer entity.
    pub layer: Entity,
    /// The class index in the layer.
    pub class: u16,
    /// The point.
    pub id: PointId,
    /// The instance's transform, as drawn.
    pub transform: Transform,
    /// Along the ray: distance (in ray lengths) to where it enters the instance's bounds;
    /// near a ground point: distance from it to the point.
    pub distance: f32,
}

/// Which instances a pick considers.
#[derive(Clone, Debug, PartialEq)]
pub struct PickFilter {
    /// These layers only (`None`: all).
    pub layers: Option<Vec<Entity>>,
    /// These classes only, by index in each layer (`None`: all). Asking for the first
    /// classes of a layer (trees before grass) lets a pick generate only their points.
    pub classes: Option<Vec<u16>>,
    /// How far along a ray to look, in world units.
    pub max_distance: f32,
}

impl Default for PickFilter {
    fn default() -> Self {
        Self {
            layers: None,
            classes: None,
            max_distance: Self::MAX_DISTANCE,
        }
    }
}

impl PickFilter {
    /// Default of [`PickFilter::max_distance`].
    pub const MAX_DISTANCE: f32 = 500.0;

    /// Considers these layers only.
    pub fn layers(mut self, layers: impl IntoIterator<Item = Entity>) -> Self {
        self.layers = Some(layers.into_iter().collect());
        self
    }

    /// Considers these classes only.
    pub fn classes(mut self, classes: impl IntoIterator<Item = u16>) -> Self {
        self.classes = Some(classes.into_iter().collect());
        self
    }

    /// Looks this far along a ray.
    pub fn max_distance(mut self, distance: f32) -> Self {
        self.max_distance = distance;
        self
    }

    fn wants(&self, class: u16) -> bool {
        self.classes.as_ref().is_none_or(|c| c.contains(&class))
    }
}

/// Finds instances by ray or by ground position (a system parameter).
#[derive(SystemParam)]
pub struct ScatterPicking<'w, 's> {
    layers: Query<'w, 's, (Entity, &'static ScatterLayer, &'static LayerState)>,
    footprints: Res<'w, KnownFootprints>,
    meshes: Option<Res<'w, Assets<Mesh>>>,
    #[cfg(feature = "gltf")]
    assets: Option<Res<'w, crate::instancing::ResolvedAssets>>,
}

impl ScatterPicking<'_, '_> {
    /// The bounds of a class's look at scale 1 (`None`: not known yet, or code's own).
    fn look_bounds(&self, look: &ClassLook) -> Option<(Vec3, Vec3)> {
        let mesh_bounds = |mesh: &Handle<Mesh>| {
            let aabb = self.meshes.as_deref()?.get(mesh)?.compute_aabb()?;
            Some((Vec3::from(aabb.min()), Vec3::from(aabb.max())))
        };
        match look {
            ClassLook::Mesh { mesh, .. } => mesh_bounds(mesh),
            ClassLook::Instanced(look) => mesh_bounds(&look.mesh),
            ClassLook::Custom(_) => None,
            #[cfg(feature = "gltf")]
            ClassLook::Asset(look) => Some(self.assets.as_deref()?.ready(look)?.bounds),
        }
    }

    /// The nearest instance `ray` enters within the filter's distance.
    pub fn cast_ray(&self, ray: Ray3d, filter: &PickFilter) -> Option<ScatterHit> {
        let mut best: Option<ScatterHit> = None;
        for (entity, layer, state) in self.layers_of(filter) {
            let Some(shown) = state.shown(layer) else {
                continue;
            };
            let bounds = ClassBounds::of(layer, |look| self.look_bounds(look));
            let segment = ground_segment(ray, filter.max_distance, layer.plane);
            let reach = bounds.reach(layer);
            let near = |r: &Rect| segment_meets(segment, &grow(r, reach));
            for p in self.points(entity, layer, &shown, filter, near) {
                let hit = self.instance(entity, layer, &shown, &p);
                let Some(t) = bounds.enter(ray, &hit.transform, p.class, filter.max_distance)
                else {
                    continue;
                };
                if best.is_none_or(|b| (t, hit.id) < (b.distance, b.id)) {
                    best = Some(ScatterHit { distance: t, ..hit });
                }
            }
        }
        best
    }

    /// Every instance whose point lies within `radius` of ground position `centre` (x and
    /// z on the default plane), nearest first.
    pub fn near(&self, centre: Vec2, radius: f32, filter: &PickFilter) -> Vec<ScatterHit> {
        let c = DVec2::new(centre.x as f64, centre.y as f64);
        let r = radius.max(0.0) as f64;
        let mut hits = Vec::new();
        for (entity, layer, state) in self.layers_of(filter) {
            let Some(shown) = state.shown(layer) else {
                continue;
            };
            let near = |rect: &Rect| rect.min().max(c.min(rect.max())).distance(c) <= r;
            let points = self.points(entity, layer, &shown, filter, near);
            for p in points.iter().filter(|p| p.position.distance(c) <= r) {
                let hit = self.instance(entity, layer, &shown, p);
                hits.push(ScatterHit {
                    distance: p.position.distance(c) as f32,
                    ..hit
                });
            }
        }
        hits.sort_by(|a, b| a.distance.total_cmp(&b.distance).then(a.id.cmp(&b.id)));
        hits
    }

    fn layers_of<'a>(
        &'a self,
        filter: &'a PickFilter,
    ) -> impl Iterator<Item = (Entity, &'a ScatterLayer, &'a LayerState)> {
        self.layers
            .iter()
            .filter(|(e, _, _)| filter.layers.as_ref().is_none_or(|l| l.contains(e)))
    }

    /// The shown points of the filter's classes in the chunks `near` accepts.
    fn points(
        &self,
        entity: Entity,
        layer: &ScatterLayer,
        shown: &ShownLayer,
        filter: &PickFilter,
        near: impl Fn(&Rect) -> bool,
    ) -> Vec<Point> {
        let size = layer.streaming.chunk_size;
        let last = filter
            .classes
            .as_ref()
            .and_then(|c| c.iter().max().copied());
        let mut out = Vec::new();
        for c in shown.chunks.iter().filter(|c| near(&c.chunk.rect(size))) {
            let rect = c.chunk.rect(size);
            let changes = Changes {
                edits: c.edits.clone(),
                footprints: self.footprints.clearing(entity, layer.plane, &rect),
            };
            // An edit may bring a point of a later class into the wanted ones.
            let last = last.filter(|_| !changes.reclasses());
            let scaled = shown.generator.scaled(c.factor, last);
            // A chunk over the point budget shows nothing (the query was refused).
            let Ok(mut points) = shown.generator.points(rect, &scaled, &changes) else {
                continue;
            };
            points.retain(|p| filter.wants(p.class));
            out.append(&mut points);
        }
        out
    }

    /// The instance of `p` as drawn.
    fn instance(
        &self,
        entity: Entity,
        layer: &ScatterLayer,
        shown: &ShownLayer,
        p: &Point,
    ) -> ScatterHit {
        ScatterHit {
            layer: entity,
            class: p.class,
            id: p.id,
            transform: layer.place(p, &shown.generator.ground),
            distance: 0.0,
        }
    }
}

/// Each class's bounds at scale 1.
struct ClassBounds(Vec<(Vec3, Vec3)>);

impl ClassBounds {
    /// A unit box standing on the ground: the bounds of a class without mesh or pick bounds.
    const UNIT: (Vec3, Vec3) = (Vec3::new(-0.5, 0.0, -0.5), Vec3::new(0.5, 1.0, 0.5));

    /// The bounds of `layer`'s classes: their pick bounds, else their looks' (`look_bounds`),
    /// else a unit box.
    fn of(layer: &ScatterLayer, look_bounds: impl Fn(&ClassLook) -> Option<(Vec3, Vec3)>) -> Self {
        let bounds = layer.classes.iter().map(|class| {
            class
                .pick_bounds
                .or_else(|| look_bounds(&class.look))
                .unwrap_or(Self::UNIT)
        });
        Self(bounds.collect())
    }

    /// How far an instance can reach on the ground from its point.
    fn reach(&self, layer: &ScatterLayer) -> f64 {
        let per_class = self.0.iter().zip(&layer.classes).map(|((lo, hi), class)| {
            let scale = class.scale.abs() * (1.0 + class.scale_variation.abs());
            (lo.abs().max(hi.abs()).length() * scale) as f64
        });
        per_class.fold(0.0, f64::max)
    }

    /// Where `ray` enters the bounds of an instance of `class` placed by `transform`,
    /// within `max` along it.
    fn enter(&self, ray: Ray3d, transform: &Transform, class: u16, max: f32) -> Option<f32> {
        let (lo, hi) = self.0.get(class as usize).copied().unwrap_or(Self::UNIT);
        let inverse = transform.compute_affine().inverse();
        let origin = inverse.transform_point3(ray.origin);
        let direction = inverse.transform_vector3(*ray.direction);
        let (mut near, mut far) = (0.0f32, max);
        for axis in 0..3 {
            let (o, d) = (origin[axis], direction[axis]);
            if d.abs() < 1e-12 {
                if o < lo[axis] || o > hi[axis] {
                    return None;
                }
                continue;
            }
            let (a, b) = ((lo[axis] - o) / d, (hi[axis] - o) / d);
            near = near.max(a.min(b));
            far = far.min(a.max(b));
            if near > far {
                return None;
            }
        }
        Some(near)
    }
}

/// The ray's path over the ground from its origin to `length` along it (plane coordinates).
fn ground_segment(ray: Ray3d, length: f32, plane: GroundPlane) -> (DVec2, DVec2) {
    let end = ray.origin + *ray.direction * length;
    let flat = |v: Vec3| plane.ground_of(v).as_dvec2();
    (flat(ray.origin), flat(end))
}

/// `r` grown by `by` on every side.
fn grow(r: &Rect, by: f64) -> Rect {
    Rect::new(r.min() - DVec2::splat(by), r.max() + DVec2::splat(by)).unwrap_or(*r)
}

/// Whether the segment `a..b` meets the closed rectangle `r` (slabs).
fn segment_meets((a, b): (DVec2, DVec2), r: &Rect) -> bool {
    let d = b - a;
    let (mut near, mut far) = (0.0f64, 1.0f64);
    for axis in 0..2 {
        let (lo, hi) = (r.min()[axis], r.max()[axis]);
        if d[axis].abs() < 1e-300 {
            if a[axis] < lo || a[axis] > hi {
                return false;
            }
            continue;
        }
        let (s, t) = ((lo - a[axis]) / d[axis], (hi - a[axis]) / d[axis]);
        near = near.max(s.min(t));
        far = far.min(s.max(t));
        if near > far {
            return false;
        }
    }
    true
}
