//! `rwt zoneplate`: a line per pattern, the claim's line, the figure; sizes it refuses.

#![cfg(unix)]

mod common;

use common::*;

#[test]
fn zoneplate_prints_every_pattern_and_writes_the_figure() {
    let dir = scratch("zoneplate");
    let out = rwt(&dir, &["zoneplate", "--size", "64", "--out", "plate.png"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let text = String::from_utf8(out.stdout).unwrap();
    for pattern in ["rwt", "grid", "jitter", "white", "dart", "sobol"] {
        let line = format!("zoneplate: pattern={pattern} psnr=");
        assert!(text.contains(&line), "{pattern}: {text}");
    }
    assert!(
        text.contains("zoneplate: claim aliasing_removed="),
        "{text}"
    );
    // The reference and six patterns, side by side.
    let png = image::open(dir.join("plate.png")).unwrap();
    assert_eq!((png.width(), png.height()), (7 * 64, 64));
    for size in ["8", "4096"] {
        let out = rwt(&dir, &["zoneplate", "--size", size, "--out", "refused.png"]);
        refused(&out, "--size must be between 16 and 2048");
        assert!(!dir.join("refused.png").exists());
    }
}
