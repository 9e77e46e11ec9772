//! `rwt tileset ...`: build, check and render tile sets.

use crate::draw::Canvas;
use indicatif::{ProgressBar, ProgressStyle};
use rwt_core::analysis::check::{base_prefix_rho, edge_violations, subdivision_prefix_rho};
use rwt_core::construction::{BuildConfig, Progress, Stage, build};
use rwt_core::files::{AtomicFile, read_limited};
use rwt_core::tileset::{MAX_FILE_BYTES, TileSet, TileSetError, fixed_to_unit};
use std::io::Write;
use std::path::Path;
use std::sync::Mutex;
use std::time::Instant;

/// One progress bar per build stage.
struct Bars {
    bar: Mutex<Option<ProgressBar>>,
}

impl Progress for Bars {
    fn start(&self, stage: Stage, total: u64) {
        let bar = ProgressBar::new(total).with_style(
            ProgressStyle::with_template("{prefix:>18} [{bar:32}] {pos}/{len} {elapsed_precise}")
                .expect("valid template")
                .progress_chars("=> "),
        );
        bar.set_prefix(stage.name());
        *self.bar.lock().expect("progress lock") = Some(bar);
    }
    fn advance(&self, n: u64) {
        if let Some(b) = self.bar.lock().expect("progress lock").as_ref() {
            b.inc(n);
        }
    }
    fn finish(&self) {
        if let Some(b) = self.bar.lock().expect("progress lock").take() {
            b.finish();
        }
    }
}

/// `rwt tileset build`.
pub fn build_cmd(out: &Path, config: BuildConfig) -> Result<(), String> {
    let started = Instant::now();
    let bars = Bars {
        bar: Mutex::new(None),
    };
    let (set, report) = build(&config, &bars).map_err(|e| e.to_string())?;
    let text = set.to_ron();
    // Written atomically; through a link (assets/tilesets/default.ron points into rwt_core,
    // whose embedded set it is), the file it points to is replaced and the link kept.
    let mut file = AtomicFile::create(out).map_err(|e| e.to_string())?;
    let target = file.target().to_path_buf();
    file.write_all(text.as_bytes())
        .map_err(|e| format!("{}: {e}", out.display()))?;
    file.commit().map_err(|e| e.to_string())?;
    let through = if target != out {
        format!(" (a link to {})", target.display())
    } else {
        String::new()
    };
    say!(
        "built {} tiles x {} points (subdivision {}x{}) in {:.1} s -> {}{through} ({:.1} MB)",
        set.tiles.len(),
        set.points_per_tile,
        set.subdivision,
        set.subdivision,
        started.elapsed().as_secs_f64(),
        out.display(),
        text.len() as f64 / 1e6
    );
    say!(
        "  merged rho per tile: min {:.3}, median {:.3}; relaxation residual {:.1e}, max shift {:.2} spacings",
        report.merged_rho_min,
        report.merged_rho_median,
        report.relaxation_residual,
        report.relaxation_max_shift
    );
    say!(
        "  relaxation: {} points short of the requested clearance (worst {:.3} spacings); prefix pass: {} base and {} subdivision ranks without room",
        report.relaxation_crowded,
        report.relaxation_crowded_clearance,
        report.prefix_misses,
        report.sub_prefix_misses
    );
    for (r, lag) in &report.rank_lag {
        say!("  rank {r:>5}: threshold / rank at most {lag:.2}");
    }
    Ok(())
}

/// Reads and validates a tile set file (at most [`MAX_FILE_BYTES`]); the error names the
/// file.
pub fn load(path: &Path) -> Result<TileSet, String> {
    TileSet::read_file(path).map_err(|e| match e {
        TileSetError::File(e) => e.to_string(),
        e => format!("{}: {e}", path.display()),
    })
}

/// `rwt tileset check`: returns whether the set is valid.
pub fn check_cmd(path: &Path, min_rho: Option<f64>) -> Result<bool, String> {
    let bytes = read_limited(path, MAX_FILE_BYTES).map_err(|e| e.to_string())?;
    let set = TileSet::from_ron_bytes_unchecked(&bytes).map_err(|e| e.to_string())?;
    let mut ok = true;
    say!("tile set        {}", path.display());
    say!(
        "tiles           {} ({} colours, complete set)",
        set.tiles.len(),
        set.colors
    );
    say!("points per tile {}", set.points_per_tile);
    say!("subdivision     {0}x{0}", set.subdivision);
    match set.validate() {
        Ok(()) => {
            say!("structure       valid (sizes, colours, rules, rank permutations, subset)")
        }
        Err(e) => {
            say!("structure       INVALID: {e}");
            return Ok(false);
        }
    }
    say!("rank lists      valid permutations; subdivision lists start with the base points");
    for level in 0..=3 {
        let window = if level == 3 { 3 } else { 8 };
        let v = edge_violations(&set, 1, level, window);
        ok &= v == 0;
        say!("edge mismatches level {level}: {v}");
    }
    let dev = set.max_subset_deviation();
    ok &= dev == 0;
    say!("max base-to-subdivision deviation: {dev} (fixed-point units of 2^-32 tile)");
    say!(
        "normalized minimum distance of each tile's first k points, with neighbours (8 seeds, 10x10 tiles):"
    );
    let n = set.points_per_tile as usize;
    for k in [16usize, 64, 256, 1024, n] {
        if k > n {
            continue;
        }
        let rho = base_prefix_rho(&set, k, 8, 10);
        let pass = min_rho.is_none_or(|m| rho >= m);
        ok &= pass;
        say!("  k = {k:>5}: rho = {rho:.3}{}", below_min_rho(pass));
    }
    // Every prefix between the listed ones matters too (a query at 0.3 N per tile reads the
    // first 614): the worst over quarter-octave steps from 16 to N.
    let (worst_k, worst) = quarter_octaves(n)
        .map(|k| (k, base_prefix_rho(&set, k, 8, 10)))
        .fold((0, f64::INFINITY), |a, b| if b.1 < a.1 { b } else { a });
    let pass = min_rho.is_none_or(|m| worst >= m);
    ok &= pass;
    say!(
        "  worst k in 16..{n} (quarter octaves): rho = {worst:.3} at k = {worst_k}{}",
        below_min_rho(pass)
    );
    ok &= subdivision_prefixes_pass(&set, min_rho);
    say!("{}", if ok { "OK" } else { "FAILED" });
    Ok(ok)
}

/// `rwt tileset check`'s rho of each tile's first k subdivision points: whether the worst
/// is at least `min_rho`.
fn subdivision_prefixes_pass(set: &TileSet, min_rho: Option<f64>) -> bool {
    // Between the base level and the next, a query shows a prefix of each tile's
    // subdivision ranking: the points are nested subsets of a fixed set there.
    let n = set.points_per_tile as usize;
    let full = set.subdivision_len() / n;
    say!("the same for each tile's first k subdivision points, k = m N (2 seeds, 4x4 tiles):");
    let mut worst = (0.0, f64::INFINITY);
    let multiples = [1.5, 2.0, 3.0, 4.0, 5.0, 6.0, 8.5, 12.0].into_iter();
    // Only multiples within this set's subdivision (a 2x2 set holds 4 N).
    for m in multiples.filter(|&m| m < full as f64).chain([full as f64]) {
        let k = (m * n as f64) as usize;
        let rho = subdivision_prefix_rho(set, k, 2, 4);
        say!("  m = {m:>4}: rho = {rho:.3}");
        if rho < worst.1 {
            worst = (m, rho);
        }
    }
    let pass = min_rho.is_none_or(|m| worst.1 >= m);
    say!(
        "  worst: rho = {:.3} at m = {}{}",
        worst.1,
        worst.0,
        below_min_rho(pass)
    );
    pass
}

/// What `rwt tileset check` appends to a figure that fails `--min-rho`.
fn below_min_rho(pass: bool) -> &'static str {
    if pass { "" } else { "  (below --min-rho)" }
}

/// Prefix sizes `16 * 2^(i/4)` up to `n`.
fn quarter_octaves(n: usize) -> impl Iterator<Item = usize> {
    (0..)
        .map(|i| (16.0 * 2f64.powf(i as f64 / 4.0)).round() as usize)
        .take_while(move |&k| k <= n)
}

const ORIGIN_COLOURS: [[u8; 3]; 5] = [
    [30, 30, 30],
    [214, 39, 40],
    [31, 119, 180],
    [44, 160, 44],
    [255, 127, 14],
];
const EDGE_COLOURS: [[u8; 3]; 8] = [
    [230, 85, 13],
    [49, 130, 189],
    [117, 107, 177],
    [49, 163, 84],
    [222, 45, 38],
    [99, 99, 99],
    [140, 86, 75],
    [188, 189, 34],
];

fn edge_bars(c: &mut Canvas, set: &TileSet, t: usize, x: f64, y: f64, s: f64, w: f64) {
    let e = set.tiles[t].edges;
    let hc = |k: u8| EDGE_COLOURS[k as usize % 4];
    let vc = |k: u8| EDGE_COLOURS[4 + k as usize % 4];
    c.rect(x, y, x + s, y + w, hc(e.north));
    c.rect(x, y + s - w, x + s, y + s, hc(e.south));
    c.rect(x, y, x + w, y + s, vc(e.west));
    c.rect(x + s - w, y, x + s, y + s, vc(e.east));
}

/// `rwt tileset render`: all tiles with seams, origins and edge colours (figure 4); one tile
/// subdivided twice with the edge colours of every level (figure 6); and a corner of that
/// tile where its points sit exactly on points of its subdivision (figure 7).
pub fn render_cmd(path: &Path, out: &Path) -> Result<(), String> {
    crate::draw::format_of(out, &[crate::draw::Format::Png])?;
    let set = load(path)?;
    let cols = (set.tiles.len() as f64).sqrt().ceil() as usize;
    let s = 220.0;
    let gap = 12.0;
    let grid_w = cols as f64 * (s + gap) + gap;
    let side = (grid_w - 3.0 * gap) / 2.0;
    let width = grid_w + side + gap;
    let height = grid_w;
    let mut c = Canvas::new(width as u32, height as u32, [255, 255, 255]);
    all_tiles(&mut c, &set, cols, s, gap);
    subdivided_tile(&mut c, &set, (grid_w, gap), side);
    corner_on_subdivision(&mut c, &set, (grid_w, 2.0 * gap + side), side);
    c.save(out)?;
    say!("wrote {}", out.display());
    Ok(())
}

/// Figure 4: every tile (`s` pixels wide, `cols` a row, `gap` apart) with its seams, the
/// origins of its points and its edge colours.
fn all_tiles(c: &mut Canvas, set: &TileSet, cols: usize, s: f64, gap: f64) {
    for (t, tile) in set.tiles.iter().enumerate() {
        let x = gap + (t % cols) as f64 * (s + gap);
        let y = gap + (t / cols) as f64 * (s + gap);
        c.rect(x, y, x + s, y + s, [245, 245, 245]);
        edge_bars(c, set, t, x, y, s, 5.0);
        for seam in &tile.seams {
            for w in seam.windows(2) {
                let p = |q: [f32; 2]| (x + q[0] as f64 * s, y + (1.0 - q[1] as f64) * s);
                c.line(p(w[0]), p(w[1]), 1.2, [170, 170, 170]);
            }
        }
        for (k, p) in tile.points.iter().enumerate() {
            let (px, py) = (
                x + fixed_to_unit(p[0]) * s,
                y + (1.0 - fixed_to_unit(p[1])) * s,
            );
            c.disc(px, py, 1.3, ORIGIN_COLOURS[tile.origins[k] as usize % 5]);
        }
    }
}

/// Figure 6: tile 0 and two levels of its subdivision, edge colours only, in the square of
/// `side` pixels at `(x0, y0)`.
fn subdivided_tile(c: &mut Canvas, set: &TileSet, (x0, y0): (f64, f64), side: f64) {
    let n = set.subdivision as usize;
    let t0 = 0usize;
    let level2 = side / (n * n) as f64;
    for (cell, &child) in set.tiles[t0].children.iter().enumerate() {
        let (a, b) = (cell % n, cell / n);
        for (cell2, &grand) in set.tiles[child as usize].children.iter().enumerate() {
            let (a2, b2) = (cell2 % n, cell2 / n);
            let gx = x0 + (a * n + a2) as f64 * level2;
            let gy = y0 + side - (b * n + b2 + 1) as f64 * level2;
            edge_bars(
                c,
                set,
                grand as usize,
                gx + 1.0,
                gy + 1.0,
                level2 - 2.0,
                2.0,
            );
        }
    }
    for (cell, &child) in set.tiles[t0].children.iter().enumerate() {
        let (a, b) = (cell % n, cell / n);
        let cx = x0 + a as f64 * side / n as f64;
        let cy = y0 + side - (b + 1) as f64 * side / n as f64;
        edge_bars(c, set, child as usize, cx, cy, side / n as f64, 4.0);
    }
    edge_bars(c, set, t0, x0, y0, side, 7.0);
}

/// Figure 7: the south-west quarter of tile 0, its points (filled) on its subdivision's
/// points (rings), in the square of `side` pixels at `(x1, y1)`.
fn corner_on_subdivision(c: &mut Canvas, set: &TileSet, (x1, y1): (f64, f64), side: f64) {
    let t0 = 0usize;
    let zoom = side * 4.0;
    c.rect(x1, y1, x1 + side, y1 + side, [250, 250, 250]);
    let big_n = set.points_per_tile as usize;
    let to_px = |q: [u32; 2]| {
        (
            x1 + fixed_to_unit(q[0]) * zoom,
            y1 + side - fixed_to_unit(q[1]) * zoom,
        )
    };
    let inside = |(px, py): (f64, f64)| px >= x1 && px < x1 + side && py >= y1 && py < y1 + side;
    for (j, &e) in set.tiles[t0].subdivision.iter().enumerate() {
        let q = to_px(set.subdivision_point_fixed(t0, e));
        if inside(q) {
            c.disc(q.0, q.1, 3.2, [150, 150, 150]);
            c.disc(q.0, q.1, 2.0, [250, 250, 250]);
            if j < big_n {
                c.disc(q.0, q.1, 1.6, [0, 0, 0]);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn check_gates_base_and_subdivision_prefixes_on_min_rho() {
        let shipped =
            Path::new(env!("CARGO_MANIFEST_DIR")).join("../rwt_core/tilesets/default.ron");
        assert_eq!(check_cmd(&shipped, Some(0.6)), Ok(true));
        // The shipped set's worst prefixes are 0.642 (base, 431 points) and 0.643 (4 N).
        assert_eq!(check_cmd(&shipped, Some(0.66)), Ok(false));
        assert!(check_cmd(Path::new("/does/not/exist.ron"), None).is_err());
    }
}
