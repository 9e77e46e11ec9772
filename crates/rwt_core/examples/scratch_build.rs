use rwt_core::check::*;
use rwt_core::construction::*;
fn main() {
    let mut cfg = BuildConfig::default();
    if let Some(a) = std::env::args().nth(1) {
        cfg.points = a.parse().unwrap();
    }
    if let Some(a) = std::env::args().nth(2) {
        cfg.subdivision = a.parse().unwrap();
    }
    if let Some(a) = std::env::args().nth(3) {
        cfg.alpha = a.parse().unwrap();
    }
    if let Some(a) = std::env::args().nth(4) {
        cfg.min_spacing = a.parse().unwrap();
    }
    if let Some(a) = std::env::args().nth(5) {
        cfg.lead = a.parse().unwrap();
    }
    if let Some(a) = std::env::args().nth(6) {
        cfg.relax_iterations = a.parse().unwrap();
    }
    let t = std::time::Instant::now();
    let (set, rep) = build(&cfg, &NoProgress).unwrap();
    println!("{rep:?}");
    println!("build {:?}", t.elapsed());
    for k in [16usize, 64, 256, 1024, cfg.points as usize] {
        println!("k={k} rho={:.3}", base_prefix_rho(&set, k, 3, 10));
    }
    for l in 0..3 {
        println!("level {l} violations {}", edge_violations(&set, 1, l, 4));
    }
    println!("dev {}", set.max_subset_deviation());
    std::fs::write("/tmp/set.ron", set.to_ron()).unwrap();
}
