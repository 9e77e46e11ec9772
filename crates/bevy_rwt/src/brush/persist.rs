//! Painted maps on disk: one 16-bit grey PNG per target, a layer file per target layer that
//! reads them, and a RON index of where each lies.

use super::paint::set_texel_luminance;
use super::plugin::target_map;
use super::{BrushError, BrushTarget, DensityBrush};
use crate::layers::file::{LayerDescription, NamedAssets};
use crate::layers::{ScatterLayer, texel_luminance};
use bevy::prelude::*;
use serde::{Deserialize, Serialize};
use std::collections::HashMap;
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
/// needs to read them (each PNG is the linear map value as 16-bit grey, row 0 at max z),
/// and the layer files written beside them.
#[derive(Serialize, Deserialize, Clone, Debug, Default, PartialEq)]
pub struct PaintedMaps {
    /// The maps.
    pub maps: Vec<PaintedMapEntry>,
    /// The layer files (`*.layer.ron`, relative to the index) of the targets' layers, which
    /// read the maps (`./name.png`) and load with a [`crate::layers::file::ScatterLayerSource`].
    #[serde(default)]
    pub layers: Vec<String>,
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

/// A file name: `name` with anything but letters, digits, `-` and `_` replaced, then
/// `extension`.
fn file_name(name: &str, extension: &str) -> String {
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
    format!(
        "{}.{extension}",
        if clean.is_empty() { "map" } else { &clean }
    )
}

/// Writes a map's values as a 16-bit grey PNG.
fn write_map(image: &Image, path: &Path) -> Result<(), BrushError> {
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
fn read_map(image: &mut Image, path: &Path) -> Result<(), BrushError> {
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

/// Writes every target's map, the layer file of every target's layer (reading the maps
/// from beside it) and the index to `dir`. A layer that cannot be described (see
/// [`LayerDescription::describe`]) gets no file; the rest is still written, and the error
/// names it.
pub(super) fn save(
    brush: &DensityBrush,
    layers: &Query<&ScatterLayer>,
    layer_name: impl Fn(Entity) -> Option<String>,
    names: &NamedAssets,
    images: &Assets<Image>,
    dir: &Path,
) -> Result<String, BrushError> {
    std::fs::create_dir_all(dir).map_err(|e| BrushError::Io(format!("{}: {e}", dir.display())))?;
    let mut index = PaintedMaps::default();
    let mut saved = HashMap::new();
    for (i, BrushTarget { name, .. }) in brush.targets.iter().enumerate() {
        let map = target_map(brush, i, layers)?;
        let image = images
            .get(&map.image)
            .ok_or_else(|| BrushError::MapUnavailable(name.clone()))?;
        let file = file_name(name, "png");
        write_map(image, &dir.join(&file))?;
        saved.insert(map.image.id(), format!("./{file}"));
        index.maps.push(PaintedMapEntry {
            name: name.clone(),
            file,
            min: map.at.min.into(),
            size: map.at.size.into(),
            scale: map.scale,
        });
    }
    let mut unwritten = Vec::new();
    let mut entities: Vec<Entity> = Vec::new();
    for t in &brush.targets {
        if !entities.contains(&t.layer) {
            entities.push(t.layer);
        }
    }
    for entity in entities {
        let name = layer_name(entity).unwrap_or_else(|| format!("layer {entity}"));
        let mut file = file_name(&name, "layer.ron");
        if index.layers.contains(&file) {
            file = file_name(&format!("{name} {entity}"), "layer.ron");
        }
        let layer = layers
            .get(entity)
            .map_err(|_| BrushError::NoLayer(name.clone()))?;
        let image_path = |h: &Handle<Image>| saved.get(&h.id()).cloned();
        match LayerDescription::describe(layer, names, image_path).and_then(|d| d.to_ron()) {
            Ok(text) => {
                let path = dir.join(&file);
                std::fs::write(&path, text)
                    .map_err(|e| BrushError::Io(format!("{}: {e}", path.display())))?;
                index.layers.push(file);
            }
            Err(e) => unwritten.push(format!("{name}: {e}")),
        }
    }
    index.write(dir)?;
    if !unwritten.is_empty() {
        return Err(BrushError::LayerNotSaved(unwritten.join("; ")));
    }
    Ok(format!(
        "saved {} maps and {} layer files to {}",
        index.maps.len(),
        index.layers.len(),
        dir.display()
    ))
}

/// Reads the maps of `dir`'s index into the targets of the same name.
pub(super) fn load(
    brush: &DensityBrush,
    layers: &Query<&ScatterLayer>,
    images: &mut Assets<Image>,
    dir: &Path,
) -> Result<String, BrushError> {
    let index = PaintedMaps::read(dir)?;
    let mut loaded = 0;
    for entry in &index.maps {
        let Some(i) = brush.targets.iter().position(|t| t.name == entry.name) else {
            continue;
        };
        let map = target_map(brush, i, layers)?;
        let mut image = images
            .get_mut(&map.image)
            .ok_or_else(|| BrushError::MapUnavailable(entry.name.clone()))?;
        read_map(&mut image, &dir.join(&entry.file))?;
        loaded += 1;
    }
    Ok(format!("loaded {loaded} maps from {}", dir.display()))
}
