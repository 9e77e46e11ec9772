//! Density specifications on the command line: `const:V`, `image:PATH[:V]`,
//! `dark:PATH[:V]` (dark pixels dense), `noise:V[:FREQUENCY[:OCTAVES[:SEED]]]`.

use glam::DVec2;
use rwt_core::density::{Constant, Density, ImageDensity, NoiseDensity, NoiseParams};

/// A parsed density, boxed so every kind goes through one query path.
pub type BoxedDensity = Box<dyn Density + Send + Sync>;

fn number(s: &str, what: &str) -> Result<f64, String> {
    s.parse::<f64>()
        .ok()
        .filter(|v| v.is_finite())
        .ok_or_else(|| format!("{what} must be a finite number, got {s:?}"))
}

/// Parses a density spec; images are mapped onto `rect` (min, max).
pub fn parse(spec: &str, rect: (DVec2, DVec2)) -> Result<BoxedDensity, String> {
    let (kind, rest) = spec.split_once(':').unwrap_or((spec, ""));
    let parts: Vec<&str> = if rest.is_empty() {
        Vec::new()
    } else {
        rest.split(':').collect()
    };
    match kind {
        "const" => {
            let v = number(parts.first().copied().unwrap_or(""), "const:V")?;
            Ok(Box::new(Constant(v)))
        }
        "image" | "dark" => {
            let path = parts.first().ok_or("image:PATH[:V] needs a path")?;
            let scale = parts
                .get(1)
                .map(|v| number(v, "image scale"))
                .transpose()?
                .unwrap_or(1000.0);
            let bytes = std::fs::read(path).map_err(|e| format!("{path}: {e}"))?;
            let d =
                ImageDensity::from_bytes(&bytes, kind == "dark", rect.0, rect.1 - rect.0, scale)
                    .map_err(|e| format!("{path}: {e}"))?;
            Ok(Box::new(d))
        }
        "noise" => {
            let v = number(parts.first().copied().unwrap_or(""), "noise:V")?;
            let freq = parts
                .get(1)
                .map(|s| number(s, "noise frequency"))
                .transpose()?
                .unwrap_or(0.1);
            let octaves = parts
                .get(2)
                .map(|s| number(s, "noise octaves"))
                .transpose()?
                .unwrap_or(4.0);
            let seed = parts
                .get(3)
                .map(|s| number(s, "noise seed"))
                .transpose()?
                .unwrap_or(0.0);
            Ok(Box::new(NoiseDensity::new(NoiseParams {
                seed: seed as u32,
                frequency: freq,
                octaves: octaves as usize,
                base: 0.5,
                amplitude: 0.5,
                scale: v,
            })))
        }
        _ => Err(format!(
            "unknown density {spec:?}: use const:V, image:PATH[:V], dark:PATH[:V] or noise:V[:FREQ[:OCTAVES[:SEED]]]"
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_and_rejects() {
        let r = (DVec2::ZERO, DVec2::ONE);
        assert_eq!(parse("const:5", r).unwrap().density(DVec2::ZERO), 5.0);
        assert!(parse("noise:100:0.5:3:7", r).is_ok());
        let err = |spec: &str| parse(spec, r).err().unwrap_or_default();
        assert!(err("const:abc").contains("finite number"));
        assert!(parse("const:inf", r).is_err());
        assert!(err("wobble:3").contains("unknown density"));
        assert!(parse("image:/does/not/exist.png", r).is_err());
    }
}
