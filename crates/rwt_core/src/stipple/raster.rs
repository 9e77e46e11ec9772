//! Grey rasters for stippling: antialiased dots, Gaussian blur, bilinear resampling.

use glam::DVec2;

/// A grey raster, row 0 at the top, values in `[0, 1]`: an image's grey levels, a darkness
/// (ink) map or a rendered stipple's coverage.
#[derive(Clone, Debug, PartialEq)]
pub struct Grey {
    /// Width in pixels.
    pub width: usize,
    /// Height in pixels.
    pub height: usize,
    /// Row-major values.
    pub values: Vec<f32>,
}

/// Samples per pixel side when dots are rasterised (16 per pixel).
const SUPERSAMPLE: usize = 4;

impl Grey {
    /// The grey levels of an image (its luma, 0 black .. 1 white), transparent pixels
    /// composited over white: a transparent pixel is paper, with no ink.
    pub fn from_image(image: &image::DynamicImage) -> Self {
        let (width, height) = (image.width() as usize, image.height() as usize);
        let values = if image.color().has_alpha() {
            image
                .to_luma_alpha32f()
                .pixels()
                .map(|p| 1.0 - (1.0 - p.0[0]) * p.0[1])
                .collect()
        } else {
            image.to_luma32f().into_raw()
        };
        Self {
            width,
            height,
            values,
        }
    }

    /// A raster of one value.
    pub fn filled(width: usize, height: usize, value: f32) -> Self {
        Self {
            width,
            height,
            values: vec![value; width * height],
        }
    }

    /// A raster of the same size with `f` of each value.
    pub fn map(&self, f: impl Fn(f32) -> f32) -> Self {
        Self {
            width: self.width,
            height: self.height,
            values: self.values.iter().map(|&v| f(v)).collect(),
        }
    }

    /// The value at pixel `(x, y)`.
    #[inline]
    pub fn at(&self, x: usize, y: usize) -> f32 {
        self.values[y * self.width + x]
    }

    /// The mean value.
    pub fn mean(&self) -> f64 {
        self.values.iter().map(|&v| v as f64).sum::<f64>() / self.values.len().max(1) as f64
    }

    /// Bilinear value at a position in pixel units (pixel centres at `i + 0.5`), clamped to
    /// the edges.
    pub fn sample(&self, p: DVec2) -> f32 {
        let fx = (p.x - 0.5).clamp(0.0, (self.width - 1) as f64);
        let fy = (p.y - 0.5).clamp(0.0, (self.height - 1) as f64);
        let (x0, y0) = (fx as usize, fy as usize);
        let (x1, y1) = ((x0 + 1).min(self.width - 1), (y0 + 1).min(self.height - 1));
        let (ax, ay) = ((fx - x0 as f64) as f32, (fy - y0 as f64) as f32);
        let top = self.at(x0, y0) * (1.0 - ax) + self.at(x1, y0) * ax;
        let bottom = self.at(x0, y1) * (1.0 - ax) + self.at(x1, y1) * ax;
        top * (1.0 - ay) + bottom * ay
    }

    /// This raster resampled to `width x height` (bilinear).
    pub fn resized(&self, width: usize, height: usize) -> Self {
        let sx = self.width as f64 / width as f64;
        let sy = self.height as f64 / height as f64;
        let mut values = Vec::with_capacity(width * height);
        for y in 0..height {
            for x in 0..width {
                let p = DVec2::new((x as f64 + 0.5) * sx, (y as f64 + 0.5) * sy);
                values.push(self.sample(p));
            }
        }
        Self {
            width,
            height,
            values,
        }
    }

    /// Adds an ink dot of radius `r` centred at `c` (pixel units): each pixel's coverage
    /// (16 samples) combines with the ink already there as overlapping inks do,
    /// `1 - (1 - ink) (1 - coverage)`.
    pub fn dot(&mut self, c: DVec2, r: f64) {
        let (x0, x1) = ((c.x - r).floor().max(0.0), (c.x + r).ceil());
        let (y0, y1) = ((c.y - r).floor().max(0.0), (c.y + r).ceil());
        let (x1, y1) = (
            x1.min(self.width as f64) as usize,
            y1.min(self.height as f64) as usize,
        );
        let r2 = r * r;
        let step = 1.0 / SUPERSAMPLE as f64;
        let per_sample = 1.0 / (SUPERSAMPLE * SUPERSAMPLE) as f32;
        for py in y0 as usize..y1 {
            for px in x0 as usize..x1 {
                let mut inside = 0;
                for sy in 0..SUPERSAMPLE {
                    let dy = py as f64 + (sy as f64 + 0.5) * step - c.y;
                    for sx in 0..SUPERSAMPLE {
                        let dx = px as f64 + (sx as f64 + 0.5) * step - c.x;
                        inside += (dx * dx + dy * dy <= r2) as u32;
                    }
                }
                if inside > 0 {
                    let cover = inside as f32 * per_sample;
                    let v = &mut self.values[py * self.width + px];
                    *v = 1.0 - (1.0 - *v) * (1.0 - cover);
                }
            }
        }
    }

    /// This raster blurred by a Gaussian of standard deviation `sigma` pixels; near the
    /// edges the kernel is renormalised over the pixels inside.
    pub fn blurred(&self, sigma: f64) -> Self {
        let mut out = self.clone();
        out.blur(sigma);
        out
    }

    /// [`Grey::blurred`] in place: it takes one row or column of memory, not a raster.
    pub fn blur(&mut self, sigma: f64) {
        if sigma.is_nan() || sigma <= 0.0 {
            return;
        }
        // Beyond the raster's own size a wider kernel reaches no other pixel.
        let reach = ((3.0 * sigma).ceil() as usize).min(self.width.max(self.height));
        let kernel: Vec<f32> = (0..=reach)
            .map(|i| (-0.5 * (i as f64 / sigma).powi(2)).exp() as f32)
            .collect();
        blur_pass(&mut self.values, self.width, self.height, &kernel, true);
        blur_pass(&mut self.values, self.width, self.height, &kernel, false);
    }
}

/// One separable pass in place (along rows when `along_x`, else along columns), a line at
/// a time through a copy of it.
fn blur_pass(v: &mut [f32], w: usize, h: usize, kernel: &[f32], along_x: bool) {
    let (len, lines) = if along_x { (w, h) } else { (h, w) };
    let index = |line: usize, i: usize| if along_x { line * w + i } else { i * w + line };
    let reach = kernel.len() - 1;
    let mut input = vec![0.0f32; len];
    for line in 0..lines {
        for (i, x) in input.iter_mut().enumerate() {
            *x = v[index(line, i)];
        }
        for i in 0..len {
            let (lo, hi) = (i.saturating_sub(reach), (i + reach).min(len - 1));
            let (mut sum, mut weight) = (0.0f32, 0.0f32);
            for (j, x) in input.iter().enumerate().take(hi + 1).skip(lo) {
                let k = kernel[i.abs_diff(j)];
                sum += k * x;
                weight += k;
            }
            v[index(line, i)] = sum / weight;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn transparent_pixels_are_white_paper() {
        let mut rgba = image::RgbaImage::new(3, 1);
        rgba.put_pixel(0, 0, image::Rgba([0, 0, 0, 255]));
        rgba.put_pixel(1, 0, image::Rgba([0, 0, 0, 0]));
        rgba.put_pixel(2, 0, image::Rgba([0, 0, 0, 51]));
        let g = Grey::from_image(&image::DynamicImage::ImageRgba8(rgba));
        assert_eq!((g.width, g.height), (3, 1));
        assert_eq!(g.values[0], 0.0);
        assert_eq!(g.values[1], 1.0);
        assert!((g.values[2] - 0.8).abs() < 1e-6, "{}", g.values[2]);
    }

    #[test]
    fn a_huge_blur_is_the_mean_not_an_allocation() {
        let mut g = Grey::filled(4, 3, 0.0);
        g.values[0] = 1.2;
        for sigma in [1e6, 1e300, f64::INFINITY] {
            let b = g.blurred(sigma);
            assert!(
                b.values.iter().all(|&v| (v - 0.1).abs() < 1e-6),
                "{sigma}: {b:?}"
            );
        }
    }

    #[test]
    fn a_dot_covers_its_area() {
        let mut g = Grey::filled(64, 64, 0.0);
        g.dot(DVec2::new(31.3, 30.8), 9.0);
        let area: f64 = g.values.iter().map(|&v| v as f64).sum();
        let exact = std::f64::consts::PI * 81.0;
        assert!((area / exact - 1.0).abs() < 0.01, "{area} vs {exact}");
    }

    #[test]
    fn overlapping_ink_saturates_at_black() {
        let mut g = Grey::filled(8, 8, 0.0);
        for _ in 0..3 {
            g.dot(DVec2::new(4.0, 4.0), 3.0);
        }
        assert_eq!(g.at(4, 4), 1.0);
        assert!(g.values.iter().all(|&v| (0.0..=1.0).contains(&v)));
    }

    #[test]
    fn blurring_keeps_the_mean_of_a_flat_raster_and_spreads_a_spike() {
        let flat = Grey::filled(20, 10, 0.4).blurred(3.0);
        assert!(flat.values.iter().all(|&v| (v - 0.4).abs() < 1e-5));
        let mut spike = Grey::filled(41, 41, 0.0);
        spike.values[20 * 41 + 20] = 1.0;
        let b = spike.blurred(2.0);
        let total: f32 = b.values.iter().sum();
        assert!((total - 1.0).abs() < 1e-3, "{total}");
        assert!(b.at(20, 20) < 0.05 && b.at(22, 20) > 0.0);
    }
}
