//! What one stipple may allocate: its dots and its rasters are admitted against limits
//! before any memory is taken for them.

use super::StippleError;

/// Default [`StippleLimits::max_dots`]: 4 million dots (64 MB of positions; a 4000 x 4000
/// image at the default one dot per four pixels).
pub const DEFAULT_MAX_DOTS: usize = 4_000_000;

/// Default [`StippleLimits::max_raster_pixels`]: 2^24 pixels (4096 x 4096; a raster takes 4
/// bytes a pixel, and rendering with its tone report holds three at a time).
pub const DEFAULT_MAX_RASTER_PIXELS: u64 = 1 << 24;

/// Default [`StippleLimits::max_image_pixels`]: 2^22 pixels (2048 x 2048). A stipple holds
/// about five image-sized rasters of 4 bytes a pixel and an image density of 5.3. With the
/// default raster limit, `rwt stipple` of a black 2048 x 2048 image peaks at 310 MB,
/// measured.
pub const DEFAULT_MAX_IMAGE_PIXELS: u64 = 1 << 22;

/// The most a stipple may take: dots, pixels of the image it works on, and pixels of the
/// rasters it renders. Raise them for large prints; the errors say which one was reached.
/// Whatever they admit is still allocated fallibly: what the system cannot give is
/// [`StippleError::OutOfMemory`], never an abort.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StippleLimits {
    /// Most dots.
    pub max_dots: usize,
    /// Most pixels of a rendered raster (image pixels times the scale, squared).
    pub max_raster_pixels: u64,
    /// Most pixels of the image stippled.
    pub max_image_pixels: u64,
}

impl Default for StippleLimits {
    fn default() -> Self {
        Self {
            max_dots: DEFAULT_MAX_DOTS,
            max_raster_pixels: DEFAULT_MAX_RASTER_PIXELS,
            max_image_pixels: DEFAULT_MAX_IMAGE_PIXELS,
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

    /// Refuses an image of more pixels than the limit.
    pub fn image(&self, width: usize, height: usize) -> Result<(), StippleError> {
        if width as u64 * height as u64 > self.max_image_pixels {
            return Err(StippleError::ImageTooLarge {
                width,
                height,
                limit: self.max_image_pixels,
            });
        }
        Ok(())
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

/// `n` values of `T` allocated fallibly: [`StippleError::OutOfMemory`] when the system
/// refuses (a limit raised past what the machine holds), instead of an abort.
pub(super) fn reserve<T>(n: usize, what: &'static str) -> Result<Vec<T>, StippleError> {
    let mut v = Vec::new();
    v.try_reserve_exact(n)
        .map_err(|_| StippleError::OutOfMemory {
            what,
            bytes: n as f64 * std::mem::size_of::<T>() as f64,
        })?;
    Ok(v)
}
