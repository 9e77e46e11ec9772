//! How alike the tiles of a set are: the power of every tile's first ranks at integer
//! frequencies (cycles per tile), summed over the tiles coherently (as a query repeating
//! them sees it) and incoherently (as if no two tiles shared a point), by where the points
//! came from (the tile's own interior source, or an edge source shared by every tile with
//! that edge colour).
//!
//! A ratio near 1 means tiles that share nothing; a ratio above 1 is structure every tile
//! repeats, which a query shows as peaks at the tile's period (anisotropy once the seed turns
//! the lattice). Frequencies from 12 to 24 cycles per tile on either axis are averaged.
//!
//! `cargo run --release -p rwt_core --example tile_coherence [TILESET.ron]`
//! (`MULT=0.1,0.3,1` picks how many ranks, in multiples of N).
use glam::DVec2;

mod probe_args;

/// Largest frequency per axis, cycles per tile.
const K_MAX: i32 = 24;
/// Smallest frequency on either axis that is averaged.
const K_MIN: i32 = 12;

/// Which points of each tile are counted.
#[derive(Clone, Copy, Debug)]
enum Part {
    All,
    Interior,
    Edges,
}

fn main() {
    let set = probe_args::tile_set();
    let n = set.points_per_tile as f64;
    let multiples = probe_args::multiples(&[0.1, 0.3, 0.6, 1.0]);
    println!("ranks      part       share of points   coherent / incoherent power = ratio");
    for m in multiples {
        let take = ((m * n) as usize).clamp(1, set.points_per_tile as usize);
        for part in [Part::All, Part::Interior, Part::Edges] {
            let tiles: Vec<Vec<DVec2>> = set
                .tiles
                .iter()
                .map(|t| {
                    t.points[..take]
                        .iter()
                        .zip(&t.origins)
                        .filter(|(_, o)| match part {
                            Part::All => true,
                            Part::Interior => **o == 0,
                            Part::Edges => **o != 0,
                        })
                        .map(|(p, _)| DVec2::new(p[0] as f64, p[1] as f64) / 4_294_967_296.0)
                        .collect()
                })
                .collect();
            let count: usize = tiles.iter().map(Vec::len).sum();
            let (coherent, incoherent) = powers(&tiles);
            println!(
                "{m:>5} N   {:<9}  {:>5.2}             {coherent:.3} / {incoherent:.3} = {:.2}",
                format!("{part:?}"),
                count as f64 / (take * set.tiles.len()) as f64,
                coherent / incoherent
            );
        }
    }
}

/// Mean over the averaged frequencies of `|sum over tiles of F_t(k)|^2 / n` (coherent) and of
/// `sum over tiles of |F_t(k)|^2 / n` (incoherent), `F_t` the tile's Fourier sum.
fn powers(tiles: &[Vec<DVec2>]) -> (f64, f64) {
    let n: usize = tiles.iter().map(Vec::len).sum();
    let (mut coherent, mut incoherent, mut cells) = (0.0, 0.0, 0usize);
    for v in -K_MAX..=K_MAX {
        for u in -K_MAX..=K_MAX {
            if u.abs().max(v.abs()) < K_MIN {
                continue;
            }
            let k = DVec2::new(u as f64, v as f64);
            let (mut re, mut im) = (0.0, 0.0);
            for tile in tiles {
                let (mut tr, mut ti) = (0.0, 0.0);
                for q in tile {
                    let (s, c) = (-std::f64::consts::TAU * k.dot(*q)).sin_cos();
                    tr += c;
                    ti += s;
                }
                incoherent += tr * tr + ti * ti;
                re += tr;
                im += ti;
            }
            coherent += re * re + im * im;
            cells += 1;
        }
    }
    let norm = (n.max(1) * cells) as f64;
    (coherent / norm, incoherent / norm)
}
