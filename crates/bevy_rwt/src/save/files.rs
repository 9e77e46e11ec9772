//! A save on disk: one 16-bit grey PNG per named map, a layer file per map's layer that
//! reads them, the per-instance edits of every named layer, and a RON index of where each
//! lies; written as one transaction, read back only when all of it is good.

use super::{
    LoadSummary, LoadWorld, MapProblem, NamedMap, SaveError, SaveSummary, SaveWorld, UnsavedLayer,
};
use crate::edits::{EditSet, EditStamp};
use crate::layers::file::{LayerDescription, MapDescription, NamedAssets};
use crate::layers::{ScatterLayer, set_texel_luminance, texel_luminance};
use bevy::prelude::*;
use rwt_core::edits::MAX_EDITS_FILE_BYTES;
use rwt_core::files::{SaveTransaction, is_plain_name, read_limited, recover};
use serde::{Deserialize, Serialize};
use std::collections::{HashMap, HashSet};
use std::io::Write;
use std::path::Path;

/// The index file a save writes beside its files.
pub const INDEX_FILE: &str = "painted.ron";

/// The save format this library writes: 2 names each layer's lattice in its layer file and
/// edits files (format 1, with no `format` in its index, kept every layer on the aligned
/// lattice; its files say so, and load as such).
pub const SAVE_FORMAT: u32 = 2;

/// Largest index or layer file a load reads.
const MAX_TEXT_BYTES: u64 = 1 << 20;

/// One saved map.
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq)]
pub struct PaintedMapEntry {
    /// The map's name ([`NamedMap::name`]).
    pub name: String,
    /// The map as a layer file writes it, its path the PNG file relative to the index.
    pub map: MapDescription,
}

/// The index of a folder of saved maps (`painted.ron`): what a layer file or another game
/// needs to read them (each PNG is the linear map value as 16-bit grey, row 0 at max z),
/// and the layer files written beside them.
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq)]
pub struct PaintedMaps {
    /// The save's format ([`SAVE_FORMAT`]; an index without it is of format 1).
    #[serde(default = "crate::layers::file::format_1")]
    pub format: u32,
    /// The maps.
    pub maps: Vec<PaintedMapEntry>,
    /// The layer files (`*.layer.ron`, relative to the index) of the maps' layers, which
    /// read the maps (`./name.png`) and load with a [`crate::layers::file::ScatterLayerSource`].
    #[serde(default)]
    pub layers: Vec<String>,
    /// The per-instance edits of every named layer (one file each, see
    /// [`rwt_core::edits`]); a load gives each layer of that name its edits.
    #[serde(default)]
    pub edits: Vec<SavedEdits>,
}

/// A layer's edits in a save.
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq)]
pub struct SavedEdits {
    /// The layer's `Name`.
    pub layer: String,
    /// The edits file, relative to the index.
    pub file: String,
}

impl Default for PaintedMaps {
    /// An empty index of this library's format.
    fn default() -> Self {
        Self {
            format: SAVE_FORMAT,
            maps: Vec::new(),
            layers: Vec::new(),
            edits: Vec::new(),
        }
    }
}

impl PaintedMaps {
    /// Reads `dir/painted.ron` (finishing first a save that a crash interrupted there); a
    /// save of a newer format is [`SaveError::Format`].
    pub fn read(dir: &Path) -> Result<Self, SaveError> {
        recover(dir)?;
        let path = dir.join(INDEX_FILE);
        let text = read_text(&path)?;
        let index: Self = ron::from_str(&text).map_err(|e| SaveError::Parse {
            file: path.clone(),
            error: Box::new(e.into()),
        })?;
        if !(1..=SAVE_FORMAT).contains(&index.format) {
            return Err(SaveError::Format {
                file: path,
                found: index.format,
                supported: SAVE_FORMAT,
            });
        }
        let edits = index.edits.iter().map(|e| &e.file);
        let names = index
            .maps
            .iter()
            .map(|m| &m.map.path)
            .chain(&index.layers)
            .chain(edits);
        if let Some(bad) = names.into_iter().find(|f| !is_plain_name(f)) {
            return Err(SaveError::OutsideFolder { file: bad.clone() });
        }
        Ok(index)
    }

    /// The index as RON.
    fn to_ron(&self) -> String {
        ron::ser::to_string_pretty(self, ron::ser::PrettyConfig::default())
            .expect("plain data serializes")
    }
}

/// A text file of at most [`MAX_TEXT_BYTES`].
fn read_text(path: &Path) -> Result<String, SaveError> {
    let bytes = read_limited(path, MAX_TEXT_BYTES)?;
    String::from_utf8(bytes).map_err(|e| SaveError::Parse {
        file: path.to_path_buf(),
        error: Box::new(e.utf8_error().into()),
    })
}

/// File names given out in one save: `name` with anything but letters, digits, `-` and
/// `_` replaced, made unique (also on file systems that ignore case) with `-2`, `-3`...
#[derive(Default)]
struct FileNames(HashSet<String>);

impl FileNames {
    fn claim(&mut self, name: &str, extension: &str) -> String {
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
        let stem = if clean.is_empty() { "map" } else { &clean };
        let mut file = format!("{stem}.{extension}");
        let mut n = 1;
        while !self.0.insert(file.to_lowercase()) {
            n += 1;
            file = format!("{stem}-{n}.{extension}");
        }
        file
    }
}

/// Writes a map's values as a 16-bit grey PNG.
fn write_map(image: &Image, map: &str, w: &mut dyn Write) -> Result<(), SaveError> {
    let (width, height) = (image.width(), image.height());
    let mut pixels = Vec::with_capacity((width * height) as usize);
    for y in 0..height {
        for x in 0..width {
            let v =
                texel_luminance(image, x, y).ok_or_else(|| MapProblem::of(Some(image)).at(map))?;
            pixels.push((v.clamp(0.0, 1.0) * 65535.0).round() as u16);
        }
    }
    let png = image::ImageBuffer::<image::Luma<u16>, _>::from_raw(width, height, pixels)
        .ok_or_else(|| MapProblem::of(Some(image)).at(map))?;
    png.write_with_encoder(image::codecs::png::PngEncoder::new(w))
        .map_err(|error| SaveError::Encode {
            map: map.to_string(),
            error,
        })
}

/// Reads a PNG written by [`write_map`] (or any image, as its luminance) of exactly
/// `width x height` pixels (checked from its header, before decoding).
fn read_map(path: &Path, width: u32, height: u32) -> Result<Vec<f32>, SaveError> {
    let pixels = width as u64 * height as u64;
    let bytes = read_limited(path, pixels * 16 + (1 << 20))?;
    let png = rwt_core::density::decode_image_with_limit(&bytes, pixels)
        .map_err(|error| SaveError::Decode {
            file: path.to_path_buf(),
            error,
        })?
        .to_luma16();
    if png.dimensions() != (width, height) {
        return Err(SaveError::MapSize {
            file: path.to_path_buf(),
            found: png.dimensions(),
            expected: (width, height),
        });
    }
    Ok(png.pixels().map(|p| p[0] as f32 / 65535.0).collect())
}

/// What a save reads: the layers, their names, the names of assets, the maps, the edits.
pub(super) struct SaveSources<'a, 'w, 's, 'q> {
    pub layers: &'a Query<'w, 's, &'q ScatterLayer>,
    pub layer_name: &'a dyn Fn(Entity) -> Option<String>,
    pub names: &'a NamedAssets,
    pub images: &'a Assets<Image>,
    /// Every named layer's edits.
    pub edits: &'a [LayerEdits<'a>],
}

/// A named layer's edits, and what their identities refer to.
pub(super) struct LayerEdits<'a> {
    pub name: String,
    pub entity: Entity,
    pub edits: &'a EditSet,
    pub stamp: EditStamp,
}

/// The first name that two of `names` share.
fn repeated<'n>(mut names: impl Iterator<Item = &'n String>) -> Option<String> {
    let mut seen = HashSet::new();
    names.find(|n| !seen.insert(*n)).cloned()
}

/// Writes every named map, the layer file of every map's layer (reading the maps from
/// beside it), every named layer's edits and the index to the request's folder, all or
/// nothing. A layer that cannot be described (see [`LayerDescription::describe`]) gets no
/// file; the rest is still saved, and the error names it.
pub(super) fn save(request: &SaveWorld, from: &SaveSources) -> Result<SaveSummary, SaveError> {
    if let Some(name) = repeated(request.maps.iter().map(|m| &m.name)) {
        return Err(SaveError::DuplicateMap { name });
    }
    if let Some(name) = repeated(from.edits.iter().map(|l| &l.name)) {
        return Err(SaveError::DuplicateLayer { name });
    }
    let mut save = SaveTransaction::begin(&request.dir)?;
    let mut names = FileNames::default();
    names.claim("painted", "ron");
    let mut index = PaintedMaps::default();
    let mut saved = HashMap::new();
    for named in &request.maps {
        let map = named.ground_map(from.layers)?;
        let name = &named.name;
        let image = from
            .images
            .get(&map.image)
            .ok_or_else(|| MapProblem::NotLoaded.at(name))?;
        let file = names.claim(name, "png");
        let mut failed = None;
        save.write_with(&file, |w| {
            write_map(image, name, w).map_err(|e| {
                failed = Some(e);
                std::io::Error::other("map not written")
            })
        })
        .map_err(|e| failed.take().unwrap_or(e.into()))?;
        saved.insert(map.image.id(), format!("./{file}"));
        index.maps.push(PaintedMapEntry {
            name: name.clone(),
            map: MapDescription::of(&map, file),
        });
    }
    let unwritten = if request.layer_files {
        stage_layer_files(
            &request.maps,
            from,
            &saved,
            &mut names,
            &mut save,
            &mut index,
        )?
    } else {
        Vec::new()
    };
    let mut edits = 0;
    for layer in from.edits {
        let file = names.claim(&layer.name, "edits");
        save.write(&file, &layer.edits.to_bytes(&layer.stamp))?;
        edits += layer.edits.len();
        index.edits.push(SavedEdits {
            layer: layer.name.clone(),
            file,
        });
    }
    save.write(INDEX_FILE, index.to_ron().as_bytes())?;
    save.commit()?;
    if !unwritten.is_empty() {
        return Err(SaveError::LayerNotSaved { layers: unwritten });
    }
    Ok(SaveSummary {
        maps: index.maps.len(),
        layer_files: index.layers.len(),
        edits,
    })
}

/// Stages a layer file per map's layer; returns the layers that cannot be described.
fn stage_layer_files(
    maps: &[NamedMap],
    from: &SaveSources,
    saved: &HashMap<AssetId<Image>, String>,
    names: &mut FileNames,
    save: &mut SaveTransaction,
    index: &mut PaintedMaps,
) -> Result<Vec<UnsavedLayer>, SaveError> {
    let mut unwritten = Vec::new();
    let mut entities: Vec<Entity> = Vec::new();
    for m in maps {
        if !entities.contains(&m.layer) {
            entities.push(m.layer);
        }
    }
    for entity in entities {
        let name = (from.layer_name)(entity).unwrap_or_else(|| format!("layer {entity}"));
        let layer = from
            .layers
            .get(entity)
            .map_err(|_| MapProblem::NoLayer.at(&name))?;
        let image_path = |h: &Handle<Image>| saved.get(&h.id()).cloned();
        match LayerDescription::describe(layer, from.names, image_path).and_then(|d| d.to_ron()) {
            Ok(text) => {
                let file = names.claim(&name, "layer.ron");
                save.write(&file, text.as_bytes())?;
                index.layers.push(file);
            }
            Err(error) => unwritten.push(UnsavedLayer { name, error }),
        }
    }
    Ok(unwritten)
}

/// A loaded save: what it holds, and the edits each named layer gets.
pub(super) struct Loaded {
    pub summary: LoadSummary,
    pub edits: Vec<(Entity, EditSet)>,
}

/// Reads the maps of the folder's index into the request's maps of the same name, once
/// every map, layer file and edits file of the save has been read and checked; on any error
/// nothing changes. The edits of the layers named in `named` are returned, for the caller to
/// put in place.
pub(super) fn load(
    request: &LoadWorld,
    layers: &Query<&ScatterLayer>,
    images: &mut Assets<Image>,
    named: &[LayerEdits],
) -> Result<Loaded, SaveError> {
    let dir = &request.dir;
    let index = PaintedMaps::read(dir)?;
    let edits = read_edits(&index, dir, named)?;
    let mut read = Vec::new();
    for entry in &index.maps {
        let Some(named) = request.maps.iter().find(|m| m.name == entry.name) else {
            continue;
        };
        let map = named.ground_map(layers)?;
        let image = images.get(&map.image);
        let image = image
            .filter(|image| texel_luminance(image, 0, 0).is_some())
            .ok_or_else(|| MapProblem::of(image).at(&entry.name))?;
        let values = read_map(&dir.join(&entry.map.path), image.width(), image.height())?;
        read.push((map.image, entry.name.clone(), values));
    }
    for file in &index.layers {
        let path = dir.join(file);
        LayerDescription::from_ron(&read_text(&path)?).map_err(|e| SaveError::Parse {
            file: path,
            error: Box::new(e.into()),
        })?;
    }
    for (handle, name, values) in &read {
        let mut image = images
            .get_mut(handle)
            .ok_or_else(|| MapProblem::NotLoaded.at(name))?;
        let width = image.width();
        for (texel, &v) in values.iter().enumerate() {
            let (x, y) = (texel as u32 % width, texel as u32 / width);
            if !set_texel_luminance(&mut image, x, y, v) {
                return Err(MapProblem::of(Some(&image)).at(name).into());
            }
        }
    }
    let summary = LoadSummary {
        maps: read.len(),
        edits: edits.iter().map(|(_, e)| e.len()).sum(),
    };
    Ok(Loaded { summary, edits })
}

/// Reads and checks the edits file of every layer in `named` that the index lists.
fn read_edits(
    index: &PaintedMaps,
    dir: &Path,
    named: &[LayerEdits],
) -> Result<Vec<(Entity, EditSet)>, SaveError> {
    let mut out = Vec::new();
    for saved in &index.edits {
        let Some(layer) = named.iter().find(|l| l.name == saved.layer) else {
            continue;
        };
        let path = dir.join(&saved.file);
        let bytes = read_limited(&path, MAX_EDITS_FILE_BYTES)?;
        let set = EditSet::from_bytes(&bytes, &layer.stamp)
            .map_err(|error| SaveError::Edits { file: path, error })?;
        out.push((layer.entity, set));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn colliding_names_get_their_own_files() {
        let mut names = FileNames::default();
        names.claim("painted", "ron");
        let files: Vec<String> = ["red flowers", "red_flowers", "Red_Flowers", "", "painted"]
            .iter()
            .map(|n| names.claim(n, "png"))
            .collect();
        assert_eq!(
            files,
            [
                "red_flowers.png",
                "red_flowers-2.png",
                "Red_Flowers-3.png",
                "map.png",
                "painted.png"
            ]
        );
        assert_eq!(names.claim("painted", "ron"), "painted-2.ron");
    }

    #[test]
    fn index_entries_stay_in_their_folder() {
        for ok in ["a.png", "red_flowers-2.png", ".hidden.png"] {
            assert!(is_plain_name(ok), "{ok}");
        }
        for bad in ["../a.png", "/etc/passwd", "maps/a.png", "..", ".", ""] {
            assert!(!is_plain_name(bad), "{bad}");
        }
    }
}
