//! Chunk streaming around viewers, engine-agnostic: which chunks to load and unload, and
//! which instances a re-query adds or removes. The Bevy plugin turns cameras into
//! [`Viewer`]s and the answers into entities; all decisions live here, where they are
//! tested without an engine.
//!
//! Chunks are squares of `chunk_size` world units on the ground plane (x, z in a 3-D world
//! map to this plane's x, y). A chunk owns the points whose position falls inside it,
//! half-open, so neighbouring chunks never share a point.

use crate::query::{Point, PointId, Rect};
use glam::DVec2;
use std::collections::{HashMap, HashSet};

/// Integer coordinates of a chunk: it covers `[x, x + 1) * size` by `[y, y + 1) * size`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[cfg_attr(feature = "bevy_reflect", derive(bevy_reflect::Reflect))]
pub struct ChunkCoord {
    /// Column.
    pub x: i64,
    /// Row.
    pub y: i64,
}

impl ChunkCoord {
    /// The chunk's rectangle; empty for a size that is not finite and positive.
    pub fn rect(&self, size: f64) -> Rect {
        Rect::new(
            DVec2::new(self.x as f64 * size, self.y as f64 * size),
            DVec2::new((self.x + 1) as f64 * size, (self.y + 1) as f64 * size),
        )
        .unwrap_or(Rect::EMPTY)
    }

    /// The chunk whose rectangle contains `p` (the one whose query yields a point at `p`),
    /// for a finite, positive `size` and a finite `p`.
    pub fn containing(p: DVec2, size: f64) -> Self {
        let guess = Self {
            x: (p.x / size).floor() as i64,
            y: (p.y / size).floor() as i64,
        };
        // Division rounds: near a border the guess may be one off; the rectangle decides.
        const AROUND: [(i64, i64); 9] = [
            (0, 0),
            (-1, 0),
            (1, 0),
            (0, -1),
            (0, 1),
            (-1, -1),
            (1, -1),
            (-1, 1),
            (1, 1),
        ];
        AROUND
            .iter()
            .map(|(dx, dy)| Self {
                x: guess.x.saturating_add(*dx),
                y: guess.y.saturating_add(*dy),
            })
            .find(|c| c.rect(size).contains(p))
            .unwrap_or(guess)
    }

    /// Distance from `p` to the nearest point of the chunk (0 inside).
    pub fn distance(&self, size: f64, p: DVec2) -> f64 {
        let r = self.rect(size);
        p.clamp(r.min(), r.max()).distance(p)
    }

    /// Distance to the nearest of `viewers` (infinite without viewers).
    pub fn viewer_distance(&self, size: f64, viewers: &[Viewer]) -> f64 {
        viewers
            .iter()
            .map(|v| self.distance(size, v.position))
            .fold(f64::INFINITY, f64::min)
    }
}

/// `chunks` sorted nearest to a viewer first (ties by coordinate): the order in which
/// chunks are generated, so that the ground around a viewer fills first.
pub fn nearest_first(
    chunks: impl IntoIterator<Item = ChunkCoord>,
    size: f64,
    viewers: &[Viewer],
) -> Vec<ChunkCoord> {
    let mut order: Vec<(f64, ChunkCoord)> = chunks
        .into_iter()
        .map(|c| (c.viewer_distance(size, viewers), c))
        .collect();
    order.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    order.into_iter().map(|(_, c)| c).collect()
}

/// Level of detail by density: full density up to `near` from the nearest viewer, falling
/// linearly to `floor` (a fraction of the full density, 0 for none) at `far`. Approaching
/// only adds points between the existing ones. A floor keeps a sparse remainder out to the
/// load distance: forests on distant hills rather than bare ones.
///
/// The fall-off is quantized into [`Falloff::BANDS`] bands by the chunk's distance: a chunk
/// is generated for a band, and re-generated only when a viewer moves it into another one,
/// so moving a little does not re-query, and every query of a band gives the same content.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "bevy_reflect", derive(bevy_reflect::Reflect))]
pub struct Falloff {
    /// Distance up to which the density is full.
    pub near: f64,
    /// Distance from which the density is `floor`.
    pub far: f64,
    /// Fraction of the full density kept beyond `far` (0 to 1).
    pub floor: f64,
}

impl Falloff {
    /// Bands between `near` and `far`.
    pub const BANDS: f64 = 8.0;

    /// Full density to `near`, none from `far` on.
    pub fn new(near: f64, far: f64) -> Self {
        Self {
            near,
            far,
            floor: 0.0,
        }
    }

    /// Keeps `floor` (a fraction, clamped to 0..1) of the full density beyond `far`.
    pub fn with_floor(mut self, floor: f64) -> Self {
        self.floor = if floor.is_finite() {
            floor.clamp(0.0, 1.0)
        } else {
            0.0
        };
        self
    }

    /// Width of a band (never zero).
    fn step(&self) -> f64 {
        ((self.far - self.near) / Self::BANDS).max(1e-6)
    }

    /// The band of a chunk at `distance` from the nearest viewer: 0 within `near`, and no
    /// higher than the first band at the floor (farther chunks keep their content).
    pub fn band(&self, distance: f64) -> i64 {
        let band = ((distance - self.near).max(0.0) / self.step())
            .floor()
            .min(1e6) as i64;
        band.min(self.floor_band())
    }

    /// The first band whose linear factor is at or below the floor.
    fn floor_band(&self) -> i64 {
        let span = (self.far - self.near).max(1e-6);
        ((1.0 - self.floor.clamp(0.0, 1.0)) * span / self.step())
            .ceil()
            .clamp(0.0, 1e6) as i64
    }

    /// The density factor of a band: 1 for band 0, falling linearly to the floor at `far`.
    /// Lower bands (nearer) have higher factors, so approaching only adds points.
    pub fn factor(&self, band: i64) -> f64 {
        let linear = 1.0 - band as f64 * self.step() / (self.far - self.near).max(1e-6);
        linear.max(self.floor).clamp(0.0, 1.0)
    }

    /// The band of `chunk` for `viewers`.
    pub fn chunk_band(&self, chunk: ChunkCoord, size: f64, viewers: &[Viewer]) -> i64 {
        self.band(chunk.viewer_distance(size, viewers))
    }
}

/// What a viewer sees of the ground: a position and, optionally, the ground-plane footprint
/// of its view frustum (a convex polygon). Chunks are loaded within the load distance and,
/// when a footprint is given, only where they overlap it (or lie close to the viewer, so
/// turning around never shows an empty ground).
#[derive(Clone, Debug, PartialEq)]
pub struct Viewer {
    /// Position on the ground plane.
    pub position: DVec2,
    /// Convex ground footprint of the view, counter-clockwise, or empty for all directions.
    pub footprint: Vec<DVec2>,
}

impl Viewer {
    /// A viewer that sees in every direction.
    pub fn omni(position: DVec2) -> Self {
        Self {
            position,
            footprint: Vec::new(),
        }
    }
}

/// Distances that decide what is loaded. `unload_distance > load_distance` gives hysteresis:
/// a viewer moving back and forth across the load boundary does not reload chunks.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "bevy_reflect", derive(bevy_reflect::Reflect))]
pub struct StreamingConfig {
    /// Chunk side in world units.
    pub chunk_size: f64,
    /// Chunks closer than this to a viewer (and in its footprint) are loaded.
    pub load_distance: f64,
    /// Loaded chunks farther than this from every viewer are unloaded.
    pub unload_distance: f64,
    /// Chunks this close are loaded whatever the footprint.
    pub near_distance: f64,
}

impl Default for StreamingConfig {
    fn default() -> Self {
        Self {
            chunk_size: 32.0,
            load_distance: 256.0,
            unload_distance: 320.0,
            near_distance: 48.0,
        }
    }
}

/// Chunks to start loading and to unload after an update.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ChunkChanges {
    /// Newly wanted chunks, nearest to a viewer first.
    pub load: Vec<ChunkCoord>,
    /// Chunks no viewer needs any more.
    pub unload: Vec<ChunkCoord>,
}

/// Largest load distance, in chunks: farther requests are served to this distance (a disc
/// of about 200 000 chunks per viewer), so that no configuration can exhaust memory.
pub const MAX_REACH_CHUNKS: f64 = 256.0;

/// Tracks the loaded chunks of one layer.
#[derive(Clone, Debug, Default)]
pub struct ChunkSet {
    loaded: HashSet<ChunkCoord>,
}

fn overlaps_convex(rect: &Rect, polygon: &[DVec2]) -> bool {
    if polygon.len() < 3 {
        return true;
    }
    // Separating axis test: the rectangle's axes and the polygon's edge normals.
    let corners = [
        rect.min(),
        DVec2::new(rect.max().x, rect.min().y),
        rect.max(),
        DVec2::new(rect.min().x, rect.max().y),
    ];
    let (mut lo, mut hi) = (polygon[0], polygon[0]);
    for &p in polygon {
        lo = lo.min(p);
        hi = hi.max(p);
    }
    let (min, max) = (rect.min(), rect.max());
    if hi.x < min.x || lo.x > max.x || hi.y < min.y || lo.y > max.y {
        return false;
    }
    for i in 0..polygon.len() {
        let a = polygon[i];
        let b = polygon[(i + 1) % polygon.len()];
        let normal = DVec2::new(b.y - a.y, a.x - b.x);
        let limit = normal.dot(a);
        // Outward normal for a counter-clockwise polygon: all corners outside means apart.
        if corners.iter().all(|c| normal.dot(*c) > limit) {
            return false;
        }
    }
    true
}

impl ChunkSet {
    /// Chunks currently loaded.
    pub fn loaded(&self) -> &HashSet<ChunkCoord> {
        &self.loaded
    }

    /// Updates the loaded set for `viewers`; returns what changed. Loads are sorted by
    /// distance to the nearest viewer so the nearest ground fills first.
    pub fn update(&mut self, config: &StreamingConfig, viewers: &[Viewer]) -> ChunkChanges {
        let size = config.chunk_size;
        let mut wanted: HashMap<ChunkCoord, f64> = HashMap::new();
        if size.is_finite() && size > 0.0 {
            for v in viewers {
                if !v.position.is_finite() {
                    continue;
                }
                let reach = config.load_distance.max(0.0).min(MAX_REACH_CHUNKS * size);
                let (x0, x1) = (
                    ((v.position.x - reach) / size).floor() as i64,
                    ((v.position.x + reach) / size).floor() as i64,
                );
                let (y0, y1) = (
                    ((v.position.y - reach) / size).floor() as i64,
                    ((v.position.y + reach) / size).floor() as i64,
                );
                for y in y0..=y1 {
                    for x in x0..=x1 {
                        let c = ChunkCoord { x, y };
                        let d = c.distance(size, v.position);
                        if d > reach {
                            continue;
                        }
                        if d > config.near_distance && !overlaps_convex(&c.rect(size), &v.footprint)
                        {
                            continue;
                        }
                        let slot = wanted.entry(c).or_insert(f64::INFINITY);
                        *slot = slot.min(d);
                    }
                }
            }
        }
        let mut load: Vec<(f64, ChunkCoord)> = wanted
            .iter()
            .filter(|(c, _)| !self.loaded.contains(c))
            .map(|(c, d)| (*d, *c))
            .collect();
        load.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        let keep = |c: &ChunkCoord| {
            wanted.contains_key(c)
                || viewers.iter().any(|v| {
                    v.position.is_finite() && c.distance(size, v.position) <= config.unload_distance
                })
        };
        let mut unload: Vec<ChunkCoord> =
            self.loaded.iter().filter(|c| !keep(c)).copied().collect();
        unload.sort();
        for c in &unload {
            self.loaded.remove(c);
        }
        for (_, c) in &load {
            self.loaded.insert(*c);
        }
        ChunkChanges {
            load: load.into_iter().map(|(_, c)| c).collect(),
            unload,
        }
    }
}

/// Instances a re-query adds and removes, by identity and class: existing instances never
/// move, and a point whose class changed (a repainted class map) is replaced.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct InstanceDiff {
    /// Points that are new, or shown with another class.
    pub added: Vec<Point>,
    /// Identities that are gone, or shown with another class now.
    pub removed: Vec<PointId>,
}

/// Compares what a chunk shows (identity and class of each instance) with a fresh query
/// result.
pub fn diff_instances(
    current: impl IntoIterator<Item = (PointId, u16)>,
    fresh: &[Point],
) -> InstanceDiff {
    let current: HashSet<(PointId, u16)> = current.into_iter().collect();
    let fresh_set: HashSet<(PointId, u16)> = fresh.iter().map(|p| (p.id, p.class)).collect();
    let mut removed: Vec<PointId> = current.difference(&fresh_set).map(|(id, _)| *id).collect();
    removed.sort();
    InstanceDiff {
        added: fresh
            .iter()
            .filter(|p| !current.contains(&(p.id, p.class)))
            .copied()
            .collect(),
        removed,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::density::{Constant, DistanceFalloff};
    use crate::query::Sampler;
    use crate::tileset::TileSet;

    #[test]
    fn every_point_lies_in_the_chunk_said_to_contain_it() {
        for size in [10.0, 0.3, 7.77, 1e-3] {
            let border = |k: f64| k * size;
            let hard = [-3.0, -1.0, 0.0, 1.0, 2.0, 1e6].map(border);
            let nudged = hard.iter().flat_map(|&v| [v.next_down(), v, v.next_up()]);
            let xs: Vec<f64> = nudged.chain([0.5 * size, -0.25 * size]).collect();
            for &x in &xs {
                for &y in &xs {
                    let p = DVec2::new(x, y);
                    let c = ChunkCoord::containing(p, size);
                    assert!(c.rect(size).contains(p), "{size} {p} {c:?}");
                }
            }
        }
    }

    fn config() -> StreamingConfig {
        StreamingConfig {
            chunk_size: 10.0,
            load_distance: 30.0,
            unload_distance: 40.0,
            near_distance: 12.0,
        }
    }

    #[test]
    fn loads_around_the_viewer_and_unloads_with_hysteresis() {
        let mut set = ChunkSet::default();
        let c = config();
        let first = set.update(&c, &[Viewer::omni(DVec2::ZERO)]);
        assert!(first.unload.is_empty());
        assert!(
            first.load.len() > 20 && first.load.len() < 50,
            "{}",
            first.load.len()
        );
        assert!(
            first.load[0].distance(10.0, DVec2::ZERO) == 0.0,
            "nearest first"
        );
        // A small step loads a few chunks and unloads none (hysteresis).
        let step = set.update(&c, &[Viewer::omni(DVec2::new(6.0, 0.0))]);
        assert!(step.unload.is_empty());
        // Stepping back loads nothing new and still unloads nothing.
        let back = set.update(&c, &[Viewer::omni(DVec2::ZERO)]);
        assert!(back.load.is_empty() && back.unload.is_empty());
        // Far away: everything old goes.
        let far = set.update(&c, &[Viewer::omni(DVec2::new(500.0, 0.0))]);
        assert_eq!(far.unload.len(), first.load.len() + step.load.len());
        assert!(
            set.loaded()
                .iter()
                .all(|ch| ch.distance(10.0, DVec2::new(500.0, 0.0)) <= 30.0)
        );
    }

    #[test]
    fn footprint_limits_loading_except_near_the_viewer() {
        let c = config();
        // Looking towards +x: a wedge.
        let wedge = vec![DVec2::ZERO, DVec2::new(30.0, -10.0), DVec2::new(30.0, 10.0)];
        let mut set = ChunkSet::default();
        let changes = set.update(
            &c,
            &[Viewer {
                position: DVec2::ZERO,
                footprint: wedge,
            }],
        );
        assert!(
            changes.load.iter().all(|ch| ch.x >= -2),
            "{:?}",
            changes.load
        );
        assert!(changes.load.iter().any(|ch| ch.x == 2));
        assert!(
            changes.load.iter().any(|ch| ch.x == -1),
            "near chunks load behind the viewer"
        );
        assert!(!changes.load.iter().any(|ch| ch.x == -3));
    }

    #[test]
    fn several_viewers_and_bad_positions() {
        let c = config();
        let mut set = ChunkSet::default();
        let changes = set.update(
            &c,
            &[
                Viewer::omni(DVec2::ZERO),
                Viewer::omni(DVec2::new(200.0, 0.0)),
                Viewer::omni(DVec2::NAN),
            ],
        );
        assert!(changes.load.iter().any(|ch| ch.x == 20));
        assert!(changes.load.iter().any(|ch| ch.x == 0));
        let bad = StreamingConfig {
            chunk_size: 0.0,
            ..c
        };
        assert!(
            ChunkSet::default()
                .update(&bad, &[Viewer::omni(DVec2::ZERO)])
                .load
                .is_empty()
        );
        // An absurd load distance is served to MAX_REACH_CHUNKS chunks, not to exhaustion.
        let far = StreamingConfig {
            load_distance: 1e300,
            unload_distance: f64::INFINITY,
            ..c
        };
        let n = ChunkSet::default()
            .update(&far, &[Viewer::omni(DVec2::ZERO)])
            .load
            .len() as f64;
        let disc = std::f64::consts::PI * (MAX_REACH_CHUNKS + 1.0).powi(2);
        assert!(n > 0.9 * disc && n < 1.1 * disc, "{n} chunks");
    }

    #[test]
    fn falloff_bands_quantize_distance_and_only_add_on_approach() {
        let f = Falloff::new(20.0, 100.0);
        assert_eq!(f.band(0.0), 0);
        assert_eq!(f.band(20.0), 0);
        assert_eq!(f.band(29.9), 0);
        assert_eq!(f.band(30.0), 1);
        assert_eq!(f.factor(0), 1.0);
        assert_eq!(f.factor(8), 0.0);
        assert_eq!(f.factor(1_000), 0.0);
        // Nearer bands never have a lower factor: approaching only adds points.
        let mut last = f64::INFINITY;
        for d in (0..1200).map(|i| i as f64 * 0.1) {
            let factor = f.factor(f.band(d));
            assert!(factor <= last && (0.0..=1.0).contains(&factor));
            last = factor;
        }
        // A chunk's band is the one of its nearest viewer.
        let viewers = [
            Viewer::omni(DVec2::new(500.0, 0.0)),
            Viewer::omni(DVec2::new(-45.0, 5.0)),
        ];
        let chunk = ChunkCoord { x: 0, y: 0 };
        assert_eq!(f.chunk_band(chunk, 10.0, &viewers), f.band(45.0));
        // Degenerate settings stay finite.
        let flat = Falloff::new(50.0, 50.0);
        assert!(flat.factor(flat.band(60.0)).is_finite());
        assert!(
            flat.with_floor(f64::NAN)
                .factor(flat.band(60.0))
                .is_finite()
        );
        assert_eq!(
            nearest_first(
                [ChunkCoord { x: 5, y: 0 }, ChunkCoord { x: 0, y: 0 }],
                10.0,
                &[Viewer::omni(DVec2::ZERO)]
            ),
            [ChunkCoord { x: 0, y: 0 }, ChunkCoord { x: 5, y: 0 }]
        );
    }

    #[test]
    fn a_floor_keeps_a_fraction_of_the_density_to_the_load_distance() {
        let f = Falloff::new(20.0, 100.0).with_floor(0.2);
        assert_eq!(f.factor(f.band(0.0)), 1.0);
        assert!((f.factor(f.band(70.0)) - 0.5).abs() < 0.13);
        // From where the linear fall-off reaches the floor, chunks stay in one band with
        // the floor's factor: moving far away never re-queries them.
        let last = f.band(90.0);
        assert_eq!(f.factor(last), 0.2);
        for d in [90.0, 100.0, 500.0, 1e9] {
            assert_eq!(f.band(d), last, "{d}");
        }
        assert!(f.band(85.0) < last && f.factor(f.band(85.0)) > 0.2);
        // Approaching still only adds.
        let mut before = f64::INFINITY;
        for d in (0..1500).map(|i| i as f64 * 0.1) {
            let factor = f.factor(f.band(d));
            assert!(factor <= before && factor >= 0.2);
            before = factor;
        }
        assert_eq!(Falloff::new(1.0, 2.0).with_floor(7.0).floor, 1.0);
    }

    #[test]
    fn approaching_adds_instances_and_moves_none() {
        // Level of detail by density: far, the chunk holds few instances; nearer, more, and
        // the diff only adds.
        let set = TileSet::embedded();
        let sampler = Sampler::new(&set, 3).with_tile_size(4.0);
        let chunk = ChunkCoord { x: 2, y: 0 };
        let rect = chunk.rect(10.0);
        let lod = |viewer: DVec2| DistanceFalloff {
            inner: Constant(20.0),
            centre: viewer,
            near: 5.0,
            far: 60.0,
        };
        let mut far = Vec::new();
        sampler
            .query(rect, &lod(DVec2::new(-30.0, 0.0)), &mut far)
            .unwrap();
        let mut near = Vec::new();
        sampler
            .query(rect, &lod(DVec2::new(10.0, 0.0)), &mut near)
            .unwrap();
        let d = diff_instances(far.iter().map(|p| (p.id, p.class)), &near);
        assert!(d.removed.is_empty());
        assert_eq!(d.added.len(), near.len() - far.len());
        assert!(far.len() > 50 && near.len() > far.len() + 500);
        // Going back removes exactly the added ones.
        let back = diff_instances(near.iter().map(|p| (p.id, p.class)), &far);
        assert!(back.added.is_empty());
        assert_eq!(back.removed.len(), d.added.len());
        // A point shown with another class is replaced, not kept.
        let mut recoloured = near.clone();
        recoloured[0].class = 1;
        let swap = diff_instances(near.iter().map(|p| (p.id, p.class)), &recoloured);
        assert_eq!(swap.removed, [near[0].id]);
        assert_eq!(swap.added, [recoloured[0]]);
    }
}
