//! Replays the inputs kept under `fuzz/regressions/` (crashes the fuzzers found, and seeds)
//! through the same checks the fuzz targets run (`fuzz/src/core_checks.rs`).

#[allow(dead_code, missing_docs)]
#[path = "../../../fuzz/src/core_checks.rs"]
mod core_checks;

use std::path::Path;

fn replay(target: &str, check: fn(&[u8]) -> bool) -> usize {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fuzz/regressions")
        .join(target);
    let mut n = 0;
    for entry in std::fs::read_dir(&dir).unwrap_or_else(|e| panic!("{}: {e}", dir.display())) {
        let path = entry.unwrap().path();
        let data = std::fs::read(&path).unwrap();
        let accepted = check(&data);
        eprintln!("{}: accepted {accepted}", path.display());
        n += 1;
    }
    n
}

#[test]
fn tileset_inputs() {
    assert!(replay("tileset", core_checks::tileset) > 0);
}

#[test]
fn image_density_inputs() {
    assert!(replay("image_density", core_checks::image_density) > 0);
}

#[test]
fn query_inputs() {
    assert!(replay("query", core_checks::query) > 0);
}

#[test]
fn stipple_inputs() {
    assert!(replay("stipple", core_checks::stipple) > 0);
}
