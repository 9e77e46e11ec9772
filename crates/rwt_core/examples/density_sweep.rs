//! Quality of uniform queries across densities, beside dart throwing computed in the same
//! run: the normalized minimum distance (several windows of >= 24 000 points), the
//! low-frequency power of averaged spectra and their worst anisotropy ring, all per multiple
//! of the base tile capacity N.
//!
//! `cargo run --release -p rwt_core --example density_sweep [TILESET.ron]`
//! (`MULT=0.3,4,6` picks the multiples; `MULT=quarter` every quarter octave from 0.3 N to
//! 64 N; the default spans levels 0 to 2). The anisotropy column is the worst ring from the
//! fourth on, in dB (12 spectra averaged, or `WINDOWS=W` for both ours and dart throwing:
//! isotropic noise near -10 log10(W) dB, -10.8 for 12), with the
//! frequency of that ring's strongest cell in cycles per base tile, `(u, v)`.
use glam::DVec2;
use rwt_core::analysis::{Spectrum, reference, rho};
use rwt_core::density::Constant;
use rwt_core::query::{Lattice, Rect, Sampler};

mod probe_args;

fn main() {
    let set = probe_args::tile_set();
    let n = set.points_per_tile as f64;
    let multiples = probe_args::multiples(&[
        0.3, 0.5, 1.0, 1.5, 2.0, 3.0, 4.0, 5.0, 6.0, 8.5, 12.0, 16.0, 24.0, 64.0, 96.0,
    ]);
    // `SEED=S` and `LATTICE=aligned` change the spectra's query (to tell structure from chance).
    let spectrum_seed: u64 = std::env::var("SEED")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(3);
    let spectra: u64 = std::env::var("WINDOWS")
        .ok()
        .and_then(|s| s.parse().ok())
        .filter(|&w| w > 0)
        .unwrap_or(12);
    let lattice = match std::env::var("LATTICE").as_deref() {
        Ok("aligned") => Lattice::Aligned,
        _ => Lattice::Seeded,
    };
    println!(
        "density   rho min (6 windows)   low-frequency power: ours / dart throwing   worst anisotropy ring: ours (at) / dart throwing"
    );
    for m in multiples {
        let density = m * n;
        let side = (24_000.0 / density).sqrt();
        let mut worst = f64::INFINITY;
        for w in 0..6u64 {
            let origin = DVec2::splat(-0.37 * side + w as f64 * 3.1);
            let mut out = Vec::new();
            Sampler::new(&set, 11 + w)
                .query(
                    Rect::new(origin, origin + DVec2::splat(side)).expect("finite"),
                    &Constant(density),
                    &mut out,
                )
                .expect("within budget");
            let pos: Vec<DVec2> = out.iter().map(|p| p.position).collect();
            worst = worst.min(rho(&pos, out.len() as f64 / (side * side)).unwrap_or(0.0));
        }
        // Spectra: `spectra` windows of about 2 500 points each.
        let side = (2_500.0 / density).sqrt();
        let count = (density * side * side) as usize;
        let sampler = Sampler::new(&set, spectrum_seed).with_lattice(lattice);
        let windows: Vec<(DVec2, Vec<DVec2>)> = (0..spectra)
            .map(|w| {
                let origin = DVec2::new(w as f64 * side * 1.37, -(w as f64) * side * 0.71);
                let mut out = Vec::new();
                sampler
                    .query(
                        Rect::new(origin, origin + DVec2::splat(side)).expect("finite"),
                        &Constant(density),
                        &mut out,
                    )
                    .expect("within budget");
                (origin, out.iter().map(|p| p.position).collect())
            })
            .collect();
        let ours = Spectrum::averaged(&windows, side, 96);
        let dart: Vec<(DVec2, Vec<DVec2>)> = (0..spectra)
            .map(|i| {
                (
                    DVec2::ZERO,
                    reference::dart_throwing(DVec2::ZERO, side, count, i),
                )
            })
            .collect();
        let dart = Spectrum::averaged(&dart, side, 96);
        let low = |s: &Spectrum| s.low_frequency_power(side, density, 0.5);
        let (ring, peak) = worst_ring(&ours);
        println!(
            "{m:>6.2} N   {worst:.3}                 {:.3} / {:.3} = {:.2}x          {:.1} dB (r {ring}, {:.2}, {:.2}) / {:.1} dB",
            low(&ours),
            low(&dart),
            low(&ours) / low(&dart),
            ours.max_anisotropy(4),
            peak.x / side,
            peak.y / side,
            dart.max_anisotropy(4),
        );
    }
}

/// The worst anisotropy ring from the fourth on, and its strongest cell's frequency
/// (cycles per window side).
fn worst_ring(s: &Spectrum) -> (usize, DVec2) {
    let ring = (4..s.anisotropy_db.len())
        .filter(|&r| s.anisotropy_db[r].is_finite())
        .max_by(|&a, &b| s.anisotropy_db[a].total_cmp(&s.anisotropy_db[b]))
        .unwrap_or(4);
    let half = (s.size / 2) as f64;
    let mut best = (f64::NEG_INFINITY, DVec2::ZERO);
    for v in 0..s.size {
        for u in 0..s.size {
            let f = DVec2::new(u as f64 - half, v as f64 - half);
            if f.length() as usize == ring && s.power[v * s.size + u] > best.0 {
                best = (s.power[v * s.size + u], f);
            }
        }
    }
    (ring, best.1)
}
