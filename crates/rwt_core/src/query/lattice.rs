//! Where a seed lays the tile lattice over the world.
//!
//! A seed picks the Wang tiling (which tile lies where) and each base tile's rank offset.
//! With the lattice alone, every seed would put its tiles on one grid: the tiles' points
//! would sit at the same places modulo the tile for every seed, and whatever structure the
//! tiles share at their period (their seams, the order their first points come in) would
//! line up between seeds, so that counts in strips of two seeds correlate. So
//! [`Lattice::Seeded`] turns the whole tiling by an angle and moves it by an offset, both
//! hashed from the seed: the angle is one of a quarter turn's, plus 12 to 78 degrees, and a
//! mirror image or not, so that two seeds share no lattice and no lattice direction, and the
//! tiles' period is never along the axes that rectangles and strips are cut along.
//!
//! Angles are those of Pythagorean triples, `cos = (m^2 - n^2) / (m^2 + n^2)` and
//! `sin = 2mn / (m^2 + n^2)`: rational, so every platform computes the same rotation bit for
//! bit (no `sin` or `cos` of a library). A query tests and cuts in world coordinates; a
//! tile's world rectangle is the box of its turned corners, widened by a margin far above
//! the rounding of the map, so it holds every point of the tile: exact subsets and exact
//! unions of rectangles stay as they are.

use super::rect::Rect;
use crate::density::Patch;
use crate::rng::hash_words;
use glam::DVec2;
use serde::{Deserialize, Serialize};

/// Hash stream of the lattice's offset and orientation.
const LATTICE_STREAM: u64 = 0x1a77_1ce5;

/// Margin of a turned tile's world rectangle, relative to its coordinates: the map rounds
/// a few times 1e-16 of them.
const MARGIN: f64 = 1e-13;

/// How a [`Sampler`](super::Sampler)'s seed places its tiling in the world.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[cfg_attr(feature = "bevy_reflect", derive(bevy_reflect::Reflect))]
pub enum Lattice {
    /// Turned, mirrored or not, and moved by an offset, all hashed from the seed: two
    /// seeds share no lattice, and give independent point sets.
    #[default]
    Seeded,
    /// Tile corners on multiples of the tile size, unturned, whatever the seed: the place
    /// of every point set of format 1 (edits files and layer files written before seeded
    /// lattices). Seeds then differ in their tiles and ranks only: their points coincide
    /// modulo the tile, and counts in strips correlate between seeds.
    Aligned,
}

impl std::fmt::Display for Lattice {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Lattice::Seeded => "seeded",
            Lattice::Aligned => "aligned",
        })
    }
}

/// The map from the tiling's frame (lattice coordinates times the tile size) to the world:
/// `world = x_axis * q.x + y_axis * q.y + offset`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Placement {
    /// Where the frame's x axis points in the world (a unit vector).
    x_axis: DVec2,
    /// Where the frame's y axis points (a unit vector across `x_axis`).
    y_axis: DVec2,
    /// The offset in world units.
    offset: DVec2,
    /// Margin of mapped rectangles and slack of the inverse map, relative to their
    /// coordinates (0 for the aligned lattice, whose map is exact).
    margin: f64,
}

impl Placement {
    /// The placement of `lattice` for `seed`, with base tiles `tile_size` wide.
    pub fn new(lattice: Lattice, seed: u64, tile_size: f64) -> Self {
        if lattice == Lattice::Aligned {
            return Self {
                x_axis: DVec2::X,
                y_axis: DVec2::Y,
                offset: DVec2::ZERO,
                margin: 0.0,
            };
        }
        let word = |k: u64| hash_words(seed ^ LATTICE_STREAM, &[k]);
        // tan(angle / 2) = n / m, from tan 6 to tan 39 degrees: 12 to 78 degrees.
        let m = 16 + word(0) % 48;
        let (lo, hi) = (m.div_ceil(9), m * 81 / 100);
        let n = lo + word(1) % (hi - lo + 1);
        let (m2, n2) = ((m * m) as f64, (n * n) as f64);
        let mut x_axis = DVec2::new((m2 - n2) / (m2 + n2), (2 * m * n) as f64 / (m2 + n2));
        let turns = word(2);
        for _ in 0..turns % 4 {
            x_axis = x_axis.perp();
        }
        let mirror = if turns >> 2 & 1 == 1 { -1.0 } else { 1.0 };
        let unit = |k: u64| crate::rng::unit_f64(word(k));
        Self {
            x_axis,
            y_axis: x_axis.perp() * mirror,
            offset: DVec2::new(unit(3), unit(4)) * tile_size,
            margin: MARGIN,
        }
    }

    /// The world position of `q`, a point of the tiling's frame.
    #[inline(always)]
    pub fn world(&self, q: DVec2) -> DVec2 {
        self.x_axis * q.x + self.y_axis * q.y + self.offset
    }

    /// A world rectangle holding the world position of every point of the frame's
    /// rectangle `[min, max]`, as its points' positions are computed.
    #[inline]
    pub fn world_rect(&self, min: DVec2, max: DVec2) -> Rect {
        let (lo, hi) = corner_box(min, max, |p| self.world(p));
        let e = self.rounding(min, max);
        Rect::from_ordered(lo - e, hi + e)
    }

    /// The world patch of the frame's rectangle `[min, max]`: its world rectangle, and the
    /// turned rectangle itself, widened by the map's rounding.
    pub fn world_patch(&self, min: DVec2, max: DVec2) -> Patch {
        let rect = self.world_rect(min, max);
        // A point's position is off by at most `e` per coordinate: `sqrt(2) e` in all.
        let e = 2.0 * self.rounding(min, max);
        let half = (max - min) * 0.5;
        Patch {
            min: rect.min(),
            max: rect.max(),
            centre: self.world(min + half),
            u: self.x_axis * (half.x + e),
            v: self.y_axis * (half.y + e),
        }
    }

    /// How far the map may move a point of the frame's rectangle `[min, max]` off its
    /// place, per world coordinate, and more.
    #[inline]
    fn rounding(&self, min: DVec2, max: DVec2) -> f64 {
        // The map's rounding follows the frame's coordinates and the offset (its two terms
        // may cancel to a world coordinate far smaller than either).
        let scale = min.abs().max(max.abs()).max_element() + self.offset.max_element();
        self.margin * scale
    }

    /// The base tiles `[i0, i1) x [j0, j1)` of side `s` whose points may lie in `rect`: the
    /// box of the inverse map's corners, widened by its rounding.
    pub fn tile_range(&self, rect: &Rect, s: f64) -> [i64; 4] {
        let back = |p: DVec2| {
            let d = p - self.offset;
            DVec2::new(self.x_axis.dot(d), self.y_axis.dot(d)) / s
        };
        let (lo, hi) = corner_box(rect.min(), rect.max(), back);
        let slack = |v: f64| self.margin * (v.abs() + 1.0);
        [
            (lo.x - slack(lo.x)).floor() as i64,
            (hi.x + slack(hi.x)).ceil() as i64,
            (lo.y - slack(lo.y)).floor() as i64,
            (hi.y + slack(hi.y)).ceil() as i64,
        ]
    }
}

/// The box of the four corners of the rectangle `[min, max]` mapped by `map`.
#[inline]
fn corner_box(min: DVec2, max: DVec2, map: impl Fn(DVec2) -> DVec2) -> (DVec2, DVec2) {
    let corners = [min, max, DVec2::new(min.x, max.y), DVec2::new(max.x, min.y)].map(map);
    corners[1..]
        .iter()
        .fold((corners[0], corners[0]), |(lo, hi), c| {
            (lo.min(*c), hi.max(*c))
        })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn aligned_is_the_identity() {
        let p = Placement::new(Lattice::Aligned, 99, 3.0);
        let q = DVec2::new(-2.5, 7.25);
        assert_eq!(p.world(q), q);
        let r = Rect::new(DVec2::new(-1.0, 2.0), DVec2::new(5.5, 6.0)).unwrap();
        assert_eq!(p.tile_range(&r, 2.0), [-1, 3, 1, 3]);
    }

    #[test]
    fn seeds_take_every_orientation_and_offsets_inside_a_tile() {
        let mut quadrants = std::collections::HashSet::new();
        for seed in 0..256 {
            let p = Placement::new(Lattice::Seeded, seed, 2.0);
            assert!(p.offset.cmpge(DVec2::ZERO).all() && p.offset.cmplt(DVec2::splat(2.0)).all());
            // Unit axes, at right angles, 12 to 78 degrees off the world's axes.
            assert!(
                (p.x_axis.length() - 1.0).abs() < 1e-15 && p.x_axis.dot(p.y_axis).abs() < 1e-15
            );
            let angle = p.x_axis.y.atan2(p.x_axis.x).to_degrees().rem_euclid(90.0);
            assert!((11.9..78.1).contains(&angle), "seed {seed}: {angle}");
            let mirrored = p.x_axis.perp_dot(p.y_axis) < 0.0;
            quadrants.insert((p.x_axis.x > 0.0, p.x_axis.y > 0.0, mirrored));
        }
        assert_eq!(quadrants.len(), 8);
    }

    #[test]
    fn tile_ranges_cover_the_world_rectangle() {
        for seed in 0..32 {
            let p = Placement::new(Lattice::Seeded, seed, 1.5);
            let r = Rect::new(DVec2::new(-3.2, 10.0), DVec2::new(4.1, 12.0)).unwrap();
            let [i0, i1, j0, j1] = p.tile_range(&r, 1.5);
            // Every world point of the rectangle lies in a tile of the range.
            for k in 0..=20 {
                for l in 0..=20 {
                    let w = r.min() + (r.max() - r.min()) * DVec2::new(k as f64, l as f64) / 20.0;
                    let inside = (i0..i1).any(|i| {
                        (j0..j1).any(|j| {
                            let q = DVec2::new(i as f64, j as f64) * 1.5;
                            // The tile's own square, turned: its frame coordinates.
                            let d = w - p.offset;
                            let f = DVec2::new(p.x_axis.dot(d), p.y_axis.dot(d)) - q;
                            f.cmpge(DVec2::splat(-1e-9)).all()
                                && f.cmple(DVec2::splat(1.5 + 1e-9)).all()
                        })
                    });
                    assert!(inside, "seed {seed}: {w} outside {i0}..{i1} x {j0}..{j1}");
                }
            }
        }
    }

    #[test]
    fn far_tiles_hold_their_points_where_the_map_cancels() {
        // Tiles a billion tiles out whose world x is near 0: the two terms of x cancel.
        for seed in 0..32 {
            let p = Placement::new(Lattice::Seeded, seed, 0.75);
            for far in [3e8, -7e8, 1e9] {
                let d = DVec2::new(1e-3, far) - p.offset;
                let q = DVec2::new(p.x_axis.dot(d), p.y_axis.dot(d));
                let min = (q / 0.75).floor() * 0.75;
                let square = p.world_rect(min, min + 0.75);
                for k in 0..64 {
                    let f = DVec2::new((k % 8) as f64, (k / 8) as f64) / 7.0;
                    let w = p.world(min + f * 0.75);
                    let inside = w.cmpge(square.min()).all() && w.cmple(square.max()).all();
                    assert!(inside, "seed {seed}: {w} outside {square:?}");
                }
            }
        }
    }
}
