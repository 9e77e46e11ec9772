//! `rwt stipple`: blue-noise stippling of an image whose blurred dots keep the image's tone
//! (paper figure 11), with the tone error printed next to a white-noise stipple's.

use crate::draw::{Format, format_of};
use rwt_core::density::open_image;
use rwt_core::stipple::{
    DotCount, Grey, Stipple, StippleLimits, StippleSettings, ToneMap, stipple,
};
use rwt_core::tileset::TileSet;
use std::io::Write;
use std::path::Path;
use std::time::Instant;

/// What `rwt stipple` was asked for.
pub struct StippleArgs<'a> {
    /// Input image.
    pub image: &'a Path,
    /// Output `.png` or `.svg`.
    pub out: &'a Path,
    /// Dot count, or `None` to choose it (or the radius).
    pub points: Option<usize>,
    /// Dot radius in image pixels, or `None` to choose it.
    pub radius: Option<f64>,
    /// Grey to darkness.
    pub tone: ToneMap,
    /// Tiling seed.
    pub seed: u64,
    /// Output pixels per image pixel.
    pub scale: f64,
    /// Most dots and raster pixels.
    pub limits: StippleLimits,
}

/// Runs `rwt stipple`.
pub fn run(args: &StippleArgs) -> Result<(), String> {
    let dots = match (args.points, args.radius) {
        (Some(n), None) => DotCount::Points(n),
        (None, Some(r)) => DotCount::Radius(r),
        (None, None) => DotCount::Auto,
        (Some(_), Some(_)) => return Err("give --points or --radius, not both".into()),
    };
    let settings = StippleSettings {
        dots,
        tone: args.tone,
        seed: args.seed,
        scale: args.scale,
        limits: args.limits,
    };
    let format = format_of(args.out, &[Format::Png, Format::Svg])?;
    let named = |e: &dyn std::fmt::Display| format!("{}: {e}", args.image.display());
    // Settings, raster and dot count are admitted from the header, before decoding; the
    // image itself is at most StippleLimits::max_image_pixels.
    let file = rwt_core::files::open_regular(args.image).map_err(|e| e.to_string())?;
    let (w, h) = image::ImageReader::new(std::io::BufReader::new(file))
        .with_guessed_format()
        .map_err(|e| named(&e))?
        .into_dimensions()
        .map_err(|e| named(&e))?;
    settings
        .admit(w as usize, h as usize)
        .map_err(|e| e.to_string())?;
    let img = open_image(args.image).map_err(|e| named(&e))?;
    let grey = Grey::from_image(&img);
    drop(img);
    let started = Instant::now();
    let s = stipple(&grey, &TileSet::embedded(), &settings).map_err(|e| e.to_string())?;
    say!(
        "{} dots of radius {:.3} px in {:.1} ms",
        s.dots.len(),
        s.radius,
        started.elapsed().as_secs_f64() * 1e3
    );
    // Rendered once: the tone figures and the PNG are of the same raster.
    let ink = s.render(&s.dots, args.scale).map_err(|e| e.to_string())?;
    report_tone(&s, &grey, &ink, args.seed)?;
    write(&s, &ink, args.out, format, args.scale)?;
    say!("wrote {}", args.out.display());
    Ok(())
}

/// Prints the mean grey and the tone error of the stipple and of a white-noise stipple.
fn report_tone(s: &Stipple, grey: &Grey, rendered: &Grey, seed: u64) -> Result<(), String> {
    let target = 1.0 - s.target.mean();
    let mapped = if (target - grey.mean()).abs() > 5e-4 {
        format!(", after --gamma/--contrast {target:.3}")
    } else {
        String::new()
    };
    say!(
        "mean grey: image {:.3}{mapped}, stipple {:.3}",
        grey.mean(),
        1.0 - rendered.mean()
    );
    let r = s.tone_report(rendered, seed).map_err(|e| e.to_string())?;
    say!(
        "tone error (blur {:.2} px, the mean dot spacing): blue noise {:.4} (PSNR {:.2} dB), white noise {:.4} (PSNR {:.2} dB), {:+.2} dB",
        r.sigma,
        r.blue.mean_abs,
        r.blue.psnr,
        r.white.mean_abs,
        r.white.psnr,
        r.blue.psnr - r.white.psnr
    );
    Ok(())
}

/// Writes the stipple as antialiased PNG (`ink`, its rendering) or as SVG circles,
/// atomically: on any error an existing file keeps its bytes.
fn write(s: &Stipple, ink: &Grey, out: &Path, format: Format, scale: f64) -> Result<(), String> {
    if format == Format::Svg {
        rwt_core::files::write_atomic_with(out, |w| write_svg(s, scale, w))
            .map_err(|e| e.to_string())
    } else {
        let pixels: Vec<u8> = ink
            .values
            .iter()
            .map(|&v| ((1.0 - v) * 255.0).round() as u8)
            .collect();
        crate::draw::save_png(
            out,
            &pixels,
            ink.width as u32,
            ink.height as u32,
            image::ExtendedColorType::L8,
        )
    }
}

/// The dots as SVG circles, streamed.
fn write_svg(s: &Stipple, scale: f64, w: &mut dyn Write) -> std::io::Result<()> {
    let (width, height) = (s.target.width, s.target.height);
    writeln!(
        w,
        "<svg xmlns=\"http://www.w3.org/2000/svg\" viewBox=\"0 0 {width} {height}\" width=\"{}\" height=\"{}\">",
        width as f64 * scale,
        height as f64 * scale
    )?;
    writeln!(w, "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>")?;
    for p in &s.dots {
        writeln!(
            w,
            "<circle cx=\"{:.3}\" cy=\"{:.3}\" r=\"{:.3}\"/>",
            p.x, p.y, s.radius
        )?;
    }
    writeln!(w, "</svg>")
}
