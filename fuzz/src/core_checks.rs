//! Fuzz checks of `rwt_core`: the tile set loader, image densities, queries and stippling.
//! Each takes raw bytes, must never panic, and asserts what must hold for whatever input it
//! accepts. Budgets and sizes are small, so that each input runs in well under a
//! millisecond and a run reaches millions of inputs.

use glam::DVec2;
use rwt_core::density::Placement;
use rwt_core::density::{
    Constant, Density, DistanceFalloff, ImageDensity, NoiseDensity, NoiseParams, Product, Scale,
    Sum, from_fn, sanitize,
};
use rwt_core::query::{Point, Rect, Sampler};
use rwt_core::stipple::{DotCount, Grey, StippleLimits, StippleSettings, Stippler, ToneMap};
use rwt_core::tileset::TileSet;
use std::collections::HashSet;
use std::sync::OnceLock;

/// A sampler over the shipped set, prepared once (cloning and reseeding it is cheap).
fn embedded() -> Sampler {
    static SAMPLER: OnceLock<Sampler> = OnceLock::new();
    SAMPLER
        .get_or_init(|| Sampler::new(&TileSet::embedded(), 0))
        .clone()
}

/// Reads numbers off the input, zeros once it runs out.
pub struct Bytes<'a>(pub &'a [u8]);

impl Bytes<'_> {
    /// Up to `N` bytes, zero-padded.
    fn take<const N: usize>(&mut self) -> [u8; N] {
        let mut out = [0; N];
        let n = N.min(self.0.len());
        out[..n].copy_from_slice(&self.0[..n]);
        self.0 = &self.0[n..];
        out
    }

    /// Any f64, NaN and infinities included.
    pub fn f64(&mut self) -> f64 {
        f64::from_le_bytes(self.take())
    }

    /// A byte.
    pub fn u8(&mut self) -> u8 {
        self.take::<1>()[0]
    }

    /// A word.
    pub fn u64(&mut self) -> u64 {
        u64::from_le_bytes(self.take())
    }

    /// A "reasonable" f64 most of the time and an arbitrary one otherwise, so the fuzzer
    /// reaches both the ordinary paths and the edge cases.
    pub fn number(&mut self) -> f64 {
        match self.u8() % 4 {
            0 => self.f64(),
            k => (self.u8() as i8 as f64) * 10f64.powi(k as i32 - 2),
        }
    }
}

/// What every accepted query must satisfy: points inside the rectangle, unique identities,
/// each present because the density at it exceeds its threshold, and the same output twice.
fn check_query<D: Density + ?Sized>(sampler: &Sampler, rect: Rect, density: &D) -> bool {
    let mut first = Vec::new();
    let Ok(n) = sampler.query(rect, density, &mut first) else {
        return false;
    };
    assert_eq!(n, first.len());
    let mut ids = HashSet::new();
    for p in &first {
        assert!(rect.contains(p.position), "{p:?} outside {rect:?}");
        assert!(ids.insert(p.id), "duplicate {:?}", p.id);
        let d = sanitize(density.density(p.position));
        // The rule is `density x area > rank`; the threshold is that divided by the area.
        assert!(d >= p.threshold * (1.0 - 1e-12), "{p:?} at density {d}");
    }
    // Again with every candidate evaluated: the same output, so lower bounds never took a
    // point the density would not (and the query is deterministic).
    let mut second: Vec<Point> = Vec::new();
    sampler
        .query(rect, &Evaluated(density), &mut second)
        .unwrap();
    assert_eq!(first, second);
    true
}

/// Hides a density's lower bound.
struct Evaluated<'a, D: ?Sized>(&'a D);

impl<D: Density + ?Sized> Density for Evaluated<'_, D> {
    fn density(&self, p: DVec2) -> f64 {
        self.0.density(p)
    }
    fn max_over(&self, min: DVec2, max: DVec2) -> f64 {
        self.0.max_over(min, max)
    }
}

/// A tile set file: rejected with an error, or loaded and then safe to query. Returns
/// whether it was accepted.
pub fn tileset(data: &[u8]) -> bool {
    let Ok(set) = TileSet::from_ron_bytes(data) else {
        return false;
    };
    let sampler = Sampler::new(&set, 3).with_budget(20_000);
    let rect = Rect::new(DVec2::splat(-1.3), DVec2::splat(1.7)).unwrap();
    check_query(&sampler, rect, &Constant(500.0));
    check_query(&sampler, rect, &Constant(40_000.0));
    true
}

/// Image bytes as a density: decoded or rejected; when decoded, bounded and queryable.
pub fn image_density(data: &[u8]) -> bool {
    let mut b = Bytes(data);
    let invert = b.u8() & 1 == 1;
    let (origin, size, scale) = (
        DVec2::new(b.number(), b.number()),
        DVec2::new(b.number(), b.number()),
        b.number(),
    );
    let Ok(d) = ImageDensity::from_bytes(
        b.0,
        invert,
        Placement {
            min: origin,
            size,
            scale,
        },
    ) else {
        return false;
    };
    let rect = Rect::new(DVec2::splat(-2.0), DVec2::splat(2.0)).unwrap();
    let max = d.max_over(rect.min(), rect.max());
    for i in 0..16 {
        let p = rect.min() + DVec2::new((i % 4) as f64 + 0.3, (i / 4) as f64 + 0.6);
        let v = d.density(p);
        assert!(
            sanitize(v) <= sanitize(max),
            "density {v} above its maximum {max}"
        );
    }
    check_query(&embedded().with_seed(1).with_budget(50_000), rect, &d)
}

/// One density built from the input: constant, noise, a small image, a closure or a
/// combination, with any values.
fn density(b: &mut Bytes, depth: u32) -> Box<dyn Density + Send + Sync> {
    let kind = if depth > 2 { b.u8() % 4 } else { b.u8() % 8 };
    match kind {
        0 => Box::new(Constant(b.number())),
        1 => Box::new(NoiseDensity::new(NoiseParams {
            seed: b.u8() as u32,
            frequency: b.number(),
            octaves: b.u8() as usize,
            base: b.number(),
            amplitude: b.number(),
            scale: b.number(),
        })),
        2 => {
            let (w, h) = (b.u8() as u32 % 9, b.u8() as u32 % 9);
            let values: Vec<f32> = (0..w * h).map(|_| b.number() as f32).collect();
            let (origin, size) = (
                DVec2::new(b.number(), b.number()),
                DVec2::new(b.number(), b.number()),
            );
            match ImageDensity::from_values(
                w,
                h,
                &values,
                Placement {
                    min: origin,
                    size,
                    scale: b.number(),
                },
            ) {
                Ok(d) => Box::new(d),
                Err(_) => Box::new(Constant(0.0)),
            }
        }
        3 => {
            let (v, bound) = (b.number(), b.number());
            Box::new(from_fn(move |p: DVec2| v * p.x.sin(), bound))
        }
        4 => Box::new(Scale(density(b, depth + 1), b.number())),
        5 => Box::new(Sum(density(b, depth + 1), density(b, depth + 1))),
        6 => Box::new(Product(density(b, depth + 1), density(b, depth + 1))),
        _ => Box::new(DistanceFalloff {
            inner: density(b, depth + 1),
            centre: DVec2::new(b.number(), b.number()),
            near: b.number(),
            far: b.number(),
        }),
    }
}

/// A query with any rectangle, density, tile size, seed and budget (the budget is kept
/// at 20 000 points or tile visits, so that every input runs in a fraction of a
/// millisecond). Returns whether the query was served.
pub fn query(data: &[u8]) -> bool {
    let mut b = Bytes(data);
    let seed = b.u64();
    let tile = b.number();
    let budget = (b.u64() % 20_001) as usize;
    let (x0, y0, x1, y1) = (b.number(), b.number(), b.number(), b.number());
    let Ok(rect) = Rect::new(DVec2::new(x0, y0), DVec2::new(x1, y1)) else {
        return false;
    };
    let d = density(&mut b, 0);
    let sampler = embedded()
        .with_seed(seed)
        .with_tile_size(tile)
        .with_budget(budget);
    let served = check_query(&sampler, rect, &d);
    let classes = [density(&mut b, 1), density(&mut b, 1)];
    let _ = sampler.query_classes(rect, &classes, |p| {
        assert!((p.class as usize) < classes.len());
    });
    served
}

/// The shipped set prepared for stippling, once.
fn stippler() -> &'static Stippler {
    static STIPPLER: OnceLock<Stippler> = OnceLock::new();
    STIPPLER.get_or_init(|| Stippler::new(&TileSet::embedded()))
}

/// A small grey image (up to 12 x 12) of any values (NaN and infinities too) stippled with
/// any settings under small limits (500 dots, 1024 raster pixels): refused with an error, or
/// dots inside the image that render within the limits.
pub fn stipple(data: &[u8]) -> bool {
    let mut b = Bytes(data);
    let (w, h) = ((b.u8() % 13) as usize, (b.u8() % 13) as usize);
    let dots = match b.u8() % 3 {
        0 => DotCount::Auto,
        1 => DotCount::Points((b.u64() % 1_000) as usize),
        _ => DotCount::Radius(b.number()),
    };
    let settings = StippleSettings {
        dots,
        tone: ToneMap {
            gamma: b.number(),
            contrast: b.number(),
        },
        seed: b.u8() as u64,
        scale: b.number(),
        // Small: an accepted input places at most a few hundred dots (its calibration,
        // about ten times as many), so a run reaches a million inputs.
        limits: StippleLimits {
            max_dots: 500,
            max_raster_pixels: 1 << 10,
            max_image_pixels: 1 << 10,
        },
    };
    let values = (0..w * h).map(|_| b.number() as f32).collect();
    let image = Grey {
        width: w,
        height: h,
        values,
    };
    let Ok(s) = stippler().stipple(&image, &settings) else {
        return false;
    };
    assert!(
        s.radius.is_finite() && s.radius > 0.0,
        "radius {}",
        s.radius
    );
    assert!(!s.dots.is_empty());
    // Dots are admitted by their expected number; a query's count varies a little.
    assert!(
        s.dots.len() <= 2 * settings.limits.max_dots,
        "{} dots",
        s.dots.len()
    );
    for d in &s.dots {
        assert!(
            d.x >= 0.0 && d.y >= 0.0 && d.x <= w as f64 && d.y <= h as f64,
            "{d} outside {w}x{h}"
        );
    }
    let raster = s.render(&s.dots, settings.scale).expect("admitted raster");
    assert!(raster.values.len() as u64 <= settings.limits.max_raster_pixels);
    assert!(raster.values.iter().all(|v| (0.0..=1.0).contains(v)));
    true
}
