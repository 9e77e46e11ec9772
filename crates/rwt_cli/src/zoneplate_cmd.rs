//! `rwt zoneplate`: the paper's anti-aliasing test (figure 9), every pattern in one run.

use image::ExtendedColorType;
use rwt_core::analysis::zoneplate::{Claim, ZonePlate};
use rwt_core::query::Sampler;
use rwt_core::tileset::TileSet;
use std::path::Path;

/// Most pixels on a side (the reference takes 16 samples a pixel).
const MAX_SIZE: usize = 2048;

/// Renders the zone plate with each pattern, prints one line each and the paper's claim
/// checked, and writes the images side by side (reference first) to `out`.
pub fn run(size: usize, seed: u64, out: Option<&Path>) -> Result<(), String> {
    if !(16..=MAX_SIZE).contains(&size) {
        return Err(format!(
            "--size must be between 16 and {MAX_SIZE}, got {size}"
        ));
    }
    let plate = ZonePlate {
        size,
        ..ZonePlate::default()
    };
    let sampler = Sampler::new(&TileSet::embedded(), seed);
    let comparison = plate
        .compare(&sampler, seed, || true)
        .map_err(|e| e.to_string())?;
    for r in &comparison.renderings {
        say!(
            "zoneplate: pattern={} psnr={:.2} low={:.2} high={:.2}",
            r.pattern.name(),
            r.error.psnr,
            r.error.low,
            r.error.high
        );
    }
    say!("{}", claim(comparison.claim()));
    if let Some(path) = out {
        let images: Vec<&[f64]> = std::iter::once(&comparison.reference)
            .chain(comparison.renderings.iter().map(|r| &r.image))
            .map(Vec::as_slice)
            .collect();
        write_strip(path, &images, size)?;
    }
    Ok(())
}

/// The paper's claim beside the figures it compares.
fn claim(claim: Option<Claim>) -> String {
    let Some(c) = claim else {
        return "zoneplate: claim not measured".into();
    };
    format!(
        "zoneplate: claim aliasing_removed={} (low band rwt {:.2} dB, jitter {:.2}, grid {:.2}) \
         less_noise={} (high band rwt {:.2} dB, jitter {:.2})",
        c.aliasing_removed,
        c.rwt.low,
        c.jitter.low,
        c.grid.low,
        c.less_noise,
        c.rwt.high,
        c.jitter.high
    )
}

/// The images (values -1..1) side by side as one grey PNG.
fn write_strip(path: &Path, images: &[&[f64]], size: usize) -> Result<(), String> {
    let width = size * images.len();
    let mut pixels = vec![0u8; width * size];
    for (k, image) in images.iter().enumerate() {
        for y in 0..size {
            for x in 0..size {
                let v = image[(size - 1 - y) * size + x];
                pixels[y * width + k * size + x] =
                    ((v * 0.5 + 0.5).clamp(0.0, 1.0) * 255.0).round() as u8;
            }
        }
    }
    crate::draw::save_png(
        path,
        &pixels,
        width as u32,
        size as u32,
        ExtendedColorType::L8,
    )
}
