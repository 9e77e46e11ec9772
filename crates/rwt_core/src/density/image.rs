//! Painted density maps: one channel of an image over a world rectangle, with max and min
//! mipmaps for conservative rectangle bounds.

use super::Density;
use glam::DVec2;
use std::io::{BufRead, Seek};
use std::path::Path;

/// Most pixels an image may have to be decoded by [`decode_image`] and [`open_image`]:
/// 2^26 (8192 x 8192). Checked from the image's header, before its pixels are decoded; a
/// density of that many pixels takes about 1 GB. Pass a larger limit to
/// [`decode_image_with_limit`] or [`open_image_with_limit`] to read larger images.
pub const MAX_IMAGE_PIXELS: u64 = 1 << 26;

/// A painted density map: one channel of an image, bilinearly interpolated over a world
/// rectangle, times `scale` (points per unit area at value 1). Zero outside the rectangle.
///
/// Rectangle maxima come from a max-mipmap: at the level where the rectangle covers a few
/// texels, the largest texel around it. This is exact-or-above for bilinear interpolation,
/// so a one-pixel stroke is never skipped however coarse the query.
#[derive(Clone, Debug)]
pub struct ImageDensity {
    origin: DVec2,
    size: DVec2,
    scale: f64,
    width: usize,
    height: usize,
    /// Texels per world unit on each axis.
    texels_per_unit: DVec2,
    /// The image with one extra column and row repeating the last ones, so that bilinear
    /// interpolation never needs to clamp its second texel (row stride `width + 1`).
    padded: Vec<f32>,
    /// Level 0 is the image (values in [0, 1]); level `l` holds 2x2 maxima of level `l - 1`.
    levels: Vec<(usize, usize, Vec<f32>)>,
    /// The same with 2x2 minima (level 0 is not repeated: `min_levels[l - 1]` is level `l`).
    min_levels: Vec<Vec<f32>>,
}

/// Why an image density could not be made.
#[derive(Clone, Debug, thiserror::Error, PartialEq)]
pub enum ImageDensityError {
    /// The image has no pixels or is larger than 2^15 on a side.
    #[error("image size {0}x{1} is not in 1..=32768")]
    Size(u32, u32),
    /// The world rectangle is empty, inverted or not finite.
    #[error("world rectangle must be finite with positive size")]
    Rect,
    /// The bytes are not an image this build can decode.
    #[error("cannot decode image: {0}")]
    Decode(String),
    /// The image's header announces more pixels than the limit (nothing was decoded).
    #[error(
        "image of {width}x{height} pixels is over the limit of {limit} pixels \
         (decode_image_with_limit reads larger images; a density takes about 16 bytes a pixel)"
    )]
    TooManyPixels {
        /// Width in the header.
        width: u32,
        /// Height in the header.
        height: u32,
        /// The limit.
        limit: u64,
    },
    /// The image file could not be read.
    #[error("cannot read image: {0}")]
    Read(String),
}

/// Decodes image bytes (any format this build of `image` reads) of at most
/// [`MAX_IMAGE_PIXELS`] pixels.
pub fn decode_image(bytes: &[u8]) -> Result<image::DynamicImage, ImageDensityError> {
    decode_image_with_limit(bytes, MAX_IMAGE_PIXELS)
}

/// Decodes image bytes of at most `max_pixels` pixels: the header is read first, and a
/// larger image is refused before any pixel is decoded.
pub fn decode_image_with_limit(
    bytes: &[u8],
    max_pixels: u64,
) -> Result<image::DynamicImage, ImageDensityError> {
    let reader = || {
        image::ImageReader::new(std::io::Cursor::new(bytes))
            .with_guessed_format()
            .map_err(|e| ImageDensityError::Decode(e.to_string()))
    };
    decode_limited(reader, max_pixels)
}

/// Opens and decodes an image file of at most [`MAX_IMAGE_PIXELS`] pixels, streaming from
/// the file (its bytes are never held whole).
pub fn open_image(path: &Path) -> Result<image::DynamicImage, ImageDensityError> {
    open_image_with_limit(path, MAX_IMAGE_PIXELS)
}

/// [`open_image`] with another pixel limit.
pub fn open_image_with_limit(
    path: &Path,
    max_pixels: u64,
) -> Result<image::DynamicImage, ImageDensityError> {
    let reader = || {
        image::ImageReader::open(path)
            .and_then(|r| r.with_guessed_format())
            .map_err(|e| ImageDensityError::Read(e.to_string()))
    };
    decode_limited(reader, max_pixels)
}

/// Reads the header through one reader, then decodes through another when the size is
/// within the limit.
fn decode_limited<R: BufRead + Seek>(
    reader: impl Fn() -> Result<image::ImageReader<R>, ImageDensityError>,
    max_pixels: u64,
) -> Result<image::DynamicImage, ImageDensityError> {
    let decode_err = |e: image::ImageError| ImageDensityError::Decode(e.to_string());
    let (width, height) = reader()?.into_dimensions().map_err(decode_err)?;
    if width as u64 * height as u64 > max_pixels {
        return Err(ImageDensityError::TooManyPixels {
            width,
            height,
            limit: max_pixels,
        });
    }
    let mut r = reader()?;
    let mut limits = image::Limits::default();
    // Room for the largest pixel format (16-bit RGBA) of an image within the limit.
    limits.max_alloc = Some((width as u64 * height as u64 * 8).max(512 << 20));
    r.limits(limits);
    r.decode().map_err(decode_err)
}

/// Where an image's values lie and what they mean: over the rectangle `min..min + size`
/// (row 0 of the image at max y), a value of 1 is `scale` points per unit area.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Placement {
    /// The rectangle's corner at its smallest x and y.
    pub min: DVec2,
    /// Its size (positive and finite).
    pub size: DVec2,
    /// Points per unit area where a value is 1.
    pub scale: f64,
}

impl ImageDensity {
    /// From row-major values (row 0 at the *top*, as images are stored) in `[0, 1]`; other
    /// values are clamped, NaN counts as 0.
    pub fn from_values(
        width: u32,
        height: u32,
        values: &[f32],
        at: Placement,
    ) -> Result<Self, ImageDensityError> {
        let Placement {
            min: origin,
            size,
            scale,
        } = at;
        if width == 0
            || height == 0
            || width > 32_768
            || height > 32_768
            || values.len() != (width * height) as usize
        {
            return Err(ImageDensityError::Size(width, height));
        }
        if !(origin.is_finite()
            && size.is_finite()
            && size.x > 0.0
            && size.y > 0.0
            && scale.is_finite())
        {
            return Err(ImageDensityError::Rect);
        }
        let clean: Vec<f32> = values
            .iter()
            .map(|&v| if v.is_nan() { 0.0 } else { v.clamp(0.0, 1.0) })
            .collect();
        let (w, h) = (width as usize, height as usize);
        let padded = padded(&clean, w, h);
        let (levels, min_levels) = mipmaps(clean, w, h);
        Ok(Self {
            origin,
            size,
            scale: scale.max(0.0),
            width: w,
            height: h,
            texels_per_unit: DVec2::new(w as f64, h as f64) / size,
            padded,
            levels,
            min_levels,
        })
    }

    /// From an image: `channel` 0..=3 of its RGBA form, or its luma times its alpha when
    /// `None` (a transparent pixel has no density, as painters expect). With `invert`, dark
    /// pixels are dense (for stippling): `(1 - luma)` times alpha.
    pub fn from_image(
        image: &image::DynamicImage,
        channel: Option<usize>,
        invert: bool,
        at: Placement,
    ) -> Result<Self, ImageDensityError> {
        let (w, h) = (image.width(), image.height());
        if w == 0 || h == 0 || w > 32_768 || h > 32_768 {
            return Err(ImageDensityError::Size(w, h));
        }
        let tone = |v: f32| if invert { 1.0 - v } else { v };
        let values: Vec<f32> = match channel {
            None if image.color().has_alpha() => image
                .to_luma_alpha32f()
                .pixels()
                .map(|p| tone(p.0[0]) * p.0[1])
                .collect(),
            None => image
                .to_luma32f()
                .into_raw()
                .into_iter()
                .map(tone)
                .collect(),
            Some(c) => image
                .to_rgba32f()
                .pixels()
                .map(|p| tone(p.0[c.min(3)]))
                .collect(),
        };
        Self::from_values(w, h, &values, at)
    }

    /// Decodes image bytes (any format this build of `image` supports, at most
    /// [`MAX_IMAGE_PIXELS`] pixels) into a density (see [`ImageDensity::from_image`]).
    pub fn from_bytes(
        bytes: &[u8],
        invert: bool,
        at: Placement,
    ) -> Result<Self, ImageDensityError> {
        let img = decode_image(bytes)?;
        Self::from_image(&img, None, invert, at)
    }

    /// Image width and height in pixels.
    pub fn dimensions(&self) -> (usize, usize) {
        (self.width, self.height)
    }

    /// Texel coordinates of a world point (texel centres at integer + 0.5, y downwards).
    #[inline]
    fn texel(&self, p: DVec2) -> DVec2 {
        let u = (p - self.origin) / self.size;
        DVec2::new(u.x * self.width as f64, (1.0 - u.y) * self.height as f64)
    }

    /// The image value (before `scale`) at a world point.
    // Always inlined: in a query's inner loop this lets the image fields stay in registers.
    #[inline(always)]
    pub fn value(&self, p: DVec2) -> f64 {
        // Texel coordinates with texel centres at integers, y downwards; f32 after one f64
        // subtraction, which keeps far-away worlds exact to well under a texel.
        let fx = ((p.x - self.origin.x) * self.texels_per_unit.x) as f32 - 0.5;
        let fy = ((self.origin.y + self.size.y - p.y) * self.texels_per_unit.y) as f32 - 0.5;
        let (w, h) = (self.width as f32, self.height as f32);
        if !(fx >= -0.5 && fy >= -0.5 && fx < w - 0.5 && fy < h - 0.5) {
            return 0.0;
        }
        let (fx, fy) = (fx.max(0.0), fy.max(0.0));
        let (x0, y0) = (fx as usize, fy as usize);
        let (ax, ay) = (fx - x0 as f32, fy - y0 as f32);
        let stride = self.width + 1;
        let i = y0 * stride + x0;
        let (top, bottom) = (
            &self.padded[i..i + 2],
            &self.padded[i + stride..i + stride + 2],
        );
        let t = top[0] + (top[1] - top[0]) * ax;
        let b = bottom[0] + (bottom[1] - bottom[0]) * ax;
        (t + (b - t) * ay) as f64
    }
}

/// The image with one extra column and row repeating the last ones (row stride `w + 1`).
fn padded(img: &[f32], w: usize, h: usize) -> Vec<f32> {
    let mut padded = Vec::with_capacity((w + 1) * (h + 1));
    for y in 0..=h {
        let row = &img[y.min(h - 1) * w..][..w];
        padded.extend_from_slice(row);
        padded.push(row[w - 1]);
    }
    padded
}

/// Max and min mipmaps of an image down to one texel: `levels[0]` is the image, level `l`
/// holds the 2x2 maxima of level `l - 1`; `min_levels[l - 1]` the minima of level `l`.
type Mipmaps = (Vec<(usize, usize, Vec<f32>)>, Vec<Vec<f32>>);

fn mipmaps(img: Vec<f32>, w: usize, h: usize) -> Mipmaps {
    let mut levels = vec![(w, h, img)];
    let mut min_levels: Vec<Vec<f32>> = Vec::new();
    while levels.last().is_some_and(|l| l.0 > 1 || l.1 > 1) {
        let (pw, ph, prev) = levels.last().expect("non-empty");
        let prev_min = min_levels.last().unwrap_or(prev);
        let (nw, nh) = (pw.div_ceil(2), ph.div_ceil(2));
        let mut next = vec![0.0f32; nw * nh];
        let mut next_min = vec![1.0f32; nw * nh];
        for y in 0..*ph {
            for x in 0..*pw {
                let at = (y / 2) * nw + x / 2;
                next[at] = next[at].max(prev[y * pw + x]);
                next_min[at] = next_min[at].min(prev_min[y * pw + x]);
            }
        }
        levels.push((nw, nh, next));
        min_levels.push(next_min);
    }
    (levels, min_levels)
}

impl Density for ImageDensity {
    #[inline(always)]
    fn density(&self, p: DVec2) -> f64 {
        self.value(p) * self.scale
    }

    fn max_over(&self, min: DVec2, max: DVec2) -> f64 {
        let Some((level, x, y)) = self.texel_range(min, max) else {
            return 0.0;
        };
        let (lw, _, texels) = &self.levels[level];
        fold_texels(texels, *lw, x, y, 0.0, f32::max) as f64 * self.scale
    }

    fn min_over(&self, min: DVec2, max: DVec2) -> f64 {
        // Only well inside the image: at its border `value` reads 0, after f32 rounding.
        let inside = |p: DVec2| {
            let t = self.texel(p);
            let (w, h) = (self.width as f64, self.height as f64);
            t.x >= 0.5 && t.y >= 0.5 && t.x <= w - 0.5 && t.y <= h - 0.5
        };
        if !(inside(min) && inside(max)) {
            return 0.0;
        }
        let Some((level, x, y)) = self.texel_range(min, max) else {
            return 0.0;
        };
        let (lw, _, _) = &self.levels[level];
        let texels = if level == 0 {
            &self.levels[0].2
        } else {
            &self.min_levels[level - 1]
        };
        let least = fold_texels(texels, *lw, x, y, 1.0, f32::min);
        // Bilinear blending in f32 rounds by a few units in the last place of 1.0 (texels
        // are at most 1), so it can land a hair below its smallest texel.
        (least as f64 - 1e-6).max(0.0) * self.scale
    }
}

/// Folds the texels `columns x rows` of a `width`-wide level.
fn fold_texels(
    texels: &[f32],
    width: usize,
    columns: std::ops::RangeInclusive<usize>,
    rows: std::ops::RangeInclusive<usize>,
    init: f32,
    f: fn(f32, f32) -> f32,
) -> f32 {
    let mut acc = init;
    for y in rows {
        for x in columns.clone() {
            acc = f(acc, texels[y * width + x]);
        }
    }
    acc
}

impl ImageDensity {
    /// The texels bilinear interpolation reads anywhere in the rectangle, at the coarsest
    /// mip level where they span at most 4 texels per axis: `(level, columns, rows)`.
    fn texel_range(
        &self,
        min: DVec2,
        max: DVec2,
    ) -> Option<(
        usize,
        std::ops::RangeInclusive<usize>,
        std::ops::RangeInclusive<usize>,
    )> {
        let a = self.texel(DVec2::new(min.x, max.y));
        let b = self.texel(DVec2::new(max.x, min.y));
        let (w, h) = (self.width as f64, self.height as f64);
        if b.x < 0.0 || b.y < 0.0 || a.x >= w || a.y >= h || !(a.is_finite() && b.is_finite()) {
            return None;
        }
        let x0 = (a.x - 1.0).floor().max(0.0) as usize;
        let y0 = (a.y - 1.0).floor().max(0.0) as usize;
        let x1 = ((b.x + 1.0).ceil() as usize).min(self.width - 1);
        let y1 = ((b.y + 1.0).ceil() as usize).min(self.height - 1);
        let span = (x1 - x0).max(y1 - y0) + 1;
        let mut level = 0;
        while level + 1 < self.levels.len() && (span >> (level + 1)) >= 2 {
            level += 1;
        }
        Some((
            level,
            (x0 >> level)..=(x1 >> level),
            (y0 >> level)..=(y1 >> level),
        ))
    }
}
