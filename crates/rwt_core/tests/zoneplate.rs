//! The paper's anti-aliasing claim (figure 9) on the zone plate: rwt's samples remove
//! aliasing as jittering does (past Nyquist, the error's low band at least 1 dB above the
//! regular grid's PSNR and within 10 % of jittering's error), at a lower noise level (where
//! the plate is resolved, the high band above jittering's), every pattern measured in the
//! same run.

use rwt_core::analysis::zoneplate::ZonePlate;
use rwt_core::query::Sampler;
use rwt_core::tileset::TileSet;

#[test]
fn rwt_removes_aliasing_like_jittering_with_less_noise() {
    for seed in [1, 2] {
        let plate = ZonePlate {
            size: 192,
            ..ZonePlate::default()
        };
        let sampler = Sampler::new(&TileSet::embedded(), seed);
        let comparison = plate.compare(&sampler, seed, || true).unwrap();
        for r in &comparison.renderings {
            let e = r.error;
            let name = r.pattern.name();
            println!(
                "seed {seed} {name}: psnr {:.2} low {:.2} high {:.2}",
                e.psnr, e.low, e.high
            );
        }
        let claim = comparison.claim().expect("every pattern rendered");
        assert!(claim.aliasing_removed && claim.less_noise, "{claim:?}");
        // Well above the grid, not only above it.
        assert!(claim.rwt.low > claim.grid.low + 1.0, "{claim:?}");
    }
}

#[test]
fn a_comparison_stops_when_told() {
    let plate = ZonePlate {
        size: 32,
        ..ZonePlate::default()
    };
    let sampler = Sampler::new(&TileSet::embedded(), 3);
    let mut asked = 0;
    let comparison = plate
        .compare(&sampler, 3, || {
            asked += 1;
            asked <= 2
        })
        .unwrap();
    assert_eq!(comparison.renderings.len(), 2);
    assert_eq!(comparison.reference.len(), 32 * 32);
    // rwt and the grid, but not jittering: no claim.
    assert!(comparison.claim().is_none());
}
