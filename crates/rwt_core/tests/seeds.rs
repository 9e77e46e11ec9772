//! Seeds give independent point sets: each seed lays its own lattice (a hashed angle,
//! mirror image and offset), so two seeds' points neither coincide modulo the tile nor count alike in
//! strips. Measured beside two white-noise sets of the same sizes (the independent
//! reference) and beside the aligned lattice, where every seed shares one lattice.

use glam::DVec2;
use rwt_core::density::Constant;
use rwt_core::query::{Lattice, Rect, Sampler};
use rwt_core::rng::Rng;
use rwt_core::tileset::TileSet;
use std::collections::HashSet;
use std::sync::OnceLock;

fn set() -> &'static TileSet {
    static SET: OnceLock<TileSet> = OnceLock::new();
    SET.get_or_init(TileSet::embedded)
}

/// Tiles on a side of the measured square (tiles are 1 unit wide).
const SIDE: f64 = 48.0;
/// Strips per tile of the strip counts.
const STRIPS_PER_TILE: usize = 8;
/// Points per unit area: a few per tile's base points, where the base tiles' own points
/// (the ones seeds share on one lattice) are half of the set.
const DENSITY: f64 = 64.0;

fn points(seed: u64, lattice: Lattice) -> Vec<DVec2> {
    let sampler = Sampler::new(set(), seed).with_lattice(lattice);
    let rect = Rect::new(DVec2::ZERO, DVec2::splat(SIDE)).unwrap();
    let mut out = Vec::new();
    sampler.query(rect, &Constant(DENSITY), &mut out).unwrap();
    out.iter().map(|p| p.position).collect()
}

/// `n` uniform random points of the square.
fn white(n: usize, stream: u64) -> Vec<DVec2> {
    let mut rng = Rng::new(99, stream);
    (0..n)
        .map(|_| DVec2::new(rng.next_f64(), rng.next_f64()) * SIDE)
        .collect()
}

/// Points per strip of the square along x, and along y (both directions, each strip
/// `1 / STRIPS_PER_TILE` tiles wide).
fn strip_counts(points: &[DVec2]) -> Vec<f64> {
    let strips = SIDE as usize * STRIPS_PER_TILE;
    let mut counts = vec![0.0; 2 * strips];
    for p in points {
        let s = (p * STRIPS_PER_TILE as f64).as_uvec2();
        counts[(s.x as usize).min(strips - 1)] += 1.0;
        counts[strips + (s.y as usize).min(strips - 1)] += 1.0;
    }
    counts
}

/// Pearson correlation of two equally long series.
fn correlation(a: &[f64], b: &[f64]) -> f64 {
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
    let (ma, mb) = (mean(a), mean(b));
    let (mut ab, mut aa, mut bb) = (0.0, 0.0, 0.0);
    for (x, y) in a.iter().zip(b) {
        ab += (x - ma) * (y - mb);
        aa += (x - ma) * (x - ma);
        bb += (y - mb) * (y - mb);
    }
    ab / (aa * bb).sqrt()
}

/// The fraction of `b`'s points that lie within a millionth of a tile of one of `a`'s,
/// both taken modulo the tile.
fn coincidences(a: &[DVec2], b: &[DVec2]) -> f64 {
    const GRID: f64 = 1e6;
    let key = |p: &DVec2| {
        let folded = DVec2::new(p.x.rem_euclid(1.0), p.y.rem_euclid(1.0));
        (folded * GRID).round().as_i64vec2()
    };
    let keys: HashSet<_> = a.iter().map(|p| key(p).to_array()).collect();
    let hit = |p: &DVec2| {
        let k = key(p);
        (-1..=1).any(|dx| (-1..=1).any(|dy| keys.contains(&[k.x + dx, k.y + dy])))
    };
    b.iter().filter(|p| hit(p)).count() as f64 / b.len() as f64
}

/// The worst strip correlation and coincidence fraction over ten pairs of seeds.
fn worst_over_pairs(pair: impl Fn(u64) -> (Vec<DVec2>, Vec<DVec2>)) -> (f64, f64) {
    let (mut corr, mut coincide) = (0.0f64, 0.0f64);
    for k in 0..10 {
        let (a, b) = pair(k);
        corr = corr.max(correlation(&strip_counts(&a), &strip_counts(&b)).abs());
        coincide = coincide.max(coincidences(&a, &b));
    }
    (corr, coincide)
}

#[test]
fn two_seeds_are_as_independent_as_two_white_noise_sets() {
    let seeded = worst_over_pairs(|k| {
        (
            points(2 * k + 1, Lattice::Seeded),
            points(2 * k + 2, Lattice::Seeded),
        )
    });
    let aligned = worst_over_pairs(|k| {
        (
            points(2 * k + 1, Lattice::Aligned),
            points(2 * k + 2, Lattice::Aligned),
        )
    });
    let n = points(1, Lattice::Seeded).len();
    let reference = worst_over_pairs(|k| (white(n, 2 * k), white(n, 2 * k + 1)));
    println!(
        "worst of 10 pairs, {n} points each: strip correlation seeded {:.3} aligned {:.3} \
         white {:.3}; coincident modulo the tile seeded {:.4} aligned {:.4} white {:.4}",
        seeded.0, aligned.0, reference.0, seeded.1, aligned.1, reference.1
    );
    assert!(seeded.0 <= 0.1, "strip counts correlate: {seeded:?}");
    // Independent sets share a point now and then (a few in a million here).
    let chance = reference.1.max(1.0 / n as f64);
    assert!(seeded.1 <= 3.0 * chance, "{seeded:?} against {reference:?}");
    // The measure sees what a shared lattice does.
    assert!(aligned.0 > 0.3 && aligned.1 > 0.5, "{aligned:?}");
}

#[test]
fn the_seeded_lattice_keeps_subsets_unions_and_identities() {
    let sampler = Sampler::new(set(), 5).with_tile_size(3.0);
    let rect = Rect::new(DVec2::new(-20.0, 7.0), DVec2::new(25.0, 40.0)).unwrap();
    let query = |r: Rect, d: f64| {
        let mut out = Vec::new();
        sampler.query(r, &Constant(d), &mut out).unwrap();
        out
    };
    let (sparse, dense) = (query(rect, 2.0), query(rect, 30.0));
    let ids: HashSet<_> = dense.iter().map(|p| p.id).collect();
    assert!(sparse.iter().all(|p| ids.contains(&p.id)), "not a subset");
    // Four pieces of the rectangle give its points, each once.
    let mid = DVec2::new(1.7, 21.3);
    let (lo, hi) = (rect.min(), rect.max());
    let mut pieces = Vec::new();
    for (a, b) in [
        (lo, mid),
        (DVec2::new(mid.x, lo.y), DVec2::new(hi.x, mid.y)),
        (DVec2::new(lo.x, mid.y), DVec2::new(mid.x, hi.y)),
        (mid, hi),
    ] {
        pieces.extend(query(Rect::new(a, b).unwrap(), 30.0));
    }
    let key = |p: &rwt_core::Point| (p.id, p.position.x.to_bits(), p.position.y.to_bits());
    let mut whole: Vec<_> = dense.iter().map(key).collect();
    let mut joined: Vec<_> = pieces.iter().map(key).collect();
    whole.sort();
    joined.sort();
    assert_eq!(whole, joined);
    // Every point lies in its rectangle, where its identity places it, bit for bit.
    for p in &dense {
        assert!(rect.contains(p.position));
        assert_eq!(sampler.locate(&p.id), Some(p.position));
        let tile = sampler.tile_rect(&p.id).unwrap();
        assert!(p.position.cmpge(tile.min()).all() && p.position.cmple(tile.max()).all());
    }
    // The aligned lattice is another placement of the same identities.
    let aligned = sampler.clone().with_lattice(Lattice::Aligned);
    let moved = dense
        .iter()
        .filter(|p| aligned.locate(&p.id) != Some(p.position))
        .count();
    assert!(moved > dense.len() * 9 / 10, "{moved} of {}", dense.len());
}

#[test]
fn the_aligned_lattice_places_points_where_format_1_did() {
    // Format 1's place of point `(level, x, y, index)`: `(x + frac) * side`, where `frac`
    // is the point in its tile and `side` the tile size divided down to its level.
    let tiling = rwt_core::Tiling::new(set(), 9);
    let sampler = Sampler::new(set(), 9)
        .with_tile_size(2.5)
        .with_lattice(Lattice::Aligned);
    let rect = Rect::new(DVec2::new(-7.0, -3.0), DVec2::new(6.0, 9.0)).unwrap();
    let mut points = Vec::new();
    sampler.query(rect, &Constant(3000.0), &mut points).unwrap();
    assert!(points.iter().any(|p| p.id.level >= 1));
    for p in &points {
        let id = p.id;
        let tile = &set().tiles[tiling.tile_at(id.level as u32, id.x, id.y) as usize];
        let [fx, fy] = tile.points[id.index as usize].map(|v| v as f64 / 4_294_967_296.0);
        let side = (0..id.level).fold(2.5, |s, _| s / set().subdivision as f64);
        let old = DVec2::new((id.x as f64 + fx) * side, (id.y as f64 + fy) * side);
        assert_eq!(p.position, old, "{id:?}");
    }
}
