//! Replays the layer-file inputs kept under `fuzz/regressions/layer_file/` through the check
//! the `layer_file` fuzz target runs (`fuzz/bevy/src/layer_checks.rs`).

#[allow(dead_code, missing_docs)]
#[path = "../../../fuzz/bevy/src/layer_checks.rs"]
mod layer_checks;

#[test]
fn layer_file_inputs() {
    let dir =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fuzz/regressions/layer_file");
    let mut n = 0;
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        let accepted = layer_checks::layer_file(&std::fs::read(&path).unwrap());
        eprintln!("{}: accepted {accepted}", path.display());
        n += 1;
    }
    assert!(n > 0);
}
