//! `rwt analyse`: quality figures of a point set beside references computed in the same run.

use crate::draw::{Canvas, Format, format_of};
use glam::DVec2;
use rwt_core::analysis::{Spectrum, WindowAnalysis, WindowGrid, reference};
use std::path::Path;

/// One row of the comparison table.
pub struct Row {
    /// Generator name.
    pub name: &'static str,
    /// Normalized minimum distance.
    pub rho: f64,
    /// Mean radial power below half the principal frequency.
    pub low_frequency: f64,
    /// Mean anisotropy (dB).
    pub mean_anisotropy: f64,
    /// Largest anisotropy (dB).
    pub max_anisotropy: f64,
    /// The spectrum.
    pub spectrum: Spectrum,
}

/// Computes the rows for point windows of side `side` (ours first, then the references).
pub fn compare(windows: &[(DVec2, Vec<DVec2>)], side: f64, size: usize) -> Vec<Row> {
    let count = (windows.iter().map(|w| w.1.len()).sum::<usize>() / windows.len().max(1)).max(1);
    let density = count as f64 / (side * side);
    let row = |name, wins: &[(DVec2, Vec<DVec2>)]| {
        let WindowAnalysis { rho, spectrum, .. } = WindowAnalysis::of(wins, side, size);
        Row {
            name,
            rho,
            low_frequency: spectrum.low_frequency_power(side, density, 0.5),
            mean_anisotropy: spectrum.mean_anisotropy(2),
            max_anisotropy: spectrum.max_anisotropy(2),
            spectrum,
        }
    };
    let make = |f: &dyn Fn(u64) -> Vec<DVec2>| -> Vec<(DVec2, Vec<DVec2>)> {
        (0..windows.len() as u64)
            .map(|i| (DVec2::ZERO, f(i)))
            .collect()
    };
    vec![
        row("this point set", windows),
        row(
            "dart throwing",
            &make(&|i| reference::dart_throwing(DVec2::ZERO, side, count, i)),
        ),
        row(
            "jittered grid",
            &make(&|i| reference::jittered_grid(DVec2::ZERO, side, count, i)),
        ),
        row(
            "white noise",
            &make(&|i| reference::white_noise(DVec2::ZERO, side, count, i)),
        ),
    ]
}

/// Prints the table.
pub fn print_table(rows: &[Row]) {
    say!(
        "{:<16} {:>7} {:>12} {:>15} {:>15}",
        "",
        "rho",
        "low-freq pow",
        "mean aniso dB",
        "max aniso dB"
    );
    for r in rows {
        say!(
            "{:<16} {:>7.3} {:>12.3} {:>15.1} {:>15.1}",
            r.name,
            r.rho,
            r.low_frequency,
            r.mean_anisotropy,
            r.max_anisotropy
        );
    }
}

/// Longest line of a point file read.
const MAX_LINE: usize = 4096;

/// Calls `f` with every point of the file (`x y` first on each line; lines with fewer than
/// two fields are skipped), streaming it; returns how many.
fn for_each_point(path: &Path, mut f: impl FnMut(DVec2)) -> Result<usize, String> {
    use std::io::{BufRead, Read};
    let file = rwt_core::files::open_regular(path).map_err(|e| e.to_string())?;
    let mut reader = std::io::BufReader::new(file);
    let (mut count, mut line, mut n) = (0, Vec::new(), 0);
    loop {
        line.clear();
        n += 1;
        // One line at a time, at most MAX_LINE bytes of it.
        let read = (&mut reader)
            .take(MAX_LINE as u64 + 1)
            .read_until(b'\n', &mut line)
            .map_err(|e| format!("{}: line {n}: {e}", path.display()))?;
        if read == 0 {
            break;
        }
        if line.len() > MAX_LINE {
            return Err(format!(
                "{}: line {n} is longer than {MAX_LINE} bytes: not a point file",
                path.display()
            ));
        }
        let text = String::from_utf8_lossy(&line);
        let mut it = text.split_whitespace();
        let (Some(x), Some(y)) = (it.next(), it.next()) else {
            continue;
        };
        let number = |v: &str, axis: &str| {
            v.parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| format!("{}: line {}: bad {axis} {v:?}", path.display(), n + 1))
        };
        f(DVec2::new(number(x, "x")?, number(y, "y")?));
        count += 1;
    }
    Ok(count)
}

/// `rwt analyse FILE [--plot out.png]`.
pub fn run(path: &Path, plot: Option<&Path>) -> Result<(), String> {
    if let Some(out) = plot {
        format_of(out, &[Format::Png])?;
    }
    // Two passes over the file: its extent, then the points of the windows.
    let (mut lo, mut hi) = (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY));
    let count = for_each_point(path, |p| {
        lo = lo.min(p);
        hi = hi.max(p);
    })?;
    if count < 16 {
        return Err(format!(
            "{}: {count} points, need at least 16",
            path.display()
        ));
    }
    let grid = WindowGrid::new(lo, hi, count).map_err(|e| format!("{}: {e}", path.display()))?;
    let (side, density) = (grid.side, grid.density);
    let mut windows = grid.split(std::iter::empty());
    for_each_point(path, |p| {
        if let Some(k) = grid.window_of(p) {
            windows[k].1.push(p);
        }
    })?;
    say!(
        "{count} points, {:.4} x {:.4}, {density:.1} per unit area; {} window(s) of side {side:.4}",
        hi.x - lo.x,
        hi.y - lo.y,
        windows.len(),
    );
    let rows = compare(&windows, side, 128);
    print_table(&rows);
    if let Some(out) = plot {
        draw(&windows[0], side, &rows, out)?;
        say!("wrote {}", out.display());
    }
    Ok(())
}

/// A spectrum in the square of `panel` pixels at `(x1, y1)`, log scale from 0.01 (black) to
/// 10 (white), as in the paper.
fn spectrum_panel(c: &mut Canvas, s: &Spectrum, (x1, y1): (f64, f64), panel: f64) {
    let px = panel / s.size as f64;
    for v in 0..s.size {
        for u in 0..s.size {
            let p = s.power[v * s.size + u].max(1e-3);
            let t = ((p.log10() + 2.0) / 3.0).clamp(0.0, 1.0);
            let g = (255.0 * t) as u8;
            c.rect(
                x1 + u as f64 * px,
                y1 + (s.size - 1 - v) as f64 * px,
                x1 + (u + 1) as f64 * px,
                y1 + (s.size - v) as f64 * px,
                [g, g, g],
            );
        }
    }
}

const COLOURS: [[u8; 3]; 4] = [[20, 20, 20], [31, 119, 180], [44, 160, 44], [214, 39, 40]];

/// Points, power spectrum, radial power and anisotropy (the paper's figure 2 layout).
pub fn draw(
    window: &(DVec2, Vec<DVec2>),
    side: f64,
    rows: &[Row],
    out: &Path,
) -> Result<(), String> {
    let panel = 320.0;
    let gap = 16.0;
    let mut c = Canvas::new(
        (4.0 * panel + 5.0 * gap) as u32,
        (panel + 2.0 * gap) as u32,
        [255, 255, 255],
    );
    // Points.
    let (o, pts) = window;
    let (x0, y0) = (gap, gap);
    let r = (0.9 * panel / (pts.len() as f64).sqrt() * 0.25).clamp(0.6, 3.0);
    for p in pts {
        let q = (*p - *o) / side;
        c.disc(x0 + q.x * panel, y0 + (1.0 - q.y) * panel, r, [0, 0, 0]);
    }
    spectrum_panel(&mut c, &rows[0].spectrum, (2.0 * gap + panel, gap), panel);
    // Radial mean power (0..4) and anisotropy (-20..+10 dB), every row.
    let curves =
        |c: &mut Canvas, x: f64, f: &dyn Fn(&Row) -> &Vec<f64>, lo: f64, hi: f64, guide: f64| {
            c.rect(x, gap, x + panel, gap + panel, [248, 248, 248]);
            let gy = gap + panel * (1.0 - (guide - lo) / (hi - lo));
            c.line((x, gy), (x + panel, gy), 1.0, [200, 200, 200]);
            for (k, row) in rows.iter().enumerate().rev() {
                let v = f(row);
                let n = v.len().max(2);
                let mut prev: Option<(f64, f64)> = None;
                for (i, &y) in v.iter().enumerate().skip(1) {
                    if !y.is_finite() {
                        prev = None;
                        continue;
                    }
                    let p = (
                        x + panel * i as f64 / (n - 1) as f64,
                        gap + panel * (1.0 - ((y - lo) / (hi - lo)).clamp(0.0, 1.0)),
                    );
                    if let Some(q) = prev {
                        c.line(q, p, if k == 0 { 2.0 } else { 1.2 }, COLOURS[k % 4]);
                    }
                    prev = Some(p);
                }
            }
        };
    curves(
        &mut c,
        3.0 * gap + 2.0 * panel,
        &|r: &Row| &r.spectrum.radial_mean,
        0.0,
        4.0,
        1.0,
    );
    curves(
        &mut c,
        4.0 * gap + 3.0 * panel,
        &|r: &Row| &r.spectrum.anisotropy_db,
        -20.0,
        10.0,
        0.0,
    );
    c.save(out)
}
