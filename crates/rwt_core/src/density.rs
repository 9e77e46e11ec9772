//! Target densities: how many points per unit area a query should produce, everywhere.
//!
//! A [`Density`] answers two questions: the density at a point, and a *conservative*
//! maximum over a rectangle. The query descends into finer tiles only where that maximum
//! asks for it, so the maximum must never be below any value inside the rectangle (or thin
//! features would be missed), and should be tight (or time is wasted).
//!
//! Values are sanitized by the query: NaN and negative densities count as 0. An infinite
//! density asks for infinitely many points, which the query's point budget turns into
//! [`crate::query::QueryError::BudgetExceeded`]; it never panics or allocates for it.

use glam::DVec2;
use noise::{Fbm, MultiFractal, NoiseFn, Perlin};

/// A density function over the plane, in points per unit area.
pub trait Density {
    /// Density at `p`.
    fn density(&self, p: DVec2) -> f64;
    /// An upper bound of [`Density::density`] over the rectangle `[min, max]`.
    fn max_over(&self, min: DVec2, max: DVec2) -> f64;
    /// A lower bound of [`Density::density`] over the rectangle `[min, max]`. Queries take
    /// points whose threshold lies below it without evaluating the density, so it must never
    /// exceed the density anywhere in the rectangle; the default, 0, is always right.
    fn min_over(&self, min: DVec2, max: DVec2) -> f64 {
        let _ = (min, max);
        0.0
    }
}

impl<D: Density + ?Sized> Density for &D {
    fn density(&self, p: DVec2) -> f64 {
        (**self).density(p)
    }
    fn max_over(&self, min: DVec2, max: DVec2) -> f64 {
        (**self).max_over(min, max)
    }
    fn min_over(&self, min: DVec2, max: DVec2) -> f64 {
        (**self).min_over(min, max)
    }
}

impl<D: Density + ?Sized> Density for Box<D> {
    fn density(&self, p: DVec2) -> f64 {
        (**self).density(p)
    }
    fn max_over(&self, min: DVec2, max: DVec2) -> f64 {
        (**self).max_over(min, max)
    }
    fn min_over(&self, min: DVec2, max: DVec2) -> f64 {
        (**self).min_over(min, max)
    }
}

impl<D: Density + ?Sized> Density for std::sync::Arc<D> {
    fn density(&self, p: DVec2) -> f64 {
        (**self).density(p)
    }
    fn max_over(&self, min: DVec2, max: DVec2) -> f64 {
        (**self).max_over(min, max)
    }
    fn min_over(&self, min: DVec2, max: DVec2) -> f64 {
        (**self).min_over(min, max)
    }
}

/// The same density everywhere.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Constant(pub f64);

impl Density for Constant {
    #[inline]
    fn density(&self, _: DVec2) -> f64 {
        self.0
    }
    #[inline]
    fn max_over(&self, _: DVec2, _: DVec2) -> f64 {
        self.0
    }
    #[inline]
    fn min_over(&self, _: DVec2, _: DVec2) -> f64 {
        self.0
    }
}

/// A closure density with a closure bound: `bound(min, max)` must be at least every value of
/// `f` in the rectangle.
#[derive(Clone, Copy)]
pub struct FnDensity<F, B> {
    f: F,
    bound: B,
}

impl<F: Fn(DVec2) -> f64, B: Fn(DVec2, DVec2) -> f64> FnDensity<F, B> {
    /// A density from a function and a rectangle bound.
    pub fn new(f: F, bound: B) -> Self {
        Self { f, bound }
    }
}

/// A closure density whose values never exceed `max` (a constant bound).
pub fn from_fn(
    f: impl Fn(DVec2) -> f64,
    max: f64,
) -> FnDensity<impl Fn(DVec2) -> f64, impl Fn(DVec2, DVec2) -> f64> {
    FnDensity::new(f, move |_, _| max)
}

impl<F: Fn(DVec2) -> f64, B: Fn(DVec2, DVec2) -> f64> Density for FnDensity<F, B> {
    #[inline]
    fn density(&self, p: DVec2) -> f64 {
        (self.f)(p)
    }
    #[inline]
    fn max_over(&self, min: DVec2, max: DVec2) -> f64 {
        (self.bound)(min, max)
    }
}

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
#[derive(Debug, thiserror::Error, PartialEq)]
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
}

impl ImageDensity {
    /// From row-major values (row 0 at the *top*, as images are stored) in `[0, 1]`; other
    /// values are clamped, NaN counts as 0.
    pub fn from_values(
        width: u32,
        height: u32,
        values: &[f32],
        origin: DVec2,
        size: DVec2,
        scale: f64,
    ) -> Result<Self, ImageDensityError> {
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
        let mut levels = vec![(w, h, clean)];
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
        let img = &levels[0].2;
        let mut padded = Vec::with_capacity((w + 1) * (h + 1));
        for y in 0..=h {
            let row = &img[y.min(h - 1) * w..][..w];
            padded.extend_from_slice(row);
            padded.push(row[w - 1]);
        }
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

    /// From an image: `channel` 0..=3 of its RGBA form, or the luma when `None`. With
    /// `invert`, dark pixels are dense (for stippling).
    pub fn from_image(
        image: &image::DynamicImage,
        channel: Option<usize>,
        invert: bool,
        origin: DVec2,
        size: DVec2,
        scale: f64,
    ) -> Result<Self, ImageDensityError> {
        let (w, h) = (image.width(), image.height());
        if w == 0 || h == 0 || w > 32_768 || h > 32_768 {
            return Err(ImageDensityError::Size(w, h));
        }
        let values: Vec<f32> = match channel {
            None => image.to_luma32f().into_raw(),
            Some(c) => image.to_rgba32f().pixels().map(|p| p.0[c.min(3)]).collect(),
        };
        let values: Vec<f32> = if invert {
            values.iter().map(|v| 1.0 - v).collect()
        } else {
            values
        };
        Self::from_values(w, h, &values, origin, size, scale)
    }

    /// Decodes image bytes (any format this build of `image` supports) into a density.
    pub fn from_bytes(
        bytes: &[u8],
        invert: bool,
        origin: DVec2,
        size: DVec2,
        scale: f64,
    ) -> Result<Self, ImageDensityError> {
        let img =
            image::load_from_memory(bytes).map_err(|e| ImageDensityError::Decode(e.to_string()))?;
        Self::from_image(&img, None, invert, origin, size, scale)
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

/// Fractal noise: `scale * max(0, base + amplitude * fbm(p * frequency))`, with fBm of
/// Perlin noise from the `noise` crate (values in [-1, 1]).
#[derive(Clone, Debug)]
pub struct NoiseDensity {
    fbm: Fbm<Perlin>,
    frequency: f64,
    base: f64,
    amplitude: f64,
    scale: f64,
    /// Bound of the fBm's gradient per world unit, for rectangle maxima.
    lipschitz: f64,
}

/// The parameters of a [`NoiseDensity`], as plain (serializable) data.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct NoiseParams {
    /// Noise seed.
    pub seed: u32,
    /// Cycles per world unit.
    pub frequency: f64,
    /// Octaves (1..=16).
    pub octaves: usize,
    /// Offset of the noise value.
    pub base: f64,
    /// Gain of the noise value.
    pub amplitude: f64,
    /// Points per unit area at value 1.
    pub scale: f64,
}

/// Bound of the gradient magnitude of the `noise` crate's 2D Perlin noise: the largest
/// central-difference gradient over 10^7 random samples was 3.89; doubled for safety.
const PERLIN_GRADIENT_BOUND: f64 = 8.0;

impl NoiseDensity {
    /// fBm with `octaves` octaves (1..=16), `frequency` cycles per world unit.
    pub fn new(
        seed: u32,
        frequency: f64,
        octaves: usize,
        base: f64,
        amplitude: f64,
        scale: f64,
    ) -> Self {
        let octaves = octaves.clamp(1, 16);
        let fbm = Fbm::<Perlin>::new(seed).set_octaves(octaves);
        let (mut attenuation, mut freq, mut gradient) = (fbm.persistence, 1.0, 0.0);
        let mut amplitude_sum = 0.0;
        for _ in 0..octaves {
            gradient += attenuation * freq;
            amplitude_sum += attenuation;
            attenuation *= fbm.persistence;
            freq *= fbm.lacunarity;
        }
        // The crate rescales the sum of octaves into [-1, 1] by 1 / amplitude_sum.
        let lipschitz = PERLIN_GRADIENT_BOUND * gradient / amplitude_sum * frequency.abs();
        Self {
            fbm,
            frequency,
            base,
            amplitude,
            scale,
            lipschitz,
        }
    }

    /// The density described by `params`.
    pub fn from_params(p: NoiseParams) -> Self {
        Self::new(p.seed, p.frequency, p.octaves, p.base, p.amplitude, p.scale)
    }

    /// The fBm at `p`: 0 where `p * frequency` is not finite, and wrapped by Perlin noise's
    /// period (256 lattice cells) beyond 2^40 cells, where the `noise` crate would panic
    /// converting coordinates to `isize` (and has no precision left anyway).
    #[inline]
    fn noise(&self, p: DVec2) -> f64 {
        const WRAP: f64 = (1u64 << 40) as f64;
        let mut q = p * self.frequency;
        if !q.is_finite() {
            return 0.0;
        }
        if q.abs().max_element() >= WRAP {
            q = DVec2::new(q.x.rem_euclid(256.0), q.y.rem_euclid(256.0));
        }
        self.fbm.get([q.x, q.y])
    }
}

impl Density for NoiseDensity {
    #[inline]
    fn density(&self, p: DVec2) -> f64 {
        self.scale * (self.base + self.amplitude * self.noise(p)).max(0.0)
    }

    fn max_over(&self, min: DVec2, max: DVec2) -> f64 {
        let (_, hi) = self.range_over(min, max);
        self.scale * hi.max(0.0)
    }

    fn min_over(&self, min: DVec2, max: DVec2) -> f64 {
        let (lo, _) = self.range_over(min, max);
        // A hair under, for the rounding of the noise crate's own arithmetic.
        self.scale * (lo - 1e-9).max(0.0)
    }
}

impl NoiseDensity {
    /// Bounds of `base + amplitude * noise` over the rectangle, before clamping and
    /// scaling: the noise at the centre plus or minus its Lipschitz reach, within [-1, 1].
    fn range_over(&self, min: DVec2, max: DVec2) -> (f64, f64) {
        let centre = (min + max) * 0.5;
        let reach = (max - min).length() * 0.5 * self.lipschitz;
        let at_centre = self.noise(centre);
        let a = self.base + self.amplitude * (at_centre + reach).min(1.0);
        let b = self.base + self.amplitude * (at_centre - reach).max(-1.0);
        (a.min(b), a.max(b))
    }
}

/// `inner * factor` (a negative inner density counts as 0 first).
#[derive(Clone, Debug)]
pub struct Scale<D>(pub D, pub f64);

impl<D: Density> Density for Scale<D> {
    // The inner density is sanitized first: a negative one times a negative factor must
    // stay 0, not turn positive behind the bounds' back.
    #[inline]
    fn density(&self, p: DVec2) -> f64 {
        sanitize(self.0.density(p)) * self.1
    }
    fn max_over(&self, min: DVec2, max: DVec2) -> f64 {
        sanitize(self.0.max_over(min, max)) * self.1.max(0.0)
    }
    fn min_over(&self, min: DVec2, max: DVec2) -> f64 {
        if self.1 >= 0.0 {
            sanitize(self.0.min_over(min, max)) * self.1
        } else {
            0.0
        }
    }
}

/// `a + b`.
#[derive(Clone, Debug)]
pub struct Sum<A, B>(pub A, pub B);

impl<A: Density, B: Density> Density for Sum<A, B> {
    #[inline]
    fn density(&self, p: DVec2) -> f64 {
        sanitize(self.0.density(p)) + sanitize(self.1.density(p))
    }
    fn max_over(&self, min: DVec2, max: DVec2) -> f64 {
        sanitize(self.0.max_over(min, max)) + sanitize(self.1.max_over(min, max))
    }
    fn min_over(&self, min: DVec2, max: DVec2) -> f64 {
        sanitize(self.0.min_over(min, max)) + sanitize(self.1.min_over(min, max))
    }
}

/// `a * b`.
#[derive(Clone, Debug)]
pub struct Product<A, B>(pub A, pub B);

impl<A: Density, B: Density> Density for Product<A, B> {
    #[inline]
    fn density(&self, p: DVec2) -> f64 {
        sanitize(self.0.density(p)) * sanitize(self.1.density(p))
    }
    fn max_over(&self, min: DVec2, max: DVec2) -> f64 {
        sanitize(self.0.max_over(min, max)) * sanitize(self.1.max_over(min, max))
    }
    fn min_over(&self, min: DVec2, max: DVec2) -> f64 {
        sanitize(self.0.min_over(min, max)) * sanitize(self.1.min_over(min, max))
    }
}

/// `inner` where `mask >= threshold`, zero elsewhere (exclusion zones, paths, water).
#[derive(Clone, Debug)]
pub struct Mask<D, M> {
    /// The density kept.
    pub inner: D,
    /// The mask density.
    pub mask: M,
    /// Mask values below this remove the density.
    pub threshold: f64,
}

impl<D: Density, M: Density> Density for Mask<D, M> {
    #[inline]
    fn density(&self, p: DVec2) -> f64 {
        if self.mask.density(p) >= self.threshold {
            self.inner.density(p)
        } else {
            0.0
        }
    }
    fn max_over(&self, min: DVec2, max: DVec2) -> f64 {
        if self.mask.max_over(min, max) >= self.threshold {
            self.inner.max_over(min, max)
        } else {
            0.0
        }
    }
    fn min_over(&self, min: DVec2, max: DVec2) -> f64 {
        if self.mask.min_over(min, max) >= self.threshold {
            self.inner.min_over(min, max)
        } else {
            0.0
        }
    }
}

/// `inner` except where `mask >= threshold` (painted exclusion zones: roads, clearings).
/// Its bound is `inner`'s: an exclusion can only remove points, so the bound stays
/// conservative without a minimum of the mask.
#[derive(Clone, Debug)]
pub struct Exclude<D, M> {
    /// The density kept outside the exclusion.
    pub inner: D,
    /// The exclusion mask.
    pub mask: M,
    /// Mask values at or above this remove the density.
    pub threshold: f64,
}

impl<D: Density, M: Density> Density for Exclude<D, M> {
    #[inline]
    fn density(&self, p: DVec2) -> f64 {
        if sanitize(self.mask.density(p)) >= self.threshold {
            0.0
        } else {
            self.inner.density(p)
        }
    }
    fn max_over(&self, min: DVec2, max: DVec2) -> f64 {
        self.inner.max_over(min, max)
    }
    fn min_over(&self, min: DVec2, max: DVec2) -> f64 {
        // Only where nothing can be excluded.
        if self.threshold > 0.0 && self.mask.max_over(min, max) < self.threshold {
            self.inner.min_over(min, max)
        } else {
            0.0
        }
    }
}

/// `inner` fading linearly from full at `near` to zero at `far` from `centre` (level of
/// detail by density around a viewer).
#[derive(Clone, Debug)]
pub struct DistanceFalloff<D> {
    /// The density faded.
    pub inner: D,
    /// Centre of the fall-off.
    pub centre: DVec2,
    /// Distance up to which the density is unchanged.
    pub near: f64,
    /// Distance from which the density is zero.
    pub far: f64,
}

impl<D> DistanceFalloff<D> {
    #[inline]
    fn factor(&self, distance: f64) -> f64 {
        if distance <= self.near {
            1.0
        } else if distance >= self.far {
            0.0
        } else {
            (self.far - distance) / (self.far - self.near)
        }
    }
}

impl<D: Density> Density for DistanceFalloff<D> {
    #[inline]
    fn density(&self, p: DVec2) -> f64 {
        self.inner.density(p) * self.factor(p.distance(self.centre))
    }
    fn max_over(&self, min: DVec2, max: DVec2) -> f64 {
        let nearest = self.centre.clamp(min, max);
        self.inner.max_over(min, max) * self.factor(nearest.distance(self.centre))
    }
    fn min_over(&self, min: DVec2, max: DVec2) -> f64 {
        let farthest = (min - self.centre).abs().max((max - self.centre).abs());
        sanitize(self.inner.min_over(min, max)) * self.factor(farthest.length())
    }
}

/// NaN and negative densities count as zero.
#[inline]
pub fn sanitize(v: f64) -> f64 {
    if v > 0.0 { v } else { 0.0 }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;

    /// Upper bounds hold within rounding; lower bounds exactly (queries take points below
    /// them without evaluating). Returns the share of rectangles with a positive lower bound.
    fn check_bound(d: &impl Density, rng: &mut Rng, world: f64) -> f64 {
        let mut useful = 0;
        for _ in 0..300 {
            let a = DVec2::new(rng.next_f64(), rng.next_f64()) * world;
            let ext = DVec2::new(rng.next_f64(), rng.next_f64()) * world * 0.2 * rng.next_f64();
            let b = a + ext;
            let bound = d.max_over(a, b);
            let low = sanitize(d.min_over(a, b));
            useful += usize::from(low > 0.0);
            for k in 0..40 {
                // Corners and edges too: bilinear blending is least exact there.
                let t = match k {
                    0 => DVec2::ZERO,
                    1 => DVec2::ONE,
                    2 => DVec2::X,
                    3 => DVec2::Y,
                    _ => DVec2::new(rng.next_f64(), rng.next_f64()),
                };
                let p = a + t * ext;
                let v = d.density(p);
                assert!(
                    bound >= v - 1e-9,
                    "bound {bound} < value {v} at {p:?} in {a:?}..{b:?}"
                );
                assert!(
                    low <= sanitize(v),
                    "lower bound {low} > value {v} at {p:?} in {a:?}..{b:?}"
                );
            }
        }
        useful as f64 / 300.0
    }

    #[test]
    fn image_maximum_is_conservative_and_sees_thin_strokes() {
        let (w, h) = (64u32, 48u32);
        let mut values = vec![0.0f32; (w * h) as usize];
        // A one-pixel vertical stroke.
        for y in 0..h {
            values[(y * w + 37) as usize] = 1.0;
        }
        let mut rng = Rng::new(1, 2);
        for v in values.iter_mut().filter(|v| **v == 0.0) {
            *v = (rng.next_f64() * 0.3) as f32;
        }
        let d = ImageDensity::from_values(
            w,
            h,
            &values,
            DVec2::new(-3.0, 2.0),
            DVec2::new(6.4, 4.8),
            100.0,
        )
        .unwrap();
        let useful = check_bound(&d, &mut rng, 6.0);
        assert!(
            useful > 0.2,
            "lower bounds positive in {useful} of rectangles"
        );
        // The stroke is 0.1 world units wide; any rectangle containing it sees density 100.
        let x = -3.0 + 6.4 * 37.5 / 64.0;
        assert!(d.max_over(DVec2::new(x - 2.0, 2.5), DVec2::new(x + 2.0, 3.0)) >= 100.0);
        assert!(d.max_over(DVec2::new(x - 0.01, 2.5), DVec2::new(x + 0.01, 2.6)) >= 100.0);
        assert_eq!(
            d.max_over(DVec2::new(100.0, 100.0), DVec2::new(101.0, 101.0)),
            0.0
        );
        assert_eq!(d.density(DVec2::new(-5.0, 0.0)), 0.0);
    }

    #[test]
    fn noise_maximum_is_conservative() {
        let d = NoiseDensity::new(7, 0.37, 5, 0.3, 0.8, 50.0);
        check_bound(&d, &mut Rng::new(2, 2), 40.0);
        // Small rectangles get useful lower bounds.
        let useful = check_bound(&d, &mut Rng::new(2, 3), 4.0);
        assert!(
            useful > 0.1,
            "lower bounds positive in {useful} of rectangles"
        );
    }

    #[test]
    fn combinators_keep_bounds() {
        let img = ImageDensity::from_values(
            2,
            2,
            &[0.0, 1.0, 0.5, 0.25],
            DVec2::ZERO,
            DVec2::splat(10.0),
            20.0,
        )
        .unwrap();
        let noise = NoiseDensity::new(3, 0.2, 3, 0.5, 0.5, 10.0);
        let mut rng = Rng::new(3, 3);
        check_bound(&Sum(img.clone(), noise.clone()), &mut rng, 10.0);
        check_bound(
            &Product(img.clone(), Scale(noise.clone(), 0.1)),
            &mut rng,
            10.0,
        );
        check_bound(
            &Mask {
                inner: noise.clone(),
                mask: img.clone(),
                threshold: 5.0,
            },
            &mut rng,
            10.0,
        );
        check_bound(
            &Exclude {
                inner: Sum(noise.clone(), Constant(3.0)),
                mask: img.clone(),
                threshold: 10.0,
            },
            &mut rng,
            10.0,
        );
        check_bound(&Scale(Constant(-2.0), -1.5), &mut rng, 10.0);
        check_bound(
            &DistanceFalloff {
                inner: Sum(noise.clone(), Constant(1.0)),
                centre: DVec2::splat(5.0),
                near: 1.0,
                far: 4.0,
            },
            &mut rng,
            10.0,
        );
        check_bound(
            &DistanceFalloff {
                inner: noise,
                centre: DVec2::splat(5.0),
                near: 1.0,
                far: 4.0,
            },
            &mut rng,
            10.0,
        );
    }

    #[test]
    fn bad_values_are_sanitized_or_rejected() {
        assert_eq!(sanitize(f64::NAN), 0.0);
        assert_eq!(sanitize(-3.0), 0.0);
        assert_eq!(sanitize(f64::INFINITY), f64::INFINITY);
        let d = ImageDensity::from_values(2, 1, &[f32::NAN, 7.0], DVec2::ZERO, DVec2::ONE, 1.0)
            .unwrap();
        assert!(d.max_over(DVec2::ZERO, DVec2::ONE) <= 1.0);
        assert_eq!(
            ImageDensity::from_values(0, 1, &[], DVec2::ZERO, DVec2::ONE, 1.0).unwrap_err(),
            ImageDensityError::Size(0, 1)
        );
        assert_eq!(
            ImageDensity::from_values(1, 1, &[0.5], DVec2::ZERO, DVec2::new(f64::NAN, 1.0), 1.0)
                .unwrap_err(),
            ImageDensityError::Rect
        );
        assert!(
            ImageDensity::from_bytes(b"not an image", false, DVec2::ZERO, DVec2::ONE, 1.0).is_err()
        );
    }
}
