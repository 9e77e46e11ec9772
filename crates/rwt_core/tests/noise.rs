//! The noise density against the `noise` crate it wraps: the same values bit for bit, the
//! same decisions from its early-out, and the same query output as the plain fBm with the
//! loosest possible bounds.

use glam::DVec2;
use noise::{Fbm, MultiFractal, NoiseFn, Perlin};
use rwt_core::density::{Density, FnDensity, NoiseDensity, NoiseParams, Patch, sanitize};
use rwt_core::query::{Point, PointId, Rect, Sampler};
use rwt_core::rng::Rng;
use rwt_core::tileset::TileSet;

/// Parameter sets with either sign of amplitude and scale, few and many octaves.
fn params() -> Vec<NoiseParams> {
    let p = |seed, frequency, octaves, base, amplitude, scale| NoiseParams {
        seed,
        frequency,
        octaves,
        base,
        amplitude,
        scale,
    };
    vec![
        p(3, 0.15, 4, 0.5, 0.5, 2_000.0),
        p(11, 0.7, 1, 0.2, 0.9, 900.0),
        p(12345, 0.05, 8, 0.6, -0.7, 1_500.0),
        p(7, 1.3, 16, 0.1, 1.4, 600.0),
        p(1, 0.4, 3, -0.2, 0.5, -800.0),
    ]
}

/// What `NoiseDensity` promises to equal: the `noise` crate's own fBm.
fn plain(params: NoiseParams) -> impl Fn(DVec2) -> f64 {
    let fbm = Fbm::<Perlin>::new(params.seed).set_octaves(params.octaves);
    move |p: DVec2| {
        let q = p * params.frequency;
        params.scale * (params.base + params.amplitude * fbm.get([q.x, q.y])).max(0.0)
    }
}

#[test]
fn values_are_the_noise_crates_fbm_bit_for_bit() {
    let mut rng = Rng::new(40, 1);
    for params in params() {
        let (ours, theirs) = (NoiseDensity::new(params), plain(params));
        for _ in 0..20_000 {
            let p = DVec2::new(rng.next_f64() - 0.5, rng.next_f64() - 0.5) * 2e4;
            assert_eq!(
                ours.density(p).to_bits(),
                theirs(p).to_bits(),
                "{params:?} at {p:?}"
            );
        }
    }
    // Lattice points, zero and negative integers included (the crate's corner rule differs
    // from `floor` at or below zero), at frequency 1.
    let unit = NoiseParams {
        frequency: 1.0,
        ..params()[0]
    };
    let (ours, theirs) = (NoiseDensity::new(unit), plain(unit));
    for i in -6..=6 {
        for j in -6..=6 {
            for p in [
                DVec2::new(i as f64, j as f64),
                DVec2::new(i as f64 * 0.5, j as f64),
            ] {
                assert_eq!(ours.density(p).to_bits(), theirs(p).to_bits(), "at {p:?}");
            }
        }
    }
}

#[test]
fn early_decisions_equal_full_evaluation() {
    let mut rng = Rng::new(40, 2);
    for params in params() {
        let d = NoiseDensity::new(params);
        for _ in 0..20_000 {
            let p = DVec2::new(rng.next_f64(), rng.next_f64()) * 300.0;
            let factor = 0.01 + rng.next_f64() * 4.0;
            let value = sanitize(d.density(p)) * factor;
            // Thresholds anywhere, and right at the value and one step either side.
            for threshold in [
                rng.next_f64() * 3_000.0,
                value,
                value.next_up(),
                value.next_down(),
            ] {
                assert_eq!(
                    d.exceeds(p, factor, threshold),
                    value > threshold,
                    "{params:?} at {p:?}, factor {factor}, threshold {threshold}"
                );
                assert_eq!(d.exceeds_near(p, factor, threshold), value > threshold);
            }
        }
    }
}

/// The query of `d`: every point's identity and the bits of its position and threshold.
fn query(sampler: &Sampler, rect: Rect, d: &impl Density) -> Vec<(PointId, [u64; 3])> {
    let mut out: Vec<Point> = Vec::new();
    sampler.query(rect, d, &mut out).unwrap();
    out.iter()
        .map(|p| {
            let bits = [p.position.x, p.position.y, p.threshold].map(f64::to_bits);
            (p.id, bits)
        })
        .collect()
}

#[test]
fn queries_equal_the_plain_fbm_with_the_loosest_bounds() {
    let set = TileSet::embedded();
    let sampler = Sampler::new(&set, 5);
    for params in params() {
        let ours = NoiseDensity::new(params);
        let theirs = plain(params);
        // The density's range, and no lower bound: every open point is evaluated in full.
        let top = params.scale.abs() * (params.base.abs() + params.amplitude.abs());
        let reference = FnDensity::new(theirs, move |_, _| top);
        for (origin, side) in [(-1.7, 3.1), (40.2, 1.3), (-0.25, 0.5)] {
            let rect = Rect::new(DVec2::splat(origin), DVec2::splat(origin + side)).unwrap();
            let (a, b) = (
                query(&sampler, rect, &ours),
                query(&sampler, rect, &reference),
            );
            assert!(!a.is_empty() || params.scale < 0.0, "{params:?}: no points");
            assert_eq!(a, b, "{params:?} over {rect:?}");
        }
    }
}

/// A turned square of side `side` about `centre`, its box clipped on the left by `clip`
/// (a share of the box's width, 0 for none).
fn turned(centre: DVec2, side: f64, angle: f64, clip: f64) -> Patch {
    let u = DVec2::from_angle(angle) * side * 0.5;
    let v = u.perp();
    let reach = u.abs() + v.abs();
    let (min, max) = (centre - reach, centre + reach);
    Patch {
        min: DVec2::new(min.x + (max.x - min.x) * clip, min.y),
        max,
        centre,
        u,
        v,
    }
}

/// Models of squares turned as seeded lattices turn their cells hold the density at every
/// point of the square inside its (clipped) box, and leave narrower bounds than models of
/// the square's whole box, whose corners reach lattice cells the square does not.
#[test]
fn local_models_of_turned_squares_hold_and_bend_less() {
    let mut rng = Rng::new(40, 4);
    for params in params() {
        let d = NoiseDensity::new(params);
        let (mut square_width, mut box_width) = (0.0, 0.0);
        for _ in 0..3_000 {
            let far = [1.0, 1e3, 1e7][rng.below(3)];
            let centre = DVec2::new(rng.next_f64() - 0.5, rng.next_f64() - 0.5) * far;
            let side = 0.3 / params.frequency * 4f64.powf(-3.0 * rng.next_f64());
            let angle = rng.next_f64() * std::f64::consts::TAU;
            let clip = [0.0, 0.0, 0.3, 0.7][rng.below(4)];
            let patch = turned(centre, side, angle, clip);
            let (Some(model), Some(whole)) = (
                d.local_model(&patch),
                d.local_model(&Patch::rect(patch.min, patch.max)),
            ) else {
                continue;
            };
            let (low, high) = model.bounds_over(&patch);
            for _ in 0..40 {
                let (a, b) = (rng.next_f64() * 2.0 - 1.0, rng.next_f64() * 2.0 - 1.0);
                let p = patch.centre + patch.u * a + patch.v * b;
                if p.cmplt(patch.min).any() || p.cmpgt(patch.max).any() {
                    continue;
                }
                let (value, (lo, hi)) = (sanitize(d.density(p)), model.bounds_at(p));
                let (box_lo, box_hi) = whole.bounds_at(p);
                (square_width, box_width) = (square_width + hi - lo, box_width + box_hi - box_lo);
                assert!(
                    lo <= value && value <= hi && low <= lo && hi <= high,
                    "{params:?} over {patch:?} at {p}: {value} not in {lo}..{hi}"
                );
            }
        }
        // 4 to 24 % narrower (1 to 16 octaves); a negative scale gives no models.
        assert!(
            params.scale < 0.0 || square_width < 0.97 * box_width,
            "{params:?}: bounds {square_width} wide over squares, {box_width} over boxes"
        );
    }
}

/// Wherever a noise density gives a local model, the model's bounds hold its value at every
/// point of the rectangle (near the origin and far from it, over cells of many sizes), and
/// small cells almost always get one.
#[test]
fn local_models_bound_the_density() {
    let mut rng = Rng::new(40, 3);
    for params in params() {
        let d = NoiseDensity::new(params);
        let (mut asked, mut given) = (0, 0);
        for _ in 0..4_000 {
            let far = [1.0, 1e3, 1e7][rng.below(3)];
            let min = DVec2::new(rng.next_f64() - 0.5, rng.next_f64() - 0.5) * far;
            let side = 0.3 / params.frequency * 4f64.powf(-3.0 * rng.next_f64());
            let max = min + DVec2::new(side, side * (0.5 + rng.next_f64()));
            asked += 1;
            let patch = Patch::rect(min, max);
            let Some(model) = d.local_model(&patch) else {
                continue;
            };
            given += 1;
            let (low, high) = model.bounds_over(&patch);
            for _ in 0..40 {
                let p = min + (max - min) * DVec2::new(rng.next_f64(), rng.next_f64());
                let (value, (lo, hi)) = (sanitize(d.density(p)), model.bounds_at(p));
                assert!(
                    lo <= value && value <= hi && low <= lo && hi <= high,
                    "{params:?} over {min}..{max} at {p}: {value} not in {lo}..{hi}"
                );
            }
        }
        // Cells a quarter of a noise period wide, 4 octaves and fewer: a model nearly always.
        if params.octaves <= 4 && params.scale > 0.0 {
            let small = asked as f64 * 0.5;
            assert!(given as f64 >= small, "{params:?}: {given} of {asked}");
        }
    }
}
