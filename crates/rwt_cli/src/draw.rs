//! Minimal raster drawing for the CLI's pictures (discs, lines, rectangles on RGB images).

use image::{ExtendedColorType, ImageEncoder, Rgb, RgbImage};
use std::path::Path;

/// A picture format an output's extension names.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// `.png`.
    Png,
    /// `.svg`.
    Svg,
}

impl Format {
    fn extension(self) -> &'static str {
        match self {
            Format::Png => "png",
            Format::Svg => "svg",
        }
    }
}

/// The format `path`'s extension names, among those a command writes; anything else is an
/// error naming them (a picture is never written under another format's name).
pub fn format_of(path: &Path, writes: &[Format]) -> Result<Format, String> {
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    writes
        .iter()
        .copied()
        .find(|f| f.extension() == ext)
        .ok_or_else(|| {
            let names: Vec<String> = writes
                .iter()
                .map(|f| format!(".{}", f.extension()))
                .collect();
            format!(
                "{}: the format follows the extension; this writes {}",
                path.display(),
                names.join(" or ")
            )
        })
}

/// Writes pixels as a PNG, atomically: on any error an existing file keeps its bytes.
pub fn save_png(
    path: &Path,
    pixels: &[u8],
    width: u32,
    height: u32,
    color: ExtendedColorType,
) -> Result<(), String> {
    rwt_core::files::write_atomic_with(path, |w| {
        image::codecs::png::PngEncoder::new(w)
            .write_image(pixels, width, height, color)
            .map_err(std::io::Error::other)
    })
    .map_err(|e| e.to_string())
}

/// An RGB canvas.
pub struct Canvas {
    /// The pixels.
    pub image: RgbImage,
}

impl Canvas {
    /// Writes the canvas as a PNG (see [`save_png`]).
    pub fn save(&self, path: &Path) -> Result<(), String> {
        let (w, h) = self.image.dimensions();
        save_png(path, self.image.as_raw(), w, h, ExtendedColorType::Rgb8)
    }

    /// A canvas filled with `background`.
    pub fn new(width: u32, height: u32, background: [u8; 3]) -> Self {
        Self {
            image: RgbImage::from_pixel(width, height, Rgb(background)),
        }
    }

    fn put(&mut self, x: i64, y: i64, c: [u8; 3]) {
        if x >= 0 && y >= 0 && (x as u32) < self.image.width() && (y as u32) < self.image.height() {
            self.image.put_pixel(x as u32, y as u32, Rgb(c));
        }
    }

    /// A filled disc centred at `(x, y)`.
    pub fn disc(&mut self, x: f64, y: f64, r: f64, c: [u8; 3]) {
        let (x0, x1) = ((x - r).floor() as i64, (x + r).ceil() as i64);
        let (y0, y1) = ((y - r).floor() as i64, (y + r).ceil() as i64);
        for py in y0..=y1 {
            for px in x0..=x1 {
                let (dx, dy) = (px as f64 + 0.5 - x, py as f64 + 0.5 - y);
                if dx * dx + dy * dy <= r * r {
                    self.put(px, py, c);
                }
            }
        }
    }

    /// A line of the given width.
    pub fn line(&mut self, a: (f64, f64), b: (f64, f64), width: f64, c: [u8; 3]) {
        let len = ((b.0 - a.0).powi(2) + (b.1 - a.1).powi(2)).sqrt();
        let steps = (len * 2.0).ceil().max(1.0) as usize;
        for i in 0..=steps {
            let t = i as f64 / steps as f64;
            self.disc(a.0 + (b.0 - a.0) * t, a.1 + (b.1 - a.1) * t, width / 2.0, c);
        }
    }

    /// A filled axis-aligned rectangle.
    pub fn rect(&mut self, x0: f64, y0: f64, x1: f64, y1: f64, c: [u8; 3]) {
        for py in y0.floor() as i64..y1.ceil() as i64 {
            for px in x0.floor() as i64..x1.ceil() as i64 {
                self.put(px, py, c);
            }
        }
    }
}
