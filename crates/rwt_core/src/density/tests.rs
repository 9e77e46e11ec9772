//! Bounds and sanitizing of every shipped density.

use super::*;
use crate::density::Placement;
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
        let model = d.local_model(&Patch::rect(a, b));
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
            if let Some((lo, hi)) = model.map(|m| m.bounds_at(p)) {
                let v = sanitize(v);
                assert!(lo <= v && v <= hi, "model {lo}..{hi} misses {v} at {p:?}");
            }
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
        Placement {
            min: DVec2::new(-3.0, 2.0),
            size: DVec2::new(6.4, 4.8),
            scale: 100.0,
        },
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
    let d = NoiseDensity::new(NoiseParams {
        seed: 7,
        frequency: 0.37,
        octaves: 5,
        base: 0.3,
        amplitude: 0.8,
        scale: 50.0,
    });
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
        Placement {
            min: DVec2::ZERO,
            size: DVec2::splat(10.0),
            scale: 20.0,
        },
    )
    .unwrap();
    let noise = NoiseDensity::new(NoiseParams {
        seed: 3,
        frequency: 0.2,
        octaves: 3,
        base: 0.5,
        amplitude: 0.5,
        scale: 10.0,
    });
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
    // A scaled noise passes its local model on, scaled; a negative scale does not.
    let scaled = Scale(noise.clone(), 0.3);
    assert!(
        scaled
            .local_model(&Patch::rect(DVec2::ONE, DVec2::splat(1.5)))
            .is_some()
    );
    assert!(
        Scale(noise.clone(), -0.3)
            .local_model(&Patch::rect(DVec2::ONE, DVec2::splat(1.5)))
            .is_none()
    );
    check_bound(&scaled, &mut rng, 10.0);
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
    let d = ImageDensity::from_values(
        2,
        1,
        &[f32::NAN, 7.0],
        Placement {
            min: DVec2::ZERO,
            size: DVec2::ONE,
            scale: 1.0,
        },
    )
    .unwrap();
    assert!(d.max_over(DVec2::ZERO, DVec2::ONE) <= 1.0);
    assert_eq!(
        ImageDensity::from_values(
            0,
            1,
            &[],
            Placement {
                min: DVec2::ZERO,
                size: DVec2::ONE,
                scale: 1.0
            }
        )
        .unwrap_err(),
        ImageDensityError::Size(0, 1)
    );
    assert_eq!(
        ImageDensity::from_values(
            1,
            1,
            &[0.5],
            Placement {
                min: DVec2::ZERO,
                size: DVec2::new(f64::NAN, 1.0),
                scale: 1.0
            }
        )
        .unwrap_err(),
        ImageDensityError::Rect
    );
    assert!(
        ImageDensity::from_bytes(
            b"not an image",
            false,
            Placement {
                min: DVec2::ZERO,
                size: DVec2::ONE,
                scale: 1.0
            }
        )
        .is_err()
    );
}

/// CRC-32 (PNG's) of `bytes`.
fn crc32(bytes: &[u8]) -> u32 {
    let mut c = !0u32;
    for &b in bytes {
        c ^= b as u32;
        for _ in 0..8 {
            c = if c & 1 == 1 {
                0xedb8_8320 ^ (c >> 1)
            } else {
                c >> 1
            };
        }
    }
    !c
}

/// A PNG's signature, header chunk and an empty data chunk, announcing `width x height` grey pixels: enough for a
/// reader of headers.
fn png_header(width: u32, height: u32) -> Vec<u8> {
    png_header_of(width, height, 8, 0)
}

/// [`png_header`] of another bit depth and PNG colour type (0 grey, 2 RGB, 6 RGBA).
fn png_header_of(width: u32, height: u32, depth: u8, colour: u8) -> Vec<u8> {
    let mut png = b"\x89PNG\r\n\x1a\n".to_vec();
    let mut ihdr = b"IHDR".to_vec();
    ihdr.extend(width.to_be_bytes());
    ihdr.extend(height.to_be_bytes());
    ihdr.extend([depth, colour, 0, 0, 0]);
    png.extend(13u32.to_be_bytes());
    png.extend(&ihdr);
    png.extend(crc32(&ihdr).to_be_bytes());
    // An empty data chunk: readers stop reading the header there.
    png.extend(0u32.to_be_bytes());
    png.extend(b"IDAT");
    png.extend(crc32(b"IDAT").to_be_bytes());
    png
}

#[test]
fn images_over_the_pixel_limit_are_refused_from_their_header() {
    let huge = png_header(20_000, 20_000);
    let e = decode_image(&huge).unwrap_err();
    assert_eq!(
        e,
        ImageDensityError::TooManyPixels {
            width: 20_000,
            height: 20_000,
            limit: MAX_IMAGE_PIXELS
        }
    );
    assert!(e.to_string().contains("decode_image_with_limit"), "{e}");
    // As a density, what it would take is admitted: the decoded image and the density. A
    // 65 KB 8192 x 8192 PNG took 1 GB (16-bit RGBA, 1.5 GB) within the pixel limit.
    let at = Placement {
        min: DVec2::ZERO,
        size: DVec2::ONE,
        scale: 1.0,
    };
    for (depth, colour, admitted) in [(8, 0, true), (8, 2, true), (8, 6, false), (16, 6, false)] {
        let e = ImageDensity::from_bytes(&png_header_of(8192, 8192, depth, colour), false, at)
            .unwrap_err();
        match e {
            ImageDensityError::TooMuchMemory { bytes, limit, .. } => {
                assert!(
                    !admitted && bytes > limit && limit == MAX_DENSITY_BYTES,
                    "{e}"
                )
            }
            // Admitted: decoding is tried, and these headers have no pixels.
            ImageDensityError::Decode(_) => assert!(admitted, "{depth} {colour}: {e}"),
            e => panic!("{e:?}"),
        }
    }
    // 16-bit RGBA decodes to 8 bytes a pixel: half the pixel limit.
    assert!(matches!(
        decode_image(&png_header_of(8192, 8192, 16, 6)),
        Err(ImageDensityError::TooMuchMemory { .. })
    ));
    // Within a raised limit the header passes and decoding is tried (this one has no
    // pixel data, so it fails there).
    assert!(matches!(
        decode_image_with_limit(&huge, 400_000_000),
        Err(ImageDensityError::Decode(_))
    ));
    let e = open_image(std::path::Path::new("/does/not/exist.png")).unwrap_err();
    assert!(matches!(e, ImageDensityError::Read(_)), "{e:?}");
}

#[test]
fn transparent_pixels_have_no_density() {
    // Four pixels: opaque white, transparent white, half-transparent white, opaque black.
    let mut rgba = ::image::RgbaImage::new(4, 1);
    for (x, px) in [
        [255, 255, 255, 255],
        [255, 255, 255, 0],
        [255, 255, 255, 128],
        [0, 0, 0, 255],
    ]
    .into_iter()
    .enumerate()
    {
        rgba.put_pixel(x as u32, 0, ::image::Rgba(px));
    }
    let img = ::image::DynamicImage::ImageRgba8(rgba);
    let at = |d: &ImageDensity, x: f64| d.value(DVec2::new(x + 0.5, 0.5));
    let strip = Placement {
        min: DVec2::ZERO,
        size: DVec2::new(4.0, 1.0),
        scale: 1.0,
    };
    let light = ImageDensity::from_image(&img, None, false, strip).unwrap();
    assert!((at(&light, 0.0) - 1.0).abs() < 1e-6);
    assert_eq!(at(&light, 1.0), 0.0);
    assert!((at(&light, 2.0) - 128.0 / 255.0).abs() < 1e-6);
    assert_eq!(at(&light, 3.0), 0.0);
    // Dark pixels dense (`dark:`), transparent ones still empty.
    let dark = ImageDensity::from_image(&img, None, true, strip).unwrap();
    assert_eq!(at(&dark, 1.0), 0.0);
    assert!((at(&dark, 3.0) - 1.0).abs() < 1e-6);
    // An explicit channel is that channel: the alpha channel itself here.
    let alpha = ImageDensity::from_image(&img, Some(3), false, strip).unwrap();
    assert_eq!(at(&alpha, 1.0), 0.0);
    assert!((at(&alpha, 0.0) - 1.0).abs() < 1e-6);
}
