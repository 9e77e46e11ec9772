//! Reads one file the plugin reads, as it reads it, and says what it found or why it
//! refused: what `scripts/hostile_pass.py` runs the plugin's file formats through.
//!
//! ```text
//! cargo run -p bevy_rwt --example read_file -- layer grass.layer.ron
//! cargo run -p bevy_rwt --example read_file -- edits trees.edits SEED
//! cargo run -p bevy_rwt --example read_file -- save saves/level1
//! cargo run -p bevy_rwt --example read_file -- stamp
//! ```
//!
//! Exit status 0 when accepted, 2 when refused (the reason on standard error).

use bevy_rwt::layers::file::{LayerDescription, MAX_LAYER_FILE_BYTES, NamedAssets, Placeholders};
use bevy_rwt::rwt_core::Lattice;
use bevy_rwt::rwt_core::density::decode_image;
use bevy_rwt::rwt_core::edits::{EditSet, EditStamp, EditsError, MAX_EDITS_FILE_BYTES};
use bevy_rwt::rwt_core::files::read_limited;
use bevy_rwt::rwt_core::tileset::TileSet;
use bevy_rwt::save::PaintedMaps;
use std::path::Path;
use std::process::ExitCode;

/// Largest saved map read (what a load of a 4096 x 4096 map reads, and more).
const MAX_MAP_BYTES: u64 = 512 << 20;

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let result = match args.iter().map(String::as_str).collect::<Vec<_>>()[..] {
        ["layer", path] => layer(Path::new(path)),
        ["edits", path, seed] => match seed.parse() {
            Ok(seed) => edits(Path::new(path), seed),
            Err(e) => Err(format!("seed {seed:?}: {e}")),
        },
        ["save", dir] => save(Path::new(dir)),
        // What edits files for the shipped tile set are stamped with, less the seed.
        ["stamp"] => Ok(format!("0 {}", TileSet::embedded().fingerprint())),
        _ => Err("usage: read_file layer PATH | edits PATH SEED | save DIR | stamp".into()),
    };
    match result {
        Ok(summary) => {
            println!("{summary}");
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(2)
        }
    }
}

/// A layer file, read and turned into a layer as the asset loader does.
fn layer(path: &Path) -> Result<String, String> {
    let bytes = read_limited(path, MAX_LAYER_FILE_BYTES).map_err(|e| e.to_string())?;
    let text = std::str::from_utf8(&bytes).map_err(|e| format!("{}: {e}", path.display()))?;
    let description = LayerDescription::from_ron(text).map_err(|e| e.to_string())?;
    let layer = description
        .to_layer(&NamedAssets::default(), &mut Placeholders)
        .map_err(|e| e.to_string())?;
    Ok(format!("layer: {} classes", layer.classes.len()))
}

/// An edits file for the shipped tile set and `seed` (on the seeded lattice, or the
/// aligned one for a file of format 1).
fn edits(path: &Path, seed: u64) -> Result<String, String> {
    let stamp = EditStamp {
        seed,
        lattice: Lattice::Seeded,
        tile_set: TileSet::embedded().fingerprint(),
    };
    let bytes = read_limited(path, MAX_EDITS_FILE_BYTES).map_err(|e| e.to_string())?;
    let set = EditSet::from_bytes(&bytes, &stamp)
        .or_else(|e| match e {
            EditsError::FormatLattice { .. } => EditSet::from_bytes(
                &bytes,
                &EditStamp {
                    lattice: Lattice::Aligned,
                    ..stamp
                },
            ),
            e => Err(e),
        })
        .map_err(|e| format!("{}: {e}", path.display()))?;
    Ok(format!("edits: {}", set.len()))
}

/// A brush save: its index, then every map, layer file and edits file it names.
fn save(dir: &Path) -> Result<String, String> {
    let index = PaintedMaps::read(dir).map_err(|e| e.to_string())?;
    for entry in &index.maps {
        let path = dir.join(&entry.map.path);
        let bytes = read_limited(&path, MAX_MAP_BYTES).map_err(|e| e.to_string())?;
        decode_image(&bytes).map_err(|e| format!("{}: {e}", path.display()))?;
    }
    for file in &index.layers {
        layer(&dir.join(file))?;
    }
    for saved in &index.edits {
        edits(&dir.join(&saved.file), 0)?;
    }
    Ok(format!(
        "save: {} maps, {} layer files, {} edits files",
        index.maps.len(),
        index.layers.len(),
        index.edits.len()
    ))
}
