//! `rwt stipple`: blue-noise stippling of an image, density from darkness (paper figure 11).

use crate::draw::Canvas;
use glam::DVec2;
use rwt_core::density::{Density, ImageDensity};
use rwt_core::query::{Rect, Sampler};
use rwt_core::tileset::TileSet;
use std::fmt::Write as _;
use std::path::Path;
use std::time::Instant;

/// `rwt stipple IMAGE --out FILE [--points N] [--seed S]`.
pub fn run(image: &Path, out: &Path, points: usize, seed: u64, scale: f64) -> Result<(), String> {
    let img = image::open(image).map_err(|e| format!("{}: {e}", image.display()))?;
    let (w, h) = (img.width() as f64, img.height() as f64);
    let size = DVec2::new(w, h);
    // World units are pixels; darkness 1 gives `density` points per pixel.
    let unit = ImageDensity::from_image(&img, None, true, DVec2::ZERO, size, 1.0)
        .map_err(|e| e.to_string())?;
    let darkness: f64 = (0..img.height())
        .flat_map(|y| (0..img.width()).map(move |x| (x, y)))
        .map(|(x, y)| unit.density(DVec2::new(x as f64 + 0.5, h - y as f64 - 0.5)))
        .sum();
    if darkness <= 0.0 {
        return Err("the image is white: nothing to stipple".into());
    }
    let density = points as f64 / darkness;
    let d = ImageDensity::from_image(&img, None, true, DVec2::ZERO, size, density)
        .map_err(|e| e.to_string())?;
    let set = TileSet::embedded();
    // Tiles sized so that the darkest tone fills a base tile exactly.
    let tile = (set.points_per_tile as f64 / density).sqrt();
    let sampler = Sampler::new(&set, seed)
        .with_tile_size(tile)
        .with_budget(points.saturating_mul(4).max(1000));
    let rect = Rect::new(DVec2::ZERO, size).map_err(|e| e.to_string())?;
    let mut pts = Vec::with_capacity(points + points / 8);
    let started = Instant::now();
    sampler
        .query(rect, &d, &mut pts)
        .map_err(|e| e.to_string())?;
    let secs = started.elapsed().as_secs_f64();
    say!(
        "{} points in {:.1} ms ({:.1} million points per second)",
        pts.len(),
        secs * 1e3,
        pts.len() as f64 / secs / 1e6
    );
    // Dots a little under half the spacing of the darkest tone.
    let radius = 0.42 / density.sqrt();
    let ext = out
        .extension()
        .and_then(|e| e.to_str())
        .unwrap_or("")
        .to_ascii_lowercase();
    if ext == "svg" {
        let mut svg = format!(
            "<svg xmlns=\"http://www.w3.org/2000/svg\" viewBox=\"0 0 {w} {h}\" width=\"{}\" height=\"{}\">\n<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n",
            w * scale,
            h * scale
        );
        for p in &pts {
            let _ = writeln!(
                svg,
                "<circle cx=\"{:.3}\" cy=\"{:.3}\" r=\"{radius:.3}\"/>",
                p.position.x,
                h - p.position.y
            );
        }
        svg.push_str("</svg>\n");
        std::fs::write(out, svg).map_err(|e| format!("{}: {e}", out.display()))?;
    } else {
        let mut c = Canvas::new((w * scale) as u32, (h * scale) as u32, [255, 255, 255]);
        for p in &pts {
            c.disc(
                p.position.x * scale,
                (h - p.position.y) * scale,
                (radius * scale).max(0.7),
                [0, 0, 0],
            );
        }
        c.image
            .save(out)
            .map_err(|e| format!("{}: {e}", out.display()))?;
    }
    say!("wrote {}", out.display());
    Ok(())
}
