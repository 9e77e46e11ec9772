use glam::DVec2;
use rwt_core::analysis::*;
use rwt_core::geometry::hex_spacing;
use rwt_core::tileset::*;
fn main() {
    let set = TileSet::from_ron_bytes(&std::fs::read("/tmp/set.ron").unwrap()).unwrap();
    let n = set.points_per_tile as f64;
    let mut worst = vec![];
    for (t, tile) in set.tiles.iter().enumerate() {
        let pts: Vec<DVec2> = tile
            .points
            .iter()
            .map(|p| DVec2::new(fixed_to_unit(p[0]), fixed_to_unit(p[1])))
            .collect();
        let nn = nearest_neighbour_distances(&pts);
        let (i, d) = nn
            .iter()
            .enumerate()
            .min_by(|a, b| a.1.total_cmp(b.1))
            .unwrap();
        worst.push((d / hex_spacing(n), t, i, pts[i], tile.origins[i]));
    }
    worst.sort_by(|a, b| a.0.total_cmp(&b.0));
    for w in &worst[..5] {
        println!("{w:?}");
    }
    let mut all: Vec<f64> = worst.iter().map(|w| w.0).collect();
    all.sort_by(f64::total_cmp);
    println!("median per-tile rho {}", all[all.len() / 2]);
}
