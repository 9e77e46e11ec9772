//! scratch
use rwt_core::geometry::*;
use rwt_core::rng::Rng;
use rwt_core::source_tile::DartThrowing;
fn main() {
    for (f, s) in [(10usize, 0.995), (30, 0.995), (30, 0.99), (60, 0.995)] {
        let t = std::time::Instant::now();
        let mut worst = [f64::MAX; 5];
        for seed in 0..4 {
            let pts = DartThrowing {
                points: 2048,
                pool_factor: f,
                shrink: s,
            }
            .run(&mut Rng::new(seed, 0));
            for (i, k) in [16usize, 64, 256, 1024, 2048].iter().enumerate() {
                let p = &pts[..*k];
                let mut best = f64::MAX;
                for a in 0..p.len() {
                    for b in a + 1..p.len() {
                        best = best.min(torus_delta(p[a], p[b]).length());
                    }
                }
                worst[i] = worst[i].min(best / hex_spacing(*k as f64));
            }
        }
        println!("f={f} s={s}: {:.3?} {:?}", worst, t.elapsed() / 4);
    }
}
