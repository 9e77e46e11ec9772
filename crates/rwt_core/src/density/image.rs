//! Painted density maps: one channel of an image over a world rectangle, with max and min
//! mipmaps for conservative rectangle bounds.

use super::Density;
use glam::DVec2;
use std::io::{BufRead, Seek};
use std::path::Path;

/// Most pixels an image may have to be decoded by [`decode_image`] and [`open_image`]:
/// 2^26 (8192 x 8192), and at most 4 bytes a pixel decoded (256 MiB: a 16-bit RGBA image is
/// admitted to half as many pixels). Checked from the image's header, before its pixels
/// are decoded. Pass a larger limit to [`decode_image_with_limit`] or
/// [`open_image_with_limit`] to read larger images.
pub const MAX_IMAGE_PIXELS: u64 = 1 << 26;

/// Bytes an [`ImageDensity`] takes a pixel: its values (4) and its max and min mipmaps
/// (2 bytes a texel, a third of the pixels each).
pub const DENSITY_BYTES_PER_PIXEL: f64 = 4.0 + 4.0 / 3.0;

/// Most memory [`ImageDensity::open`] and [`ImageDensity::from_bytes`] take while making a
/// density: its values beside the larger of the decoded image and the mipmaps, 448 MiB. An
/// 8192 x 8192 8-bit grey or RGB PNG is admitted (`rwt points` peaks at 377 MB on the grey
/// one, measured), an 8-bit RGBA one up to 7 600 x 7 600 pixels, a 16-bit RGBA one up to
/// 6 200 x 6 200.
pub const MAX_DENSITY_BYTES: u64 = 448 << 20;

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
    /// The image (values in [0, 1]) with one extra column and row repeating the last ones,
    /// so that bilinear interpolation never needs to clamp its second texel (row stride
    /// `width + 1`). Level 0 of the mipmaps.
    padded: Vec<f32>,
    /// Levels 1.. of the max mipmap: `(width, height, texels)`, each the 2x2 maxima of the
    /// level below, in 1/65535 steps rounded up.
    levels: Vec<(usize, usize, Vec<u16>)>,
    /// The same with 2x2 minima rounded down (`min_levels[l - 1]` is level `l`).
    min_levels: Vec<Vec<u16>>,
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
    /// Decoding the image (and making its density) would take more memory than the limit.
    #[error(
        "a {width}x{height} {color:?} image would take {:.0} MB decoded{}, over the limit of \
         {:.0} MB (8-bit grey images are admitted up to 8192x8192 pixels)",
        *bytes as f64 / 1e6,
        if *limit == MAX_DENSITY_BYTES { " and as a density" } else { "" },
        *limit as f64 / 1e6
    )]
    TooMuchMemory {
        /// Width in the header.
        width: u32,
        /// Height in the header.
        height: u32,
        /// Its pixel format.
        color: image::ColorType,
        /// Bytes it would take.
        bytes: u64,
        /// The limit.
        limit: u64,
    },
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
    decode_limited(|| bytes_reader(bytes), max_pixels)
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
    decode_limited(|| file_reader(path), max_pixels)
}

/// A reader of image bytes, its format guessed from them.
fn bytes_reader(
    bytes: &[u8],
) -> Result<image::ImageReader<std::io::Cursor<&[u8]>>, ImageDensityError> {
    image::ImageReader::new(std::io::Cursor::new(bytes))
        .with_guessed_format()
        .map_err(|e| ImageDensityError::Decode(e.to_string()))
}

/// A reader of an image file (a regular file: see [`crate::files::open_regular`]), its
/// format guessed from its first bytes.
fn file_reader(
    path: &Path,
) -> Result<image::ImageReader<std::io::BufReader<std::fs::File>>, ImageDensityError> {
    let file =
        crate::files::open_regular(path).map_err(|e| ImageDensityError::Read(e.to_string()))?;
    image::ImageReader::new(std::io::BufReader::new(file))
        .with_guessed_format()
        .map_err(|e| ImageDensityError::Read(e.to_string()))
}

/// Reads the header through one reader, then decodes through another when the size is
/// within the limit.
fn decode_limited<R: BufRead + Seek>(
    reader: impl Fn() -> Result<image::ImageReader<R>, ImageDensityError>,
    max_pixels: u64,
) -> Result<image::DynamicImage, ImageDensityError> {
    decode_admitted(reader, |header| {
        let Header {
            width,
            height,
            color,
        } = header;
        let pixels = width as u64 * height as u64;
        if pixels > max_pixels {
            return Err(ImageDensityError::TooManyPixels {
                width,
                height,
                limit: max_pixels,
            });
        }
        let decoded = pixels * color.bytes_per_pixel() as u64;
        let limit = max_pixels.saturating_mul(4);
        if decoded > limit {
            return Err(ImageDensityError::TooMuchMemory {
                width,
                height,
                color,
                bytes: decoded,
                limit,
            });
        }
        Ok(())
    })
}

/// What an image's header says.
#[derive(Clone, Copy, Debug)]
struct Header {
    width: u32,
    height: u32,
    color: image::ColorType,
}

impl Header {
    /// Bytes of the decoded pixels.
    fn decoded_bytes(&self) -> u64 {
        self.width as u64 * self.height as u64 * self.color.bytes_per_pixel() as u64
    }
}

/// Reads the header through one reader and asks `admit`; decodes through another (within
/// an allocation limit of what the header announced) when it agrees.
fn decode_admitted<R: BufRead + Seek>(
    reader: impl Fn() -> Result<image::ImageReader<R>, ImageDensityError>,
    admit: impl FnOnce(Header) -> Result<(), ImageDensityError>,
) -> Result<image::DynamicImage, ImageDensityError> {
    use image::ImageDecoder;
    let decode_err = |e: image::ImageError| ImageDensityError::Decode(e.to_string());
    let decoder = reader()?.into_decoder().map_err(decode_err)?;
    let (width, height) = decoder.dimensions();
    let header = Header {
        width,
        height,
        color: decoder.color_type(),
    };
    drop(decoder);
    admit(header)?;
    let mut r = reader()?;
    let mut limits = image::Limits::default();
    // The decoded pixels and a decoder's working rows.
    limits.max_alloc = Some(header.decoded_bytes() + (64 << 20));
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
        if values.len() != width as usize * height as usize {
            return Err(ImageDensityError::Size(width, height));
        }
        let w = width as usize;
        let padded = padded_from_strips(width, height, at, |y0, y1, out| {
            out.extend_from_slice(&values[y0 as usize * w..y1 as usize * w]);
        })?;
        Ok(Self::from_padded(width, height, padded, at))
    }

    /// From an image: `channel` 0..=3 of its RGBA form, or its luma times its alpha when
    /// `None` (a transparent pixel has no density, as painters expect). With `invert`, dark
    /// pixels are dense (for stippling): `(1 - luma)` times alpha. Converted a strip of rows
    /// at a time: it takes the image and [`DENSITY_BYTES_PER_PIXEL`].
    pub fn from_image(
        image: &image::DynamicImage,
        channel: Option<usize>,
        invert: bool,
        at: Placement,
    ) -> Result<Self, ImageDensityError> {
        let padded = padded_from_image(image, channel, invert, at)?;
        Ok(Self::from_padded(image.width(), image.height(), padded, at))
    }

    /// Decodes image bytes (any format this build of `image` supports) into a density (see
    /// [`ImageDensity::from_image`]), within [`MAX_DENSITY_BYTES`].
    pub fn from_bytes(
        bytes: &[u8],
        invert: bool,
        at: Placement,
    ) -> Result<Self, ImageDensityError> {
        Self::decode_within(|| bytes_reader(bytes), invert, at)
    }

    /// Opens an image file (see [`ImageDensity::from_image`]): refused from its header when
    /// decoding it and making its density would take more than [`MAX_DENSITY_BYTES`]; the
    /// decoded image is dropped before the mipmaps are made.
    pub fn open(path: &Path, invert: bool, at: Placement) -> Result<Self, ImageDensityError> {
        Self::decode_within(|| file_reader(path), invert, at)
    }

    fn decode_within<R: BufRead + Seek>(
        reader: impl Fn() -> Result<image::ImageReader<R>, ImageDensityError>,
        invert: bool,
        at: Placement,
    ) -> Result<Self, ImageDensityError> {
        let image = decode_admitted(reader, |header| {
            let Header {
                width,
                height,
                color,
            } = header;
            if width == 0 || height == 0 || width > 32_768 || height > 32_768 {
                return Err(ImageDensityError::Size(width, height));
            }
            let pixels = width as f64 * height as f64;
            // The values live with the decoded image, then with the mipmaps.
            let mipmaps = (DENSITY_BYTES_PER_PIXEL - 4.0) * pixels;
            let bytes = (4.0 * pixels + mipmaps.max(header.decoded_bytes() as f64)) as u64;
            if bytes > MAX_DENSITY_BYTES {
                return Err(ImageDensityError::TooMuchMemory {
                    width,
                    height,
                    color,
                    bytes,
                    limit: MAX_DENSITY_BYTES,
                });
            }
            Ok(())
        })?;
        let (width, height) = (image.width(), image.height());
        let padded = padded_from_image(&image, None, invert, at)?;
        drop(image);
        Ok(Self::from_padded(width, height, padded, at))
    }

    /// The density of checked padded values.
    fn from_padded(width: u32, height: u32, padded: Vec<f32>, at: Placement) -> Self {
        let (w, h) = (width as usize, height as usize);
        let (levels, min_levels) = mipmaps(&padded, w, h);
        let size = at.size;
        Self {
            origin: at.min,
            size,
            scale: at.scale.max(0.0),
            width: w,
            height: h,
            texels_per_unit: DVec2::new(w as f64, h as f64) / size,
            padded,
            levels,
            min_levels,
        }
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

/// Rows converted at a time from an image.
const STRIP_ROWS: u32 = 64;

/// Checks a size and a placement, then gathers values a strip of rows at a time (`strip`
/// appends rows `y0..y1`) into the padded image: clamped to `[0, 1]` (NaN is 0), with one
/// extra column and row repeating the last ones (row stride `w + 1`).
fn padded_from_strips(
    width: u32,
    height: u32,
    at: Placement,
    mut strip: impl FnMut(u32, u32, &mut Vec<f32>),
) -> Result<Vec<f32>, ImageDensityError> {
    if width == 0 || height == 0 || width > 32_768 || height > 32_768 {
        return Err(ImageDensityError::Size(width, height));
    }
    let Placement { min, size, scale } = at;
    if !(min.is_finite() && size.is_finite() && size.x > 0.0 && size.y > 0.0 && scale.is_finite()) {
        return Err(ImageDensityError::Rect);
    }
    let (w, h) = (width as usize, height as usize);
    let clean = |v: f32| if v.is_nan() { 0.0 } else { v.clamp(0.0, 1.0) };
    let mut padded = Vec::with_capacity((w + 1) * (h + 1));
    let mut rows = Vec::with_capacity(w * STRIP_ROWS as usize);
    for y0 in (0..height).step_by(STRIP_ROWS as usize) {
        let y1 = (y0 + STRIP_ROWS).min(height);
        rows.clear();
        strip(y0, y1, &mut rows);
        for row in rows.chunks_exact(w) {
            padded.extend(row.iter().map(|&v| clean(v)));
            padded.push(clean(row[w - 1]));
        }
    }
    padded.extend_from_within((h - 1) * (w + 1)..h * (w + 1));
    Ok(padded)
}

/// An image's values (see [`ImageDensity::from_image`]), padded.
fn padded_from_image(
    image: &image::DynamicImage,
    channel: Option<usize>,
    invert: bool,
    at: Placement,
) -> Result<Vec<f32>, ImageDensityError> {
    let (w, h) = (image.width(), image.height());
    let tone = |v: f32| if invert { 1.0 - v } else { v };
    padded_from_strips(w, h, at, |y0, y1, out| {
        let strip = image.crop_imm(0, y0, w, y1 - y0);
        match channel {
            None if strip.color().has_alpha() => out.extend(
                strip
                    .to_luma_alpha32f()
                    .pixels()
                    .map(|p| tone(p.0[0]) * p.0[1]),
            ),
            None => out.extend(strip.to_luma32f().into_raw().into_iter().map(tone)),
            Some(c) => out.extend(strip.to_rgba32f().pixels().map(|p| tone(p.0[c.min(3)]))),
        }
    })
}

/// Max and min mipmaps above level 0 (the padded image, row stride `w + 1`) down to one
/// texel, in 1/65535 steps: maxima rounded up and minima down, so that they stay bounds.
type Mipmaps = (Vec<(usize, usize, Vec<u16>)>, Vec<Vec<u16>>);

fn mipmaps(padded: &[f32], w: usize, h: usize) -> Mipmaps {
    let up = |v: f32| (v as f64 * 65535.0).ceil() as u16;
    let down = |v: f32| (v as f64 * 65535.0).floor() as u16;
    let mut levels: Vec<(usize, usize, Vec<u16>)> = Vec::new();
    let mut min_levels: Vec<Vec<u16>> = Vec::new();
    let (mut pw, mut ph) = (w, h);
    while pw > 1 || ph > 1 {
        let (nw, nh) = (pw.div_ceil(2), ph.div_ceil(2));
        let mut next = vec![0u16; nw * nh];
        let mut next_min = vec![u16::MAX; nw * nh];
        for y in 0..ph {
            for x in 0..pw {
                let at = (y / 2) * nw + x / 2;
                let (hi, lo) = match (levels.last(), min_levels.last()) {
                    (Some((_, _, prev)), Some(prev_min)) => {
                        (prev[y * pw + x], prev_min[y * pw + x])
                    }
                    _ => {
                        let v = padded[y * (w + 1) + x];
                        (up(v), down(v))
                    }
                };
                next[at] = next[at].max(hi);
                next_min[at] = next_min[at].min(lo);
            }
        }
        levels.push((nw, nh, next));
        min_levels.push(next_min);
        (pw, ph) = (nw, nh);
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
        let most = match level {
            0 => fold_texels(&self.padded, self.width + 1, x, y, 0.0, f32::max) as f64,
            l => {
                let (lw, _, texels) = &self.levels[l - 1];
                fold_texels(texels, *lw, x, y, 0, u16::max) as f64 / 65535.0
            }
        };
        most * self.scale
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
        let least = match level {
            0 => fold_texels(&self.padded, self.width + 1, x, y, 1.0, f32::min) as f64,
            l => {
                let lw = self.levels[l - 1].0;
                fold_texels(&self.min_levels[l - 1], lw, x, y, u16::MAX, u16::min) as f64 / 65535.0
            }
        };
        // Bilinear blending in f32 rounds by a few units in the last place of 1.0 (texels
        // are at most 1), so it can land a hair below its smallest texel.
        (least - 1e-6).max(0.0) * self.scale
    }
}

/// Folds the texels `columns x rows` of a level of row stride `stride`.
fn fold_texels<T: Copy>(
    texels: &[T],
    stride: usize,
    columns: std::ops::RangeInclusive<usize>,
    rows: std::ops::RangeInclusive<usize>,
    init: T,
    f: fn(T, T) -> T,
) -> T {
    let mut acc = init;
    for y in rows {
        for x in columns.clone() {
            acc = f(acc, texels[y * stride + x]);
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
        while level < self.levels.len() && (span >> (level + 1)) >= 2 {
            level += 1;
        }
        Some((
            level,
            (x0 >> level)..=(x1 >> level),
            (y0 >> level)..=(y1 >> level),
        ))
    }
}
