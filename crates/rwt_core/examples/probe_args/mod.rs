//! What the quality probes (`density_sweep`, `tile_coherence`) read from their command line.

use rwt_core::tileset::TileSet;

/// The tile set named by the first argument (a RON file), or the embedded one.
pub fn tile_set() -> TileSet {
    match std::env::args().nth(1) {
        Some(path) => TileSet::from_ron_bytes(&std::fs::read(&path).expect("readable file"))
            .expect("a valid tile set"),
        None => TileSet::embedded(),
    }
}

/// The multiples of N in `MULT` (`0.3,4,6`, or `quarter`: every quarter octave from 0.3 N to
/// 64 N), else `default`.
pub fn multiples(default: &[f64]) -> Vec<f64> {
    std::env::var("MULT")
        .map(|s| match s.as_str() {
            "quarter" => (0..=31).map(|k| 0.3 * 2f64.powf(k as f64 / 4.0)).collect(),
            _ => s.split(',').filter_map(|v| v.parse().ok()).collect(),
        })
        .unwrap_or_else(|_| default.to_vec())
}
