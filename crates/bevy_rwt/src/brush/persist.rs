//! Painted maps on disk: one 16-bit grey PNG per target and a RON index of where each lies.

use super::BrushError;
use super::paint::set_texel_luminance;
use crate::layers::texel_luminance;
use bevy::prelude::*;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// The index file [`super::BrushCommand::Save`] writes beside the maps.
pub const INDEX_FILE: &str = "painted.ron";

/// One saved map.
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq)]
pub struct PaintedMapEntry {
    /// The target's name ([`super::BrushTarget::name`]).
    pub name: String,
    /// The PNG file, relative to the index.
    pub file: String,
    /// Ground position of the map's bottom-left corner (x, z).
    pub min: (f32, f32),
    /// Ground size of the map (x, z).
    pub size: (f32, f32),
    /// Instances per square unit where the map is white.
    pub scale: f64,
}

/// The index of a folder of saved maps (`painted.ron`): what a layer file or another game
/// needs to read them (each PNG is the linear map value as 16-bit grey, row 0 at max z).
#[derive(Serialize, Deserialize, Clone, Debug, Default, PartialEq)]
pub struct PaintedMaps {
    /// The maps.
    pub maps: Vec<PaintedMapEntry>,
}

impl PaintedMaps {
    /// Reads `dir/painted.ron`.
    pub fn read(dir: &Path) -> Result<Self, BrushError> {
        let path = dir.join(INDEX_FILE);
        let text = std::fs::read_to_string(&path)
            .map_err(|e| BrushError::Io(format!("{}: {e}", path.display())))?;
        ron::from_str(&text).map_err(|e| BrushError::Io(format!("{}: {e}", path.display())))
    }

    /// Writes `dir/painted.ron`.
    pub fn write(&self, dir: &Path) -> Result<(), BrushError> {
        let path = dir.join(INDEX_FILE);
        let text = ron::ser::to_string_pretty(self, ron::ser::PrettyConfig::default())
            .map_err(|e| BrushError::Io(e.to_string()))?;
        std::fs::write(&path, text).map_err(|e| BrushError::Io(format!("{}: {e}", path.display())))
    }
}

/// A file name for a target's map: its name with anything but letters, digits, `-` and `_`
/// replaced.
pub(super) fn file_name(name: &str) -> String {
    let clean: String = name
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' || c == '_' {
                c
            } else {
                '_'
            }
        })
        .collect();
    format!("{}.png", if clean.is_empty() { "map" } else { &clean })
}

/// Writes a map's values as a 16-bit grey PNG.
pub(super) fn write_map(image: &Image, path: &Path) -> Result<(), BrushError> {
    let (w, h) = (image.width(), image.height());
    let mut pixels = Vec::with_capacity((w * h) as usize);
    for y in 0..h {
        for x in 0..w {
            let v = texel_luminance(image, x, y).ok_or_else(|| {
                BrushError::Io(format!("{}: map texels unreadable", path.display()))
            })?;
            pixels.push((v.clamp(0.0, 1.0) * 65535.0).round() as u16);
        }
    }
    let png = image::ImageBuffer::<image::Luma<u16>, _>::from_raw(w, h, pixels)
        .ok_or_else(|| BrushError::Io("map size".into()))?;
    png.save(path)
        .map_err(|e| BrushError::Io(format!("{}: {e}", path.display())))
}

/// Reads a PNG written by [`write_map`] (or any image, as its luminance) into `image`, which
/// must have the same size; nothing is changed when it does not.
pub(super) fn read_map(image: &mut Image, path: &Path) -> Result<(), BrushError> {
    let io = |e: String| BrushError::Io(format!("{}: {e}", path.display()));
    let png = image::open(path)
        .map_err(|e| io(e.to_string()))?
        .to_luma16();
    if png.dimensions() != (image.width(), image.height()) {
        return Err(io(format!(
            "{}x{} map, the target's is {}x{}",
            png.width(),
            png.height(),
            image.width(),
            image.height()
        )));
    }
    for (x, y, p) in png.enumerate_pixels() {
        if !set_texel_luminance(image, x, y, p[0] as f32 / 65535.0) {
            return Err(io("target map not writable".into()));
        }
    }
    Ok(())
}
