//! Property tests of the query invariants over random rectangles, densities and seeds.

use glam::DVec2;
use proptest::prelude::*;
use rwt_core::density::{Constant, DistanceFalloff, NoiseDensity, NoiseParams, from_fn};
use rwt_core::query::{Point, Rect, Sampler};
use rwt_core::tileset::TileSet;
use std::collections::HashMap;
use std::sync::OnceLock;

fn set() -> &'static TileSet {
    static SET: OnceLock<TileSet> = OnceLock::new();
    SET.get_or_init(TileSet::embedded)
}

fn key(p: &Point) -> (rwt_core::query::PointId, u64, u64) {
    (p.id, p.position.x.to_bits(), p.position.y.to_bits())
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 48, ..ProptestConfig::default() })]

    /// Raising the density anywhere only adds points; no point moves.
    #[test]
    fn monotone(seed in 0u64..1000, x in -50.0f64..50.0, y in -50.0f64..50.0, base in 10.0f64..3000.0, extra in 0.0f64..20000.0, cx in 0.0f64..1.0) {
        let s = Sampler::new(set(), seed);
        let rect = Rect::new(DVec2::new(x, y), DVec2::new(x + 1.5, y + 1.2)).unwrap();
        let low = NoiseDensity::new(NoiseParams { seed: seed as u32, frequency: 0.7, octaves: 3, base: 0.5, amplitude: 0.5, scale: base });
        let bump = DistanceFalloff { inner: Constant(extra), centre: DVec2::new(x + cx * 1.5, y + 0.6), near: 0.1, far: 0.6 };
        let high = rwt_core::density::Sum(low.clone(), bump);
        let (mut a, mut b) = (Vec::new(), Vec::new());
        s.query(rect, &low, &mut a).unwrap();
        s.query(rect, &high, &mut b).unwrap();
        let bigger: HashMap<_, _> = b.iter().map(|p| (p.id, p.position)).collect();
        for p in &a {
            prop_assert_eq!(bigger.get(&p.id), Some(&p.position));
        }
    }

    /// Any split of a rectangle into two pieces gives exactly the whole.
    #[test]
    fn chunk_union(seed in 0u64..1000, x in -1.0e4f64..1.0e4, y in -1.0e4f64..1.0e4, w in 0.1f64..3.0, h in 0.1f64..3.0, cut in 0.0f64..1.0, d in 1.0f64..40000.0, tile in 0.25f64..4.0) {
        let s = Sampler::new(set(), seed).with_tile_size(tile);
        let whole = Rect::new(DVec2::new(x, y), DVec2::new(x + w, y + h)).unwrap();
        let mid = x + cut * w;
        let left = Rect::new(whole.min(), DVec2::new(mid, y + h)).unwrap();
        let right = Rect::new(DVec2::new(mid, y), whole.max()).unwrap();
        let density = Constant(d / (tile * tile).max(1.0));
        let (mut all, mut parts) = (Vec::new(), Vec::new());
        s.query(whole, &density, &mut all).unwrap();
        s.query(left, &density, &mut parts).unwrap();
        s.query(right, &density, &mut parts).unwrap();
        let mut a: Vec<_> = all.iter().map(key).collect();
        let mut b: Vec<_> = parts.iter().map(key).collect();
        a.sort();
        b.sort();
        prop_assert_eq!(a, b);
    }

    /// Same inputs, same output, bit for bit.
    #[test]
    fn deterministic(seed in 0u64..u64::MAX, x in -1.0e6f64..1.0e6, d in 1.0f64..10000.0) {
        let rect = Rect::new(DVec2::new(x, -x), DVec2::new(x + 0.7, -x + 0.7)).unwrap();
        let run = || {
            let mut out = Vec::new();
            Sampler::new(set(), seed).query(rect, &Constant(d), &mut out).unwrap();
            out.iter().map(key).collect::<Vec<_>>()
        };
        prop_assert_eq!(run(), run());
    }

    /// Far from the origin (1e7 units) points stay inside, distinct and spaced.
    #[test]
    fn exact_far_away(seed in 0u64..1000, dx in 0.0f64..1.0, dy in 0.0f64..1.0) {
        let far = DVec2::new(1.0e7 + dx, -1.0e7 + dy);
        let rect = Rect::new(far, far + DVec2::splat(0.5)).unwrap();
        let mut out = Vec::new();
        Sampler::new(set(), seed).query(rect, &Constant(20000.0), &mut out).unwrap();
        prop_assert!(out.len() > 4000);
        prop_assert!(out.iter().all(|p| rect.contains(p.position)));
        let pts: Vec<DVec2> = out.iter().map(|p| p.position).collect();
        let rho = rwt_core::analysis::rho(&pts, 20000.0).unwrap();
        prop_assert!(rho > 0.4, "rho {}", rho);
    }

    /// No input panics: any rectangle (finite or not) and any density value.
    #[test]
    fn never_panics(a in proptest::num::f64::ANY, b in proptest::num::f64::ANY, c in proptest::num::f64::ANY, e in proptest::num::f64::ANY, v in proptest::num::f64::ANY, budget in 0usize..100000) {
        let s = Sampler::new(set(), 1).with_budget(budget);
        if let Ok(rect) = Rect::new(DVec2::new(a, b), DVec2::new(c, e)) {
            let _ = s.query(rect, &Constant(v), &mut Vec::new());
            let _ = s.query(rect, &from_fn(move |p: DVec2| v * p.x, v.abs()), &mut Vec::new());
        }
    }
}
