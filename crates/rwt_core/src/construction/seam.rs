//! Merging source tiles along min-cost Voronoi seams (paper section 4, figure 4).
//!
//! To give a Wang tile the points of an edge colour's source tile near that edge, we compute
//! the Voronoi diagram of the union of the current points and the incoming source tile,
//! clip it to the tile, add the corners, weight every Voronoi edge by `(1 - d/d_max)^r`
//! (`d` is the distance between the two points it separates), and take the cheapest path
//! (Dijkstra) between the two corners of the side. Points between the seam and the side come
//! from the incoming tile, the others stay. Because every tile with that edge colour takes
//! the same source points next to that edge, neighbouring tiles continue each other's pattern.

use crate::geometry::point_in_polygon;
use crate::wang::Side;
use glam::DVec2;
use spade::{DelaunayTriangulation, HasPosition, Point2, Triangulation};
use std::cmp::Ordering;
use std::collections::BinaryHeap;

/// Where a point of a Wang tile came from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
pub enum Origin {
    /// The tile's own unique source tile.
    Interior,
    /// The source tile of the colour on this side.
    Edge(Side),
}

/// A point during construction: position in tile coordinates, where it came from, and its
/// rank in its source tile.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SourcedPoint {
    /// Position in `[0, 1)^2`.
    pub pos: DVec2,
    /// Source region.
    pub origin: Origin,
    /// Rank in the source tile's progressive order.
    pub source_rank: u32,
}

/// Seam cost exponent `r` (paper: 10).
pub const SEAM_EXPONENT: i32 = 10;

/// Cost of a seam per point spacing of length. With `r = 10`, edges between well-separated
/// points cost almost nothing, so without a length cost seams wander to the tile centre and
/// leave little of the unique interior that keeps tiles from repeating.
pub const SEAM_LENGTH_COST: f64 = 0.005;

struct Site {
    pos: Point2<f64>,
}

impl HasPosition for Site {
    type Scalar = f64;
    fn position(&self) -> Point2<f64> {
        self.pos
    }
}

/// Merges `incoming` (a full toroidal source tile) into `current` along a seam that joins
/// the two corners of `side`. Returns the merged points and the seam polyline.
///
/// `strip` is the width of the band along every tile edge that seams may not enter except in
/// the corner squares: each edge's band then holds only its own colour's source points,
/// identical in every tile with that colour, so the pattern continues exactly across edges.
pub fn merge(
    current: &[SourcedPoint],
    incoming: &[SourcedPoint],
    side: Side,
    strip: f64,
) -> (Vec<SourcedPoint>, Vec<DVec2>) {
    let union: Vec<SourcedPoint> = current.iter().chain(incoming).copied().collect();
    let seam = seam_path(&union, side, strip);
    // The seam runs from one corner of the side to the other, so the polygon it closes
    // (last point back to the first) is the region between the seam and the side.
    let from_incoming = |p: &SourcedPoint| point_in_polygon(p.pos, &seam);
    let mut merged: Vec<SourcedPoint> = current
        .iter()
        .filter(|p| !from_incoming(p))
        .copied()
        .collect();
    merged.extend(incoming.iter().filter(|p| from_incoming(p)).copied());
    (merged, seam)
}

/// The two corners a side's seam joins, in a fixed order.
fn side_corners(side: Side) -> (DVec2, DVec2) {
    match side {
        Side::North => (DVec2::new(0.0, 1.0), DVec2::new(1.0, 1.0)),
        Side::East => (DVec2::new(1.0, 0.0), DVec2::new(1.0, 1.0)),
        Side::South => (DVec2::new(0.0, 0.0), DVec2::new(1.0, 0.0)),
        Side::West => (DVec2::new(0.0, 0.0), DVec2::new(0.0, 1.0)),
    }
}

/// Clipped Voronoi edges: end points, the faces they come from (None for clip points), and
/// the distance between the two sites they separate.
type ClippedEdge = (DVec2, DVec2, Option<usize>, Option<usize>, f64);

#[derive(PartialEq)]
struct State {
    cost: f64,
    node: usize,
}
impl Eq for State {}
impl Ord for State {
    fn cmp(&self, other: &Self) -> Ordering {
        other
            .cost
            .partial_cmp(&self.cost)
            .unwrap_or(Ordering::Equal)
            .then_with(|| other.node.cmp(&self.node))
    }
}
impl PartialOrd for State {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

/// Liang-Barsky clip of segment `a -> b` to the square `[lo, hi]^2`.
fn clip(a: DVec2, b: DVec2, lo: f64, hi: f64) -> Option<(DVec2, DVec2)> {
    let d = b - a;
    let (mut t0, mut t1) = (0.0f64, 1.0f64);
    for (p, q) in [
        (-d.x, a.x - lo),
        (d.x, hi - a.x),
        (-d.y, a.y - lo),
        (d.y, hi - a.y),
    ] {
        if p == 0.0 {
            if q < 0.0 {
                return None;
            }
        } else {
            let r = q / p;
            if p < 0.0 {
                t0 = t0.max(r);
            } else {
                t1 = t1.min(r);
            }
        }
    }
    (t0 <= t1).then(|| (a + d * t0, a + d * t1))
}

/// Computes the seam between the corners of `side`.
///
/// Inside the square `[strip, 1 - strip]^2` the seam is the min-cost path through the
/// clipped Voronoi diagram of `points` (a toroidal margin keeps border cells bounded).
/// Outside it, the seam is fixed: from each corner it runs along the diagonal to the inner
/// square's corner. So the band along every edge belongs to that edge's source alone, and
/// each corner square is split along its diagonal into two triangles, each owned by the
/// edge it touches. Around a lattice vertex, every pair of triangles that face each other
/// across an edge then comes from that edge's source: no two sources meet across a tile
/// edge anywhere near it, which is what lets neighbouring tiles continue each other.
pub fn seam_path(points: &[SourcedPoint], side: Side, strip: f64) -> Vec<DVec2> {
    let (lo, hi) = (strip, 1.0 - strip);
    let (start_corner, end_corner) = side_corners(side);
    let inner = |c: DVec2| DVec2::new(c.x.clamp(lo, hi), c.y.clamp(lo, hi));
    let (start_in, end_in) = (inner(start_corner), inner(end_corner));
    let fallback = vec![start_corner, start_in, end_in, end_corner];
    let Ok(tri) = DelaunayTriangulation::<Site>::bulk_load(toroidal_sites(points)) else {
        return fallback;
    };
    let spacing = crate::geometry::hex_spacing(points.len() as f64 / 2.0);
    let mut graph = voronoi_graph(&tri, lo, hi, spacing);
    let start = graph.add_corner(start_in, lo, hi, 3.0 * spacing);
    let end = graph.add_corner(end_in, lo, hi, 3.0 * spacing);
    let Some(inner_path) = graph.shortest_path(start, end) else {
        return fallback;
    };
    let mut path = vec![start_corner];
    path.extend(inner_path);
    path.push(end_corner);
    path
}

/// The points and their copies one tile over, within a margin of the tile: a toroidal
/// margin keeps the Voronoi cells at the border bounded.
fn toroidal_sites(points: &[SourcedPoint]) -> Vec<Site> {
    const MARGIN: f64 = 0.12;
    let mut sites = Vec::with_capacity(points.len() * 2);
    for p in points {
        for dx in [-1.0, 0.0, 1.0] {
            for dy in [-1.0, 0.0, 1.0] {
                let q = p.pos + DVec2::new(dx, dy);
                if q.x > -MARGIN && q.x < 1.0 + MARGIN && q.y > -MARGIN && q.y < 1.0 + MARGIN {
                    sites.push(Site {
                        pos: Point2::new(q.x, q.y),
                    });
                }
            }
        }
    }
    sites
}

/// The graph a seam runs on: Voronoi vertices inside the inner square (one node per
/// Delaunay face), clip points on its border, and the inner corners the seam joins.
struct SeamGraph {
    nodes: Vec<DVec2>,
    edges: Vec<(usize, usize, f64)>,
}

/// The Voronoi edges clipped to the inner square `[lo, hi]^2`, each costing
/// `(1 - d/d_max)^r` (`d` the distance between the sites it separates) plus its length.
fn voronoi_graph(tri: &DelaunayTriangulation<Site>, lo: f64, hi: f64, spacing: f64) -> SeamGraph {
    let mut raw: Vec<ClippedEdge> = Vec::new();
    let mut d_max = 0.0f64;
    for e in tri.undirected_edges() {
        let de = e.as_directed();
        let (Some(f0), Some(f1)) = (de.face().as_inner(), de.rev().face().as_inner()) else {
            continue;
        };
        let [pa, pb] = e.positions();
        let d = DVec2::new(pa.x - pb.x, pa.y - pb.y).length();
        let (c0, c1) = (f0.circumcenter(), f1.circumcenter());
        let (c0, c1) = (DVec2::new(c0.x, c0.y), DVec2::new(c1.x, c1.y));
        let Some((a, b)) = clip(c0, c1, lo, hi) else {
            continue;
        };
        d_max = d_max.max(d);
        let a_inner = (a == c0).then_some(f0.fix().index());
        let b_inner = (b == c1).then_some(f1.fix().index());
        raw.push((a, b, a_inner, b_inner, d));
    }
    let mut graph = SeamGraph {
        nodes: Vec::new(),
        edges: Vec::new(),
    };
    let mut face_node: Vec<Option<usize>> = vec![None; tri.num_all_faces()];
    let mut node_at = |p: DVec2, face: Option<usize>, nodes: &mut Vec<DVec2>| -> usize {
        if let Some(f) = face {
            if let Some(n) = face_node[f] {
                return n;
            }
            nodes.push(p);
            face_node[f] = Some(nodes.len() - 1);
        } else {
            nodes.push(p);
        }
        nodes.len() - 1
    };
    for &(a, b, fa, fb, d) in &raw {
        let na = node_at(a, fa, &mut graph.nodes);
        let nb = node_at(b, fb, &mut graph.nodes);
        let mut cost = 1.0;
        let base = 1.0 - d / d_max;
        for _ in 0..SEAM_EXPONENT {
            cost *= base;
        }
        graph
            .edges
            .push((na, nb, cost + SEAM_LENGTH_COST * (b - a).length() / spacing));
    }
    graph
}

impl SeamGraph {
    /// Adds an inner corner of the square. Along the square's border the seam may only hop
    /// from a corner to the first Voronoi edges next to it, within `reach` (a few point
    /// spacings: two hops must never meet, or the seam would skip the diagram); running
    /// along the border separates nothing.
    fn add_corner(&mut self, c: DVec2, lo: f64, hi: f64, reach: f64) -> usize {
        self.nodes.push(c);
        let corner = self.nodes.len() - 1;
        let on_border = |p: DVec2| {
            const EPS: f64 = 1e-12;
            (p.x - lo).abs() < EPS
                || (p.x - hi).abs() < EPS
                || (p.y - lo).abs() < EPS
                || (p.y - hi).abs() < EPS
        };
        let mut hops = Vec::new();
        for (i, &p) in self.nodes.iter().enumerate() {
            let same_line = (p.x - c.x).abs() < 1e-12 || (p.y - c.y).abs() < 1e-12;
            if i != corner && on_border(p) && same_line && (p - c).length() < reach {
                hops.push((corner, i, 1.0));
            }
        }
        self.edges.extend(hops);
        corner
    }

    /// The cheapest path from `start` to `end` (Dijkstra), as node positions.
    fn shortest_path(&self, start: usize, end: usize) -> Option<Vec<DVec2>> {
        let mut adjacency: Vec<Vec<(usize, f64)>> = vec![Vec::new(); self.nodes.len()];
        for &(a, b, c) in &self.edges {
            if a != b {
                adjacency[a].push((b, c));
                adjacency[b].push((a, c));
            }
        }
        let mut dist = vec![f64::INFINITY; self.nodes.len()];
        let mut prev = vec![usize::MAX; self.nodes.len()];
        let mut heap = BinaryHeap::new();
        dist[start] = 0.0;
        heap.push(State {
            cost: 0.0,
            node: start,
        });
        while let Some(State { cost, node }) = heap.pop() {
            if node == end {
                break;
            }
            if cost > dist[node] {
                continue;
            }
            for &(next, c) in &adjacency[node] {
                let nc = cost + c;
                if nc < dist[next] {
                    dist[next] = nc;
                    prev[next] = node;
                    heap.push(State {
                        cost: nc,
                        node: next,
                    });
                }
            }
        }
        if !dist[end].is_finite() {
            return None;
        }
        let mut path = vec![self.nodes[end]];
        let mut at = end;
        while at != start {
            at = prev[at];
            path.push(self.nodes[at]);
        }
        path.reverse();
        Some(path)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dart_throwing::DartThrowing;
    use crate::rng::Rng;

    fn source(seed: u64, origin: Origin) -> Vec<SourcedPoint> {
        DartThrowing::new(400)
            .run(&mut Rng::new(seed, 0))
            .into_iter()
            .enumerate()
            .map(|(i, pos)| SourcedPoint {
                pos,
                origin,
                source_rank: i as u32,
            })
            .collect()
    }

    #[test]
    fn seam_joins_the_corners_of_the_side() {
        let t = source(1, Origin::Interior);
        let e = source(2, Origin::Edge(Side::East));
        let (merged, seam) = merge(&t, &e, Side::East, 0.08);
        assert_eq!(seam.first(), Some(&DVec2::new(1.0, 0.0)));
        assert_eq!(seam.last(), Some(&DVec2::new(1.0, 1.0)));
        let from_edge: Vec<_> = merged
            .iter()
            .filter(|p| p.origin == Origin::Edge(Side::East))
            .collect();
        assert!(!from_edge.is_empty());
        // Incoming points sit on the east side; the interior keeps most of the tile.
        let mean_x = from_edge.iter().map(|p| p.pos.x).sum::<f64>() / from_edge.len() as f64;
        assert!(mean_x > 0.6, "mean x of east points {mean_x}");
        assert!(from_edge.len() < merged.len() / 2);
        // The east band belongs to the east source alone, the other bands to the tile.
        for p in &merged {
            let in_band = |v: f64| v > 0.08 && v < 0.92;
            if p.pos.x > 0.92 && in_band(p.pos.y) {
                assert_eq!(p.origin, Origin::Edge(Side::East), "{p:?}");
            }
            if p.pos.x < 0.08 && in_band(p.pos.y) {
                assert_eq!(p.origin, Origin::Interior, "{p:?}");
            }
        }
        // About as many points as one source tile.
        let n = merged.len() as f64;
        assert!((n - 400.0).abs() < 40.0, "{n}");
    }
}
