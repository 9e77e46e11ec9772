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
pub fn merge(
    current: &[SourcedPoint],
    incoming: &[SourcedPoint],
    side: Side,
) -> (Vec<SourcedPoint>, Vec<DVec2>) {
    let union: Vec<SourcedPoint> = current.iter().chain(incoming).copied().collect();
    let seam = seam_path(&union, side);
    let polygon = side_polygon(&seam, side);
    let from_incoming = |p: &SourcedPoint| point_in_polygon(p.pos, &polygon);
    let mut merged: Vec<SourcedPoint> = current
        .iter()
        .filter(|p| !from_incoming(p))
        .copied()
        .collect();
    merged.extend(incoming.iter().filter(|p| from_incoming(p)).copied());
    (merged, seam)
}

/// The region owned by the incoming tile: the seam closed along the side itself.
fn side_polygon(seam: &[DVec2], _side: Side) -> Vec<DVec2> {
    // The seam runs from one corner of the side to the other, so closing the polyline
    // (last -> first) follows the side exactly.
    seam.to_vec()
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

/// Which side of the unit square a boundary point lies on (None for interior points).
fn boundary_side(p: DVec2) -> [Option<Side>; 2] {
    const EPS: f64 = 1e-12;
    let mut sides = [None, None];
    let mut n = 0;
    for (on, s) in [
        (p.y >= 1.0 - EPS, Side::North),
        (p.x >= 1.0 - EPS, Side::East),
        (p.y <= EPS, Side::South),
        (p.x <= EPS, Side::West),
    ] {
        if on && n < 2 {
            sides[n] = Some(s);
            n += 1;
        }
    }
    sides
}

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

/// Liang-Barsky clip of segment `a -> b` to the unit square.
fn clip_unit(a: DVec2, b: DVec2) -> Option<(DVec2, DVec2)> {
    let d = b - a;
    let (mut t0, mut t1) = (0.0f64, 1.0f64);
    for (p, q) in [(-d.x, a.x), (d.x, 1.0 - a.x), (-d.y, a.y), (d.y, 1.0 - a.y)] {
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

/// Computes the min-cost seam between the corners of `side` through the clipped Voronoi
/// diagram of `points` (with a toroidal margin so that cells at the border are bounded).
pub fn seam_path(points: &[SourcedPoint], side: Side) -> Vec<DVec2> {
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
    let Ok(tri) = DelaunayTriangulation::<Site>::bulk_load(sites) else {
        // Degenerate input (cannot happen for blue-noise tiles): fall back to the side itself.
        let (a, b) = side_corners(side);
        return vec![a, b];
    };

    // Graph nodes: Voronoi vertices inside the tile (by face index), clip points, corners.
    let mut nodes: Vec<DVec2> = Vec::new();
    let mut face_node: Vec<Option<usize>> = vec![None; tri.num_all_faces()];
    let mut edges: Vec<(usize, usize, f64)> = Vec::new();
    let mut raw: Vec<(DVec2, DVec2, Option<usize>, Option<usize>, f64)> = Vec::new();
    let mut d_max = 0.0f64;
    for e in tri.undirected_edges() {
        let de = e.as_directed();
        let (Some(f0), Some(f1)) = (de.face().as_inner(), de.rev().face().as_inner()) else {
            continue;
        };
        let [pa, pb] = e.positions();
        let d = DVec2::new(pa.x - pb.x, pa.y - pb.y).length();
        let c0 = f0.circumcenter();
        let c1 = f1.circumcenter();
        let (c0, c1) = (DVec2::new(c0.x, c0.y), DVec2::new(c1.x, c1.y));
        let Some((a, b)) = clip_unit(c0, c1) else {
            continue;
        };
        d_max = d_max.max(d);
        let a_inner = (a == c0).then_some(f0.fix().index());
        let b_inner = (b == c1).then_some(f1.fix().index());
        raw.push((a, b, a_inner, b_inner, d));
    }
    let mut node_at = |p: DVec2, face: Option<usize>, nodes: &mut Vec<DVec2>| -> usize {
        if let Some(f) = face {
            if let Some(n) = face_node[f] {
                return n;
            }
            nodes.push(p);
            face_node[f] = Some(nodes.len() - 1);
            nodes.len() - 1
        } else {
            nodes.push(p);
            nodes.len() - 1
        }
    };
    for &(a, b, fa, fb, d) in &raw {
        let na = node_at(a, fa, &mut nodes);
        let nb = node_at(b, fb, &mut nodes);
        let mut cost = 1.0;
        let base = 1.0 - d / d_max;
        for _ in 0..SEAM_EXPONENT {
            cost *= base;
        }
        edges.push((na, nb, cost));
    }
    // Corners, then boundary segments along every side except the merged one.
    let corners = [
        DVec2::new(0.0, 0.0),
        DVec2::new(1.0, 0.0),
        DVec2::new(1.0, 1.0),
        DVec2::new(0.0, 1.0),
    ];
    let corner_nodes: Vec<usize> = corners
        .iter()
        .map(|&c| {
            nodes.push(c);
            nodes.len() - 1
        })
        .collect();
    for s in Side::ALL {
        if s == side {
            continue;
        }
        let mut on_side: Vec<(f64, usize)> = nodes
            .iter()
            .enumerate()
            .filter(|(_, p)| boundary_side(**p).contains(&Some(s)))
            .map(|(i, p)| (if s.is_horizontal() { p.x } else { p.y }, i))
            .collect();
        on_side.sort_by(|a, b| a.0.total_cmp(&b.0));
        for w in on_side.windows(2) {
            // Running along the tile border separates nothing: make it the worst edge.
            edges.push((w[0].1, w[1].1, 1.0));
        }
    }

    let (start_p, end_p) = side_corners(side);
    let corner_index = |p: DVec2| corner_nodes[corners.iter().position(|&c| c == p).unwrap_or(0)];
    let (start, end) = (corner_index(start_p), corner_index(end_p));
    let mut adjacency: Vec<Vec<(usize, f64)>> = vec![Vec::new(); nodes.len()];
    for &(a, b, c) in &edges {
        if a != b {
            adjacency[a].push((b, c));
            adjacency[b].push((a, c));
        }
    }
    let mut dist = vec![f64::INFINITY; nodes.len()];
    let mut prev = vec![usize::MAX; nodes.len()];
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
        return vec![start_p, end_p];
    }
    let mut path = vec![nodes[end]];
    let mut at = end;
    while at != start {
        at = prev[at];
        path.push(nodes[at]);
    }
    path.reverse();
    path
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;
    use crate::source_tile::DartThrowing;

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
        let (merged, seam) = merge(&t, &e, Side::East);
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
        // About as many points as one source tile.
        let n = merged.len() as f64;
        assert!((n - 400.0).abs() < 40.0, "{n}");
    }
}
