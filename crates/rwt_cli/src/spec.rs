//! Density specifications on the command line: `const:V`, `image:PATH[:V]`,
//! `dark:PATH[:V]` (dark pixels dense), `noise:V[:FREQUENCY[:OCTAVES[:SEED]]]`.
//!
//! Fields are separated by `:`. An image path runs to the last `:` that is followed by a
//! number (the scale), so paths that contain `:` need nothing special (`image:in/a:b.png`,
//! `image:C:\maps\a.png:500`); a path that itself ends in `:NUMBER` is written in double
//! quotes (`image:"maps/x:5":500`). Every field must parse completely, and no spec takes more
//! fields than it names.

use glam::DVec2;
use rwt_core::density::Placement;
use rwt_core::density::{
    Constant, Density, ImageDensity, ImageDensityError, NoiseDensity, NoiseParams,
};
use std::path::PathBuf;

/// A parsed density, boxed so every kind goes through one query path.
pub type BoxedDensity = Box<dyn Density + Send + Sync>;

/// The grammar, shown with every error.
const USAGE: &str = "const:V, image:PATH[:V], dark:PATH[:V] or noise:V[:FREQ[:OCTAVES[:SEED]]]";

/// Most octaves a noise density sums.
const MAX_OCTAVES: u64 = 16;

/// What is wrong with a density spec.
#[derive(Debug, thiserror::Error)]
pub enum SpecError {
    /// Not one of the kinds.
    #[error("unknown density {spec:?}: use {USAGE}")]
    Unknown {
        /// The spec.
        spec: String,
    },
    /// A field is not the number it must be.
    #[error("{field} must be {expected}, got {text:?}")]
    Number {
        /// Which field.
        field: &'static str,
        /// What was given.
        text: String,
        /// What it must be.
        expected: &'static str,
    },
    /// More fields than the kind takes.
    #[error(
        "{spec:?} has {found} fields after the kind, {kind} takes at most {most} (use {USAGE})"
    )]
    Extra {
        /// The spec.
        spec: String,
        /// The kind.
        kind: &'static str,
        /// Fields given.
        found: usize,
        /// Fields it takes.
        most: usize,
    },
    /// An image spec without a path, or with an unclosed quote.
    #[error("{0}: image:PATH[:V] needs a path (in double quotes when it ends in :NUMBER)")]
    Path(String),
    /// The image could not be read or decoded.
    #[error("{}: {error}", path.display())]
    Image {
        /// The file.
        path: PathBuf,
        /// Why.
        error: ImageDensityError,
    },
}

/// A finite number of the field `field`.
fn finite(text: &str, field: &'static str, expected: &'static str) -> Result<f64, SpecError> {
    text.parse::<f64>()
        .ok()
        .filter(|v| v.is_finite())
        .ok_or_else(|| SpecError::Number {
            field,
            text: text.to_string(),
            expected,
        })
}

/// A finite number at least 0.
fn non_negative(text: &str, field: &'static str) -> Result<f64, SpecError> {
    let expected = "a finite number >= 0";
    let v = finite(text, field, expected)?;
    if v >= 0.0 {
        Ok(v)
    } else {
        Err(SpecError::Number {
            field,
            text: text.to_string(),
            expected,
        })
    }
}

/// A whole number in `range`.
fn whole(
    text: &str,
    field: &'static str,
    range: std::ops::RangeInclusive<u64>,
    expected: &'static str,
) -> Result<u64, SpecError> {
    text.parse::<u64>()
        .ok()
        .filter(|v| range.contains(v))
        .ok_or_else(|| SpecError::Number {
            field,
            text: text.to_string(),
            expected,
        })
}

/// Parses a density spec; images are mapped onto `rect` (min, max).
pub fn parse(spec: &str, rect: (DVec2, DVec2)) -> Result<BoxedDensity, SpecError> {
    let (kind, rest) = spec.split_once(':').unwrap_or((spec, ""));
    match kind {
        "const" => {
            let fields = fields(spec, "const", rest, 1)?;
            let v = non_negative(fields.first().copied().unwrap_or(""), "const:V")?;
            Ok(Box::new(Constant(v)))
        }
        "image" | "dark" => {
            let (path, scale) = image_fields(spec, rest)?;
            let scale = match scale {
                Some(v) => non_negative(v, "image scale")?,
                None => 1000.0,
            };
            let image_err = |error| SpecError::Image {
                path: path.clone(),
                error,
            };
            let d = ImageDensity::open(
                &path,
                kind == "dark",
                Placement {
                    min: rect.0,
                    size: rect.1 - rect.0,
                    scale,
                },
            )
            .map_err(image_err)?;
            Ok(Box::new(d))
        }
        "noise" => {
            let f = fields(spec, "noise", rest, 4)?;
            let v = non_negative(f.first().copied().unwrap_or(""), "noise:V")?;
            let freq = match f.get(1) {
                Some(s) => Some(finite(s, "noise frequency", "a finite number > 0")?)
                    .filter(|&v| v > 0.0)
                    .ok_or_else(|| SpecError::Number {
                        field: "noise frequency",
                        text: s.to_string(),
                        expected: "a finite number > 0",
                    })?,
                None => 0.1,
            };
            let octaves = match f.get(2) {
                Some(s) => whole(
                    s,
                    "noise octaves",
                    1..=MAX_OCTAVES,
                    "a whole number in 1..=16",
                )?,
                None => 4,
            };
            let seed = match f.get(3) {
                Some(s) => whole(
                    s,
                    "noise seed",
                    0..=u32::MAX as u64,
                    "a whole number in 0..=4294967295",
                )?,
                None => 0,
            };
            Ok(Box::new(NoiseDensity::new(NoiseParams {
                seed: seed as u32,
                frequency: freq,
                octaves: octaves as usize,
                base: 0.5,
                amplitude: 0.5,
                scale: v,
            })))
        }
        _ => Err(SpecError::Unknown {
            spec: spec.to_string(),
        }),
    }
}

/// The `:`-separated fields of `rest`, at most `most` of them.
fn fields<'a>(
    spec: &str,
    kind: &'static str,
    rest: &'a str,
    most: usize,
) -> Result<Vec<&'a str>, SpecError> {
    let fields: Vec<&str> = if rest.is_empty() {
        Vec::new()
    } else {
        rest.split(':').collect()
    };
    if fields.len() > most {
        return Err(SpecError::Extra {
            spec: spec.to_string(),
            kind,
            found: fields.len(),
            most,
        });
    }
    Ok(fields)
}

/// An image spec's path and scale field: a quoted path runs to its closing quote; an
/// unquoted one to the last `:` followed by a number, or to the end.
fn image_fields<'a>(spec: &str, rest: &'a str) -> Result<(PathBuf, Option<&'a str>), SpecError> {
    let missing = || SpecError::Path(spec.to_string());
    if let Some(quoted) = rest.strip_prefix('"') {
        let (path, after) = quoted.split_once('"').ok_or_else(missing)?;
        let scale = match after {
            "" => None,
            _ => Some(after.strip_prefix(':').ok_or_else(missing)?),
        };
        if path.is_empty() {
            return Err(missing());
        }
        return Ok((PathBuf::from(path), scale));
    }
    let (path, scale) = match rest.rsplit_once(':') {
        Some((path, last)) if last.parse::<f64>().is_ok() => (path, Some(last)),
        _ => (rest, None),
    };
    if path.is_empty() {
        return Err(missing());
    }
    Ok((PathBuf::from(path), scale))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn err(spec: &str) -> String {
        parse(spec, (DVec2::ZERO, DVec2::ONE))
            .err()
            .map(|e| e.to_string())
            .unwrap_or_default()
    }

    #[test]
    fn parses_and_rejects() {
        let r = (DVec2::ZERO, DVec2::ONE);
        assert_eq!(parse("const:5", r).unwrap().density(DVec2::ZERO), 5.0);
        assert!(parse("noise:100:0.5:3:7", r).is_ok());
        assert!(err("const:abc").contains("finite number"));
        assert!(parse("const:inf", r).is_err());
        assert!(err("wobble:3").contains("unknown density"));
        assert!(parse("image:/does/not/exist.png", r).is_err());
        // Extra fields and coerced numbers are refused, with the field named.
        assert!(
            err("const:5:garbage").contains("const takes at most 1"),
            "{}",
            err("const:5:garbage")
        );
        assert!(err("const:-1").contains(">= 0"));
        assert!(err("noise:5:0.1:4:7:9").contains("noise takes at most 4"));
        assert!(err("noise:5:0.1:4.7").contains("noise octaves must be a whole number"));
        assert!(err("noise:5:0.1:0").contains("noise octaves"));
        assert!(err("noise:5:0.1:4:-1").contains("noise seed must be a whole number"));
        assert!(err("noise:5:0.1:4:1e20").contains("noise seed"));
        assert!(err("noise:5:0.1:4:4294967296").contains("noise seed"));
        assert!(err("noise:5:0:4").contains("noise frequency must be a finite number > 0"));
        assert!(err("noise:5:0.1:4:12abc").contains("noise seed"));
    }

    #[test]
    fn image_paths_may_contain_colons() {
        let cases = [
            ("in/a:b.png", ("in/a:b.png", None)),
            ("C:\\maps\\a.png", ("C:\\maps\\a.png", None)),
            ("C:\\maps\\a.png:500", ("C:\\maps\\a.png", Some("500"))),
            ("maps/a.png:2.5", ("maps/a.png", Some("2.5"))),
            ("\"maps/x:5\":500", ("maps/x:5", Some("500"))),
            ("\"maps/x:5\"", ("maps/x:5", None)),
        ];
        for (rest, (path, scale)) in cases {
            let (p, s) = image_fields("image:...", rest).unwrap();
            assert_eq!((p, s), (PathBuf::from(path), scale), "{rest}");
        }
        for bad in ["", "\"unclosed", "\"\":5", "\"a\"junk"] {
            assert!(image_fields("image:...", bad).is_err(), "{bad}");
        }
        // The file named in the message is the whole path.
        let e = err("image:/no/such/dir:with:colons.png");
        assert!(e.starts_with("/no/such/dir:with:colons.png:"), "{e}");
        assert!(
            err("image:/no/such/a.png:abc:").contains("a.png:abc:"),
            "{}",
            err("image:/no/such/a.png:abc:")
        );
    }
}
