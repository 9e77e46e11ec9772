//! Quality of uniform queries across densities, beside dart throwing computed in the same
//! run: the normalized minimum distance (several windows of >= 24 000 points) and the
//! low-frequency power of averaged spectra, both per multiple of the base tile capacity N.
//!
//! `cargo run --release -p rwt_core --example density_sweep [TILESET.ron]`
//! (`MULT=0.3,4,6` picks the multiples; the default spans levels 0 to 2).
use glam::DVec2;
use rwt_core::analysis::{Spectrum, reference, rho};
use rwt_core::density::Constant;
use rwt_core::query::{Rect, Sampler};
use rwt_core::tileset::TileSet;

fn main() {
    let set = match std::env::args().nth(1) {
        Some(path) => TileSet::from_ron_bytes(&std::fs::read(&path).expect("readable file"))
            .expect("a valid tile set"),
        None => TileSet::embedded(),
    };
    let n = set.points_per_tile as f64;
    let multiples: Vec<f64> = std::env::var("MULT")
        .map(|s| s.split(',').filter_map(|v| v.parse().ok()).collect())
        .unwrap_or(vec![
            0.3, 0.5, 1.0, 1.5, 2.0, 3.0, 4.0, 5.0, 6.0, 8.5, 12.0, 16.0, 24.0, 64.0, 96.0,
        ]);
    println!("density   rho min (6 windows)   low-frequency power: ours / dart throwing");
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
        // Spectra: 12 windows of about 2 500 points each.
        let side = (2_500.0 / density).sqrt();
        let count = (density * side * side) as usize;
        let sampler = Sampler::new(&set, 3);
        let windows: Vec<(DVec2, Vec<DVec2>)> = (0..12)
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
        let dart: Vec<(DVec2, Vec<DVec2>)> = (0..12)
            .map(|i| {
                (
                    DVec2::ZERO,
                    reference::dart_throwing(DVec2::ZERO, side, count, i),
                )
            })
            .collect();
        let dart = Spectrum::averaged(&dart, side, 96);
        let low = |s: &Spectrum| s.low_frequency_power(side, density, 0.5);
        println!(
            "{m:>6} N   {worst:.3}                 {:.3} / {:.3} = {:.2}x",
            low(&ours),
            low(&dart),
            low(&ours) / low(&dart)
        );
    }
}
