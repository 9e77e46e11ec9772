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
//! let report = s.tone_report(&s.render(&s.dots, 2.0), 1);
//! assert!(report.blue.mean_abs < report.white.mean_abs);
//! ```

mod raster;
mod tone;

pub use raster::Grey;
pub use tone::{CoverageCurve, ToneError};

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
    /// The darkness of grey level `v`.
    pub fn darkness(&self, v: f32) -> f32 {
        let d = (self.contrast * (1.0 - v as f64)).clamp(0.0, 1.0);
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
}

impl Default for StippleSettings {
    fn default() -> Self {
        Self {
            dots: DotCount::Auto,
            tone: ToneMap::default(),
            seed: 0,
            scale: 2.0,
        }
    }
}

/// Why an image could not be stippled.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum StippleError {
    /// Nothing is dark: there is nothing to stipple.
    #[error("the image is white: nothing to stipple")]
    White,
    /// A setting out of range.
    #[error("{0}")]
    Setting(String),
    /// The image is empty or too large.
    #[error(transparent)]
    Image(#[from] ImageDensityError),
    /// The query failed (e.g. more points than its budget).
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
}

/// Stipples `image` (grey levels, row 0 at the top) with the tile set's blue noise.
pub fn stipple(
    image: &Grey,
    set: &TileSet,
    settings: &StippleSettings,
) -> Result<Stipple, StippleError> {
    check(image, settings)?;
    let tone = settings.tone;
    let target = Grey {
        values: image.values.iter().map(|&v| tone.darkness(v)).collect(),
        ..image.clone()
    };
    let ink: f64 = target.values.iter().map(|&v| v as f64).sum();
    if ink <= 0.0 {
        return Err(StippleError::White);
    }
    let wanted = match settings.dots {
        DotCount::Auto => Some((image.width * image.height).div_ceil(4)),
        DotCount::Points(n) => Some(n.max(1)),
        DotCount::Radius(_) => None,
    };
    let radius_for = |nominal_ink: f64, n: usize| (nominal_ink / (PI * n as f64)).sqrt();
    let mut radius = match (settings.dots, wanted) {
        (DotCount::Radius(r), _) => r,
        (_, Some(n)) => radius_for(ink, n),
        _ => unreachable!("a count or a radius"),
    };
    // Calibrate at the first guess of the radius; with a dot count, the nominal ink then
    // gives the radius, calibrated once more.
    let mut plan = Plan::new(set, settings, &target, radius)?;
    if let Some(n) = wanted {
        radius = radius_for(plan.nominal_ink(), n);
        plan = Plan::new(set, settings, &target, radius)?;
    }
    plan.place(image, radius, target)
}

fn check(image: &Grey, settings: &StippleSettings) -> Result<(), StippleError> {
    if image.width == 0 || image.height == 0 || image.values.len() != image.width * image.height {
        return Err(ImageDensityError::Size(image.width as u32, image.height as u32).into());
    }
    let positive = |v: f64| v.is_finite() && v > 0.0;
    let bad = |what: &str, v: f64| {
        Err(StippleError::Setting(format!(
            "{what} {v} must be positive"
        )))
    };
    if let DotCount::Radius(r) = settings.dots
        && !positive(r)
    {
        return bad("radius", r);
    }
    for (what, v) in [
        ("scale", settings.scale),
        ("gamma", settings.tone.gamma),
        ("contrast", settings.tone.contrast),
    ] {
        if !positive(v) {
            return bad(what, v);
        }
    }
    Ok(())
}

/// The sampler, coverage curve and nominal coverage map for one radius.
struct Plan {
    sampler: Sampler,
    curve: CoverageCurve,
    nominal: Grey,
}

impl Plan {
    fn new(
        set: &TileSet,
        settings: &StippleSettings,
        target: &Grey,
        radius: f64,
    ) -> Result<Self, StippleError> {
        // Base tiles are full at a light tone: darker tones come from subdivision levels.
        let full_tile = TILE_NOMINAL / (PI * radius * radius);
        let tile = (set.points_per_tile as f64 / full_tile).sqrt();
        let sampler = Sampler::new(set, settings.seed).with_tile_size(tile);
        let curve =
            CoverageCurve::measure(&sampler, radius, settings.scale, MAX_NOMINAL, CURVE_SAMPLES)?;
        let nominal = Grey {
            values: target
                .values
                .iter()
                .map(|&t| curve.nominal(t as f64) as f32)
                .collect(),
            ..target.clone()
        };
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

    /// Queries the dots.
    fn place(self, image: &Grey, radius: f64, target: Grey) -> Result<Stipple, StippleError> {
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
            DVec2::ZERO,
            size,
            scale,
        )?;
        let expected = self.nominal_ink() / (PI * radius * radius);
        let sampler = self
            .sampler
            .with_budget((expected as usize).saturating_mul(4).max(10_000));
        let mut points = Vec::with_capacity(expected as usize + expected as usize / 8);
        sampler.query(Rect::new(DVec2::ZERO, size)?, &density, &mut points)?;
        let dots = points
            .iter()
            .map(|p| DVec2::new(p.position.x, size.y - p.position.y))
            .collect();
        Ok(Stipple {
            dots,
            radius,
            target,
            curve: self.curve,
            nominal: self.nominal,
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
    /// image pixel, antialiased.
    pub fn render(&self, dots: &[DVec2], scale: f64) -> Grey {
        let (w, h) = self.raster_size(scale);
        let mut raster = Grey::filled(w, h, 0.0);
        for &d in dots {
            raster.dot(d * scale, self.radius * scale);
        }
        raster
    }

    fn raster_size(&self, scale: f64) -> (usize, usize) {
        let side = |n: usize| ((n as f64 * scale).round() as usize).max(1);
        (side(self.target.width), side(self.target.height))
    }

    /// Mean distance between dots where there is ink: `sqrt(inked area / dots)`, in image
    /// pixels.
    pub fn mean_spacing(&self) -> f64 {
        let inked = self.target.values.iter().filter(|&&t| t > 0.0).count();
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
    pub fn tone_report(&self, rendered: &Grey, seed: u64) -> ToneReport {
        let scale = rendered.width as f64 / self.target.width as f64;
        let sigma = self.mean_spacing() * scale;
        let target = self
            .target
            .resized(rendered.width, rendered.height)
            .blurred(sigma);
        let white = self.render(&self.white_noise(seed), scale).blurred(sigma);
        ToneReport {
            sigma,
            blue: ToneError::of_blurred(&rendered.blurred(sigma), &target),
            white: ToneError::of_blurred(&white, &target),
        }
    }
}
