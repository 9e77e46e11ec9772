//! How a layer uses its ground: which surfaces above a point it grows on (its policy, its
//! height and slope filters), how much density each gets (per unit of surface area, not of
//! the plane), and the density the query runs on.

use super::{SharedGround, SurfaceHit, SurfacePolicy};
use bevy::prelude::*;
use glam::DVec2;
use rwt_core::density::{Density, sanitize};
use rwt_core::query::{Point, QueryError, Rect, Sampler};
use std::cell::Cell;

/// The most surface area a unit of plane area counts for (a slope of about 75.5 degrees):
/// steeper surfaces (walls) grow nothing, so the density's bounds stay finite.
pub const MAX_AREA_FACTOR: f32 = 4.0;

/// The surfaces a query found its points on, by point: what packing reads instead of
/// asking the ground again.
pub(crate) type Stands = bevy::platform::collections::HashMap<rwt_core::PointId, (SurfaceHit, f64)>;

/// Salt of the hash that picks one of several surfaces above a point.
const SURFACE_SALT: u64 = 0x5f4c;

/// A ground with a layer's rule for it (thread-safe, cheap to clone): which surfaces grow
/// instances and how much density each gets. [`GroundRule::points`] is blue noise on the
/// ground, with no Bevy app needed:
///
/// ```
/// use bevy::prelude::*;
/// use bevy_rwt::ground::{FunctionGround, GroundRule, GroundSettings};
/// use bevy_rwt::rwt_core::{Rect, Sampler, TileSet, density::Constant};
/// use std::sync::Arc;
///
/// // A 60 degree slope: twice the area of its shadow on the plane.
/// let rise = 60f32.to_radians().tan();
/// let ground = FunctionGround::new(Arc::new(move |p: Vec2| p.x * rise));
/// let rule = GroundRule::new(Arc::new(ground), GroundSettings::default());
/// let sampler = Sampler::new(&TileSet::embedded(), 1).with_tile_size(4.0);
/// let rect = Rect::new([0.0, 0.0].into(), [20.0, 20.0].into()).unwrap();
/// let points = rule.points(&sampler, rect, &[Constant(1.0)]).unwrap();
/// // About one point per square unit of the slope's 800 square units.
/// assert!((points.len() as f64 - 800.0).abs() < 40.0, "{}", points.len());
/// ```
#[derive(Clone)]
pub struct GroundRule {
    /// The ground.
    pub ground: SharedGround,
    policy: SurfacePolicy,
    range: Option<(f32, f32)>,
    /// The steepest slope grown on: the layer's limit, or that of [`MAX_AREA_FACTOR`].
    max_slope: f32,
    per_area: bool,
    seed: u64,
    /// Every point of the plane has exactly one surface, flat and within the filters: the
    /// query needs no ground at all.
    trivial: bool,
}

/// What a layer says about its ground (see the fields of the same names in
/// [`crate::ScatterLayer`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GroundSettings {
    /// Which surfaces above a point grow instances.
    pub policy: SurfacePolicy,
    /// Instances only on surfaces of a height within this range.
    pub range: Option<(f32, f32)>,
    /// Instances only on surfaces of at most this slope (rise over run).
    pub max_slope: Option<f32>,
    /// Whether densities count per unit of surface area (or of the plane).
    pub per_area: bool,
    /// The layer's seed (it hashes which of several surfaces a point grows on).
    pub seed: u64,
}

impl Default for GroundSettings {
    /// The top-most surface, per unit of its area, no filters.
    fn default() -> Self {
        Self {
            policy: SurfacePolicy::TopMost,
            range: None,
            max_slope: None,
            per_area: true,
            seed: 0,
        }
    }
}

impl GroundRule {
    /// The rule `s` on `ground`.
    pub fn new(ground: SharedGround, s: GroundSettings) -> Self {
        let limit = (MAX_AREA_FACTOR * MAX_AREA_FACTOR - 1.0).sqrt();
        let max_slope = s.max_slope.map_or(limit, |m| m.min(limit));
        let all = ground.bounds(Vec2::splat(-f32::MAX), Vec2::splat(f32::MAX));
        let in_range = s
            .range
            .is_none_or(|(lo, hi)| lo <= all.min_height && all.max_height <= hi);
        let trivial = all.covered && all.max_surfaces == 1 && all.max_slope == 0.0 && in_range;
        Self {
            ground,
            policy: s.policy,
            range: s.range,
            max_slope,
            per_area: s.per_area,
            seed: s.seed,
            trivial,
        }
    }

    /// Whether the layer's points need no ground to be chosen (flat ground everywhere,
    /// within the filters).
    pub fn trivial(&self) -> bool {
        self.trivial
    }

    /// The points of `rect` for densities `classes` (per unit of surface area, or of the
    /// plane), on the surfaces the rule grows on; each point's class is picked among the
    /// classes' densities on the ground, as [`Sampler::query_classes`] does on the plane.
    /// The points of the first classes alone are exactly those of the sum of their
    /// densities, and a rectangle's points are the union of its parts'.
    pub fn points<D: Density>(
        &self,
        sampler: &Sampler,
        rect: Rect,
        classes: &[D],
    ) -> Result<Vec<Point>, QueryError> {
        self.query(sampler, rect, classes, None)
    }

    /// [`GroundRule::points`], with the surface each point stands on where the query found
    /// it on its way (the top-most surface): [`GroundRule::stand_in`] reads them instead of
    /// asking the ground again.
    pub(crate) fn points_and_stands<D: Density>(
        &self,
        sampler: &Sampler,
        rect: Rect,
        classes: &[D],
    ) -> Result<(Vec<Point>, Stands), QueryError> {
        let mut stands = Stands::default();
        let points = self.query(sampler, rect, classes, Some(&mut stands))?;
        Ok((points, stands))
    }

    fn query<D: Density>(
        &self,
        sampler: &Sampler,
        rect: Rect,
        classes: &[D],
        mut stands: Option<&mut Stands>,
    ) -> Result<Vec<Point>, QueryError> {
        let mut out = Vec::new();
        if self.trivial {
            sampler.query_classes(rect, classes, |p| out.push(p))?;
            return Ok(out);
        }
        let on_ground = OnGround::new(classes, self);
        sampler.query_with(rect, &on_ground, |mut p| {
            p.class = on_ground.class_of(&p);
            if let (Some(stands), (_, area, Some(hit))) = (stands.as_mut(), on_ground.last.get()) {
                stands.insert(p.id, (hit, area));
            }
            out.push(p);
        })?;
        Ok(out)
    }

    /// [`GroundRule::stand`], read from `stands` where the query kept it.
    pub(crate) fn stand_in(&self, p: &Point, stands: &Stands) -> Option<(SurfaceHit, f64)> {
        stands.get(&p.id).copied().or_else(|| self.stand(p))
    }

    fn accepts(&self, hit: &SurfaceHit) -> bool {
        hit.normal.y > 0.0
            && hit.slope() <= self.max_slope
            && self
                .range
                .is_none_or(|(lo, hi)| (lo..=hi).contains(&hit.height))
    }

    /// The density weight of an accepted surface.
    fn weight(&self, hit: &SurfaceHit) -> f64 {
        if self.per_area {
            hit.area_factor().min(MAX_AREA_FACTOR) as f64
        } else {
            1.0
        }
    }

    /// How much of the layer's density a point of the plane gets: the summed weights of
    /// the surfaces it grows on there (0 where it grows on none).
    pub(crate) fn area(&self, p: DVec2) -> f64 {
        self.area_and_top(p).0
    }

    /// [`GroundRule::area`], with the surface a top-most layer grows on there.
    fn area_and_top(&self, p: DVec2) -> (f64, Option<SurfaceHit>) {
        let p = p.as_vec2();
        match self.policy {
            SurfacePolicy::TopMost => {
                let top = self.ground.top(p).filter(|h| self.accepts(h));
                (top.map_or(0.0, |h| self.weight(&h)), top)
            }
            SurfacePolicy::Every => {
                let mut sum = 0.0;
                self.open_hits(p, |h| sum += self.weight(&h));
                (sum, None)
            }
        }
    }

    /// Calls `f` with every surface above `p` that the layer grows on, passes its filters
    /// and lies outside every solid: of the surfaces above it, as many face down (entering
    /// a solid from below, as a bridge's underside) as face up (leaving one through its
    /// top). Inside a rock, or a pier under a deck, more face up.
    fn open_hits(&self, p: Vec2, mut f: impl FnMut(SurfaceHit)) {
        const MOST: usize = 16;
        let mut hits = [SurfaceHit::flat(0.0); MOST];
        let mut n = 0;
        self.ground.hits(p, &mut |h| {
            if n < MOST {
                hits[n] = h;
                n += 1;
            }
        });
        let hits = &hits[..n];
        for h in hits.iter().filter(|h| h.grows && self.accepts(h)) {
            let winding: i32 = hits
                .iter()
                .filter(|o| o.height > h.height)
                .map(|o| (o.normal.y > 0.0) as i32 - (o.normal.y < 0.0) as i32)
                .sum();
            if winding <= 0 {
                f(*h);
            }
        }
    }

    /// An upper bound of [`GroundRule::area`] over the rectangle `min..=max`.
    pub(crate) fn area_bound(&self, min: DVec2, max: DVec2) -> f64 {
        let b = self.ground.bounds(min.as_vec2(), max.as_vec2());
        let outside = self
            .range
            .is_some_and(|(lo, hi)| b.max_height < lo || b.min_height > hi);
        if b.max_surfaces == 0 || outside {
            return 0.0;
        }
        let slope = b.max_slope.min(self.max_slope);
        let each = if self.per_area {
            ((1.0 + slope * slope).sqrt()).min(MAX_AREA_FACTOR) as f64
        } else {
            1.0
        };
        match self.policy {
            SurfacePolicy::TopMost => each,
            SurfacePolicy::Every => each * b.max_surfaces as f64,
        }
    }

    /// The surface point `p` stands on, with the layer's area weight there; `None` where
    /// the layer grows on no surface. Of several surfaces, one is picked by a hash of the
    /// point's identity, weighted by their areas.
    pub fn stand(&self, p: &Point) -> Option<(SurfaceHit, f64)> {
        let at = p.position.as_vec2();
        match self.policy {
            SurfacePolicy::TopMost => {
                let hit = self.ground.top(at).filter(|h| self.accepts(h))?;
                Some((hit, self.weight(&hit)))
            }
            SurfacePolicy::Every => {
                let total = self.area(p.position);
                let mut left = p.id.unit(self.seed, SURFACE_SALT) * total;
                let mut chosen = None;
                self.open_hits(at, |h| {
                    if chosen.is_none() {
                        left -= self.weight(&h);
                        if left < 0.0 {
                            chosen = Some(h);
                        }
                    }
                });
                chosen.map(|h| (h, total))
            }
        }
    }

    /// The surface point `p` stands on.
    pub fn surface(&self, p: &Point) -> Option<SurfaceHit> {
        self.stand(p).map(|(hit, _)| hit)
    }
}

/// The classes' densities on the ground: their sum times [`GroundRule::area`], which a
/// query runs on; [`OnGround::class_of`] then picks each point's class as
/// [`rwt_core::Sampler::query_classes`] does, among the densities on the ground.
struct OnGround<'a, D> {
    classes: &'a [D],
    rule: &'a GroundRule,
    /// The last point's area and surface (a query asks for the density of a point, then
    /// its class).
    last: Cell<(DVec2, f64, Option<SurfaceHit>)>,
}

impl<'a, D: Density> OnGround<'a, D> {
    fn new(classes: &'a [D], rule: &'a GroundRule) -> Self {
        Self {
            classes,
            rule,
            last: Cell::new((DVec2::NAN, 0.0, None)),
        }
    }

    fn area(&self, p: DVec2) -> f64 {
        let (at, area, _) = self.last.get();
        if at == p {
            return area;
        }
        let (area, top) = self.rule.area_and_top(p);
        self.last.set((p, area, top));
        area
    }

    /// The class of a point the query gave: the first whose cumulative density on the
    /// ground exceeds its threshold.
    fn class_of(&self, p: &Point) -> u16 {
        let area = self.area(p.position);
        let mut cumulative = 0.0;
        for (i, c) in self.classes.iter().enumerate() {
            cumulative += sanitize(c.density(p.position)) * area;
            if p.threshold < cumulative {
                return i as u16;
            }
        }
        self.classes.len().saturating_sub(1) as u16
    }
}

impl<D: Density> Density for OnGround<'_, D> {
    fn density(&self, p: DVec2) -> f64 {
        let sum: f64 = self.classes.iter().map(|c| sanitize(c.density(p))).sum();
        if sum <= 0.0 {
            return 0.0;
        }
        sum * self.area(p)
    }

    fn max_over(&self, min: DVec2, max: DVec2) -> f64 {
        let area = self.rule.area_bound(min, max);
        if area <= 0.0 {
            return 0.0;
        }
        let sum: f64 = self.classes.iter().map(|c| c.max_over(min, max)).sum();
        sum * area
    }
}
