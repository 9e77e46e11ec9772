//! Stippling that reproduces tone (paper figure 11): black dots of one radius on white,
//! placed by the sampler's blue noise, so many that the ink covering each place equals the
//! image's darkness there.
//!
//! Dots crowd and overlap as the tone darkens, so ink coverage is not proportional to dot
//! density: [`CoverageCurve`] measures how much ink the sampler's dots of the chosen radius
//! lay down at each density (rendering uniform patches the way the stipple is rendered), and
//! the density map is the inverse of that curve applied to the darkness. White stays white
//! (no dots where the darkness is 0).
//!
//! ```
//! use rwt_core::stipple::{Grey, StippleSettings, stipple};
//! use rwt_core::TileSet;
//! // A grey ramp: white at the left, black at the right.
//! let (w, h) = (48, 16);
//! let values = (0..w * h).map(|i| 1.0 - (i % w) as f32 / (w - 1) as f32).collect();
//! let image = Grey { width: w, height: h, values };
//! let s = stipple(&image, &TileSet::embedded(), &StippleSettings::default()).unwrap();
//! let report = s.tone_report(&s.render(&s.dots, 2.0).unwrap(), 1).unwrap();
//! assert!(report.blue.mean_abs < report.white.mean_abs);
//! ```

mod limits;
mod raster;
mod tone;

pub use limits::{
    DEFAULT_MAX_DOTS, DEFAULT_MAX_IMAGE_PIXELS, DEFAULT_MAX_RASTER_PIXELS, StippleLimits,
};
pub use raster::Grey;
pub use tone::{CoverageCurve, Patch, ToneError};

use crate::density::Placement;
use crate::density::{ImageDensity, ImageDensityError};
use crate::query::{QueryError, Rect, Sampler};
use crate::rng::Rng;
use crate::tileset::TileSet;
use glam::DVec2;
use std::f64::consts::PI;

/// How an image's grey level `v` (0 black .. 1 white) becomes darkness (ink coverage):
/// `(contrast * (1 - v))^gamma`, clamped to `[0, 1]`; white stays white.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ToneMap {
    /// Exponent: above 1 lightens mid-tones, below 1 darkens them.
    pub gamma: f64,
    /// Darkness multiplier before the exponent: above 1 darkens, below 1 lightens.
    pub contrast: f64,
}

impl Default for ToneMap {
    fn default() -> Self {
        Self {
            gamma: 1.0,
            contrast: 1.0,
        }
    }
}

impl ToneMap {
    /// The darkness of grey level `v` (a NaN grey is white).
    pub fn darkness(&self, v: f32) -> f32 {
        let d = (self.contrast * (1.0 - v as f64)).clamp(0.0, 1.0);
        if d.is_nan() {
            return 0.0;
        }
        d.powf(self.gamma) as f32
    }
}

/// How many dots, and how large.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum DotCount {
    /// One dot per four image pixels; the radius follows from the tone.
    Auto,
    /// About this many dots; the radius follows from the tone.
    Points(usize),
    /// Dots of this radius (image pixels); their number follows from the tone.
    Radius(f64),
}

/// What [`stipple`] is asked for.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StippleSettings {
    /// Dot count or radius.
    pub dots: DotCount,
    /// Grey to darkness.
    pub tone: ToneMap,
    /// Tiling seed.
    pub seed: u64,
    /// Raster pixels per image pixel the dots are calibrated (and should be rendered) at.
    pub scale: f64,
    /// The most dots and raster pixels it may take.
    pub limits: StippleLimits,
}

impl Default for StippleSettings {
    fn default() -> Self {
        Self {
            dots: DotCount::Auto,
            tone: ToneMap::default(),
            seed: 0,
            scale: 2.0,
            limits: StippleLimits::default(),
        }
    }
}

/// Why an image could not be stippled.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum StippleError {
    /// Nothing is dark: there is nothing to stipple.
    #[error("the image is white: nothing to stipple")]
    White,
    /// A setting that must be positive and finite is not.
    #[error("{setting} {value} must be positive and finite")]
    Setting {
        /// Which setting.
        setting: &'static str,
        /// Its value.
        value: f64,
    },
    /// More dots than [`StippleLimits::max_dots`].
    #[error(
        "the stipple needs about {dots:.0} dots, over the limit of {limit} (raise \
         StippleLimits::max_dots, rwt stipple --max-dots; or ask for fewer dots or a larger radius)"
    )]
    TooManyDots {
        /// Dots it would take.
        dots: f64,
        /// The limit.
        limit: usize,
    },
    /// A rendered raster larger than [`StippleLimits::max_raster_pixels`].
    #[error(
        "a {width:.0}x{height:.0} raster is over the limit of {limit} pixels (raise \
         StippleLimits::max_raster_pixels, rwt stipple --max-raster-pixels; or lower the scale)"
    )]
    RasterTooLarge {
        /// Raster width at the scale asked for.
        width: f64,
        /// Raster height.
        height: f64,
        /// The limit.
        limit: u64,
    },
    /// The image has more pixels than [`StippleLimits::max_image_pixels`].
    #[error(
        "a {width}x{height} image is over the limit of {limit} pixels to stipple (raise \
         StippleLimits::max_image_pixels, rwt stipple --max-image-pixels; or scale the image down)"
    )]
    ImageTooLarge {
        /// Image width.
        width: usize,
        /// Image height.
        height: usize,
        /// The limit.
        limit: u64,
    },
    /// The system refused memory the limits admitted.
    #[error("out of memory: {what} needs {bytes:.3e} bytes (lower the limits or the request)")]
    OutOfMemory {
        /// What was being allocated.
        what: &'static str,
        /// Bytes asked for.
        bytes: f64,
    },
    /// Dots too small to draw at the scale asked for: the page would be a grey wash or blank.
    #[error(
        "dots of radius {radius:.3e} px are {drawn:.3e} raster pixels across at scale {scale:e}, \
         under {MIN_DRAWN_DIAMETER} (raise the scale, or ask for fewer dots or a larger radius)"
    )]
    DotsTooSmall {
        /// Dot radius in image pixels.
        radius: f64,
        /// Dot diameter in raster pixels.
        drawn: f64,
        /// The scale.
        scale: f64,
    },
    /// Dots wider than the image's shorter side: they cannot lay down its tone.
    #[error(
        "dots of radius {radius:.3e} px do not fit an image {side} px across (ask for more dots \
         or a smaller radius)"
    )]
    DotsTooLarge {
        /// Dot radius in image pixels.
        radius: f64,
        /// The image's shorter side in pixels.
        side: usize,
    },
    /// The image has ink, but no dot fell on it: too few dots for its size.
    #[error("no dot landed (about {expected:.2} expected): ask for more dots or a smaller radius")]
    NoDots {
        /// Dots expected.
        expected: f64,
    },
    /// The image is empty or too large.
    #[error(transparent)]
    Image(#[from] ImageDensityError),
    /// The query failed.
    #[error(transparent)]
    Query(#[from] QueryError),
}

/// Nominal coverage (density times dot area) of the darkest tone the stippler aims at:
/// past it, more dots add almost no ink.
const MAX_NOMINAL: f64 = 3.5;
/// Nominal coverage at which a base tile's points are all present. Tone errors on the
/// test photographs (sphere, landscape) against this value, as measured: 0.1: 0.025, 0.030;
/// 0.25: 0.024, 0.028; 0.5: 0.025, 0.028; 1: 0.026, 0.031; 3.5 (the darkest tone): 0.028,
/// 0.034 (see `docs/stippling.md`).
const TILE_NOMINAL: f64 = 0.5;
/// Samples of the coverage curve.
const CURVE_SAMPLES: usize = 35;
/// The image is seen through a Gaussian of this many dot radii (about 0.6 of the dot
/// spacing at mid grey) before its tone is turned into dots: detail finer than the dots
/// (halftone screens, one-pixel stripes) becomes its mean tone, as the eye sees it, instead
/// of driving the coverage curve to its extremes pixel by pixel (a 50 % ordered dither came
/// out at 4 % grey without it). Measured in `docs/stippling.md`.
const PREFILTER_RADII: f64 = 1.5;
/// Fewest dots [`DotCount::Auto`] places, so that tiny images still get their tone.
const MIN_AUTO_DOTS: usize = 64;

/// Smallest dot diameter in raster pixels that is drawn: dots are rasterised with 4 x 4
/// samples a pixel, and a smaller one may fall between them (a blank page at a tiny scale).
pub const MIN_DRAWN_DIAMETER: f64 = 0.25;

/// Dot radius, as a fraction of the image's shorter side, that automatic dot counts keep
/// under; twice it is refused. Dots clipped by the image's border lose ink the coverage
/// curve does not know of (a black 20000 x 1 image came out mean grey 0.225).
const MAX_RADIUS_PER_SIDE: f64 = 0.125;

/// A stippled image: dot centres and radius in image pixels (x right, y down).
#[derive(Clone, Debug)]
pub struct Stipple {
    /// Dot centres.
    pub dots: Vec<DVec2>,
    /// Dot radius.
    pub radius: f64,
    /// The darkness the dots reproduce (the image through the tone map).
    pub target: Grey,
    /// Ink coverage against nominal coverage for these dots.
    pub curve: CoverageCurve,
    /// Nominal coverage the dots are placed for, per image pixel.
    nominal: Grey,
    /// What it may allocate when rendered.
    limits: StippleLimits,
}

/// Stipples `image` (grey levels, row 0 at the top) with the tile set's blue noise (see
/// [`Stippler::stipple`]; a [`Stippler`] prepares the tile set once for many images).
pub fn stipple(
    image: &Grey,
    set: &TileSet,
    settings: &StippleSettings,
) -> Result<Stipple, StippleError> {
    Stippler::new(set).stipple(image, settings)
}

/// A tile set prepared for stippling: its sampler is built once, so that stippling many
/// images (the frames of a video, a batch of prints) costs only the stipples.
#[derive(Clone, Debug)]
pub struct Stippler {
    sampler: Sampler,
}

impl Stippler {
    /// Prepares `set`.
    pub fn new(set: &TileSet) -> Self {
        Self {
            sampler: Sampler::new(set, 0),
        }
    }

    /// Stipples `image` (grey levels, row 0 at the top). The dots and the raster are
    /// admitted against [`StippleSettings::limits`] before anything is allocated for them.
    pub fn stipple(
        &self,
        image: &Grey,
        settings: &StippleSettings,
    ) -> Result<Stipple, StippleError> {
        check(image, settings)?;
        let tone = settings.tone;
        // The ink is known before anything image-sized is allocated.
        let ink: f64 = image.values.iter().map(|&v| tone.darkness(v) as f64).sum();
        if ink <= 0.0 {
            return Err(StippleError::White);
        }
        let short = image.width.min(image.height) as f64;
        let wanted = match settings.dots {
            DotCount::Auto => {
                // Enough dots that each fits the image's shorter side.
                let largest = MAX_RADIUS_PER_SIDE * short;
                let fitting = (ink / (PI * largest * largest)).ceil();
                settings.limits.dots(fitting)?;
                Some(
                    (image.width * image.height)
                        .div_ceil(4)
                        .max(MIN_AUTO_DOTS)
                        .max(fitting as usize),
                )
            }
            DotCount::Points(n) => Some(n),
            DotCount::Radius(_) => None,
        };
        let radius_for = |nominal_ink: f64, n: usize| (nominal_ink / (PI * n as f64)).sqrt();
        let mut radius = match (settings.dots, wanted) {
            (DotCount::Radius(r), _) => {
                // Dots lay down at most their nominal ink: at least this many are needed.
                settings.limits.dots(ink / (PI * r * r))?;
                r
            }
            (_, Some(n)) => radius_for(ink, n),
            _ => unreachable!("a count or a radius"),
        };
        // (Not `..image.clone()`: that copies the values it replaces.)
        let target = image.map(|v| tone.darkness(v));
        // What the dots reproduce: the darkness as seen at the scale of the dots.
        let seen = target.blurred(PREFILTER_RADII * radius);
        // Calibrate at the first guess of the radius; with a dot count, the nominal ink
        // then gives the radius, calibrated once more.
        let mut plan = Plan::new(&self.sampler, settings, &seen, radius)?;
        if let Some(n) = wanted {
            radius = radius_for(plan.nominal_ink(), n);
            plan = Plan::new(&self.sampler, settings, &seen, radius)?;
        }
        settings.fits(radius, image)?;
        plan.place(image, radius, target, settings.limits)
    }
}

fn check(image: &Grey, settings: &StippleSettings) -> Result<(), StippleError> {
    if image.width == 0 || image.height == 0 || image.values.len() != image.width * image.height {
        return Err(ImageDensityError::Size(image.width as u32, image.height as u32).into());
    }
    settings.admit(image.width, image.height)
}

impl StippleSettings {
    /// Whether dots of `radius` can be drawn at the scale and fit in the image.
    fn fits(&self, radius: f64, image: &Grey) -> Result<(), StippleError> {
        let drawn = 2.0 * radius * self.scale;
        if drawn < MIN_DRAWN_DIAMETER {
            return Err(StippleError::DotsTooSmall {
                radius,
                drawn,
                scale: self.scale,
            });
        }
        let side = image.width.min(image.height);
        // Automatic counts aim at half of this; calibration moves a radius by a few percent.
        if radius > 2.0 * MAX_RADIUS_PER_SIDE * side as f64 {
            return Err(StippleError::DotsTooLarge { radius, side });
        }
        Ok(())
    }

    /// The checks that need only the image's size: numbers in range, and the raster and
    /// the dot count (of [`DotCount::Auto`] and [`DotCount::Points`]) within the limits.
    /// [`stipple`] makes them first; a tool makes them from an image file's header, before
    /// it decodes the image.
    pub fn admit(&self, width: usize, height: usize) -> Result<(), StippleError> {
        let positive = |v: f64| v.is_finite() && v > 0.0;
        let mut numbers = vec![
            ("scale", self.scale),
            ("gamma", self.tone.gamma),
            ("contrast", self.tone.contrast),
        ];
        match self.dots {
            DotCount::Radius(r) => numbers.push(("radius", r)),
            DotCount::Points(n) => numbers.push(("points", n as f64)),
            DotCount::Auto => {}
        }
        if let Some(&(setting, value)) = numbers.iter().find(|(_, v)| !positive(*v)) {
            return Err(StippleError::Setting { setting, value });
        }
        self.limits.image(width, height)?;
        self.limits.raster(width, height, self.scale)?;
        match self.dots {
            DotCount::Points(n) => self.limits.dots(n as f64),
            DotCount::Auto => self.limits.dots((width * height).div_ceil(4) as f64),
            DotCount::Radius(_) => Ok(()),
        }
    }
}

/// The sampler, coverage curve and nominal coverage map for one radius.
struct Plan {
    sampler: Sampler,
    curve: CoverageCurve,
    nominal: Grey,
}

impl Plan {
    fn new(
        base: &Sampler,
        settings: &StippleSettings,
        target: &Grey,
        radius: f64,
    ) -> Result<Self, StippleError> {
        // Base tiles are full at a light tone: darker tones come from subdivision levels.
        let full_tile = TILE_NOMINAL / (PI * radius * radius);
        let tile = (base.points_per_tile() as f64 / full_tile).sqrt();
        let sampler = base.clone().with_seed(settings.seed).with_tile_size(tile);
        let patch = Patch {
            radius,
            scale: settings.scale,
            extent: target.width.max(target.height) as f64,
        };
        let curve = CoverageCurve::measure(&sampler, patch, MAX_NOMINAL, CURVE_SAMPLES)?;
        let nominal = target.map(|t| curve.nominal(t as f64) as f32);
        Ok(Self {
            sampler,
            curve,
            nominal,
        })
    }

    /// Nominal ink in pixel units: dots times dot area.
    fn nominal_ink(&self) -> f64 {
        self.nominal.values.iter().map(|&v| v as f64).sum()
    }

    /// Queries the dots, once their expected number is within the limits.
    fn place(
        self,
        image: &Grey,
        radius: f64,
        target: Grey,
        limits: StippleLimits,
    ) -> Result<Stipple, StippleError> {
        let size = DVec2::new(image.width as f64, image.height as f64);
        let unit: Vec<f32> = self
            .nominal
            .values
            .iter()
            .map(|&a| (a as f64 / MAX_NOMINAL) as f32)
            .collect();
        let scale = MAX_NOMINAL / (PI * radius * radius);
        let density = ImageDensity::from_values(
            image.width as u32,
            image.height as u32,
            &unit,
            Placement {
                min: DVec2::ZERO,
                size,
                scale,
            },
        )?;
        let expected = self.nominal_ink() / (PI * radius * radius);
        limits.dots(expected)?;
        let rect = Rect::new(DVec2::ZERO, size)?;
        // The dots were admitted against the limits; the query's own budget also counts
        // tile visits, which fine detail multiplies.
        let work = self.sampler.work_bound(&rect, &density);
        let sampler = self
            .sampler
            .with_budget((expected * 4.0).max(work * 1.01).max(10_000.0) as usize);
        let mut dots = limits::reserve(expected as usize + expected as usize / 8, "the dots")?;
        sampler.query_with(rect, &density, |p| {
            dots.push(DVec2::new(p.position.x, size.y - p.position.y));
        })?;
        if dots.is_empty() {
            return Err(StippleError::NoDots { expected });
        }
        Ok(Stipple {
            dots,
            radius,
            target,
            curve: self.curve,
            nominal: self.nominal,
            limits,
        })
    }
}

/// A stipple's tone error next to a white-noise stipple's with the same dots.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ToneReport {
    /// The blur both are compared at: the mean dot spacing, in raster pixels.
    pub sigma: f64,
    /// The blue-noise stipple.
    pub blue: ToneError,
    /// As many dots of the same radius placed by white noise with the same density.
    pub white: ToneError,
}

impl Stipple {
    /// The dots rendered as ink coverage (0 white .. 1 black) at `scale` raster pixels per
    /// image pixel, antialiased; a raster over [`StippleLimits::max_raster_pixels`] is
    /// refused before it is allocated.
    pub fn render(&self, dots: &[DVec2], scale: f64) -> Result<Grey, StippleError> {
        if !(scale.is_finite() && scale > 0.0) {
            return Err(StippleError::Setting {
                setting: "scale",
                value: scale,
            });
        }
        let (w, h) = self
            .limits
            .raster(self.target.width, self.target.height, scale)?;
        self.render_at(dots, w, h, scale)
    }

    fn render_at(
        &self,
        dots: &[DVec2],
        w: usize,
        h: usize,
        scale: f64,
    ) -> Result<Grey, StippleError> {
        let mut values = limits::reserve(w * h, "the rendered raster")?;
        values.resize(w * h, 0.0);
        let mut raster = Grey {
            width: w,
            height: h,
            values,
        };
        for &d in dots {
            raster.dot(d * scale, self.radius * scale);
        }
        Ok(raster)
    }

    /// Mean distance between dots where there is ink: `sqrt(inked area / dots)`, in image
    /// pixels. The inked area is where the dots place ink, the image seen at their scale (a
    /// dither's white pixels between black ones are inked area).
    pub fn mean_spacing(&self) -> f64 {
        let inked = self.nominal.values.iter().filter(|&&t| t > 0.0).count();
        (inked as f64 / self.dots.len().max(1) as f64).sqrt()
    }

    /// As many dots as this stipple has, placed by white noise with the same density.
    pub fn white_noise(&self, seed: u64) -> Vec<DVec2> {
        let a = &self.nominal;
        let top = a.values.iter().copied().fold(0.0f32, f32::max);
        let mut rng = Rng::new(seed, 0x5717_991e);
        let mut dots = Vec::with_capacity(self.dots.len());
        while dots.len() < self.dots.len() && top > 0.0 {
            let p = DVec2::new(
                rng.next_f64() * a.width as f64,
                rng.next_f64() * a.height as f64,
            );
            if rng.next_f64() * (top as f64) < a.sample(p) as f64 {
                dots.push(p);
            }
        }
        dots
    }

    /// Tone error of this stipple, `rendered` as [`Stipple::render`] draws its dots (at the
    /// scale to compare at), and of a white-noise stipple with the same dots rendered alike;
    /// each blurred by the mean dot spacing against the target blurred the same way.
    pub fn tone_report(&self, rendered: &Grey, seed: u64) -> Result<ToneReport, StippleError> {
        let scale = rendered.width as f64 / self.target.width as f64;
        let sigma = self.mean_spacing() * scale;
        // Blurred in place, one raster-sized buffer at a time beside `rendered`.
        let mut target = self.target.resized(rendered.width, rendered.height);
        target.blur(sigma);
        let blue = ToneError::of_blurred(&rendered.blurred(sigma), &target);
        let mut white = self.render_at(
            &self.white_noise(seed),
            rendered.width,
            rendered.height,
            scale,
        )?;
        white.blur(sigma);
        Ok(ToneReport {
            sigma,
            blue,
            white: ToneError::of_blurred(&white, &target),
        })
    }
}
