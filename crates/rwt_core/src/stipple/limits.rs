//! What one stipple may allocate: its dots and its rasters are admitted against limits
//! before any memory is taken for them.

use super::StippleError;

/// Default [`StippleLimits::max_dots`]: 4 million dots (64 MB of positions; a 4000 x 4000
/// image at the default one dot per four pixels).
pub const DEFAULT_MAX_DOTS: usize = 4_000_000;

/// Default [`StippleLimits::max_raster_pixels`]: 2^26 pixels (8192 x 8192; a raster takes 4
/// bytes a pixel, and the tone report holds about four at a time).
pub const DEFAULT_MAX_RASTER_PIXELS: u64 = 1 << 26;

/// The most a stipple may produce: dots, and pixels of the rasters it renders. Raise them
/// for large prints; the errors say which one was reached.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StippleLimits {
    /// Most dots.
    pub max_dots: usize,
    /// Most pixels of a rendered raster (image pixels times the scale, squared).
    pub max_raster_pixels: u64,
}

impl Default for StippleLimits {
    fn default() -> Self {
        Self {
            max_dots: DEFAULT_MAX_DOTS,
            max_raster_pixels: DEFAULT_MAX_RASTER_PIXELS,
        }
    }
}

impl StippleLimits {
    /// The raster size of an image of `width x height` pixels at `scale` raster pixels per
    /// image pixel, when it is within the limit.
    pub fn raster(
        &self,
        width: usize,
        height: usize,
        scale: f64,
    ) -> Result<(usize, usize), StippleError> {
        let side = |n: usize| (n as f64 * scale).round().max(1.0);
        let (w, h) = (side(width), side(height));
        if (w * h).is_nan() || w * h > self.max_raster_pixels as f64 {
            return Err(StippleError::RasterTooLarge {
                width: w,
                height: h,
                limit: self.max_raster_pixels,
            });
        }
        Ok((w as usize, h as usize))
    }

    /// Refuses `dots` expected dots over the limit.
    pub fn dots(&self, dots: f64) -> Result<(), StippleError> {
        if dots.is_nan() || dots > self.max_dots as f64 {
            return Err(StippleError::TooManyDots {
                dots,
                limit: self.max_dots,
            });
        }
        Ok(())
    }
}
