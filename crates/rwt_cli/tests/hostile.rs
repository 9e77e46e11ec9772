//! The second hostile pass against the `rwt` binary: options that panicked or were taken
//! as nonsense, outputs named for another format, readers that blocked or read without
//! end, signals that left temporary files, and work whose memory followed the requested
//! budget instead of the output. Each case failed before its fix.

#![cfg(unix)]

mod common;

use common::*;
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

fn args(list: &[&str]) -> Vec<String> {
    list.iter().map(|s| s.to_string()).collect()
}

#[test]
fn options_that_panicked_or_were_taken_as_nonsense_are_refused() {
    let dir = scratch("options");
    let picture = picture(&dir);
    let picture = picture.to_str().unwrap();
    let runs: Vec<(Vec<String>, &str)> = vec![
        // An index into an empty list (exit 101).
        (args(&["points", "--density", "const:1"]), "--rect"),
        (
            args(&[
                "points",
                "--rect",
                "0",
                "0",
                "1",
                "1",
                "--density",
                "const:1",
                "--tile-size",
                "NaN",
            ]),
            "NaN is not a finite number",
        ),
        (
            args(&[
                "points",
                "--rect",
                "0",
                "0",
                "inf",
                "1",
                "--density",
                "const:1",
            ]),
            "inf is not a finite number",
        ),
        (
            args(&["stipple", picture, "--out", "o.png", "--gamma", "nan"]),
            "--gamma",
        ),
        (
            args(&["stipple", picture, "--out", "o.png", "--contrast=-inf"]),
            "--contrast",
        ),
        (
            args(&["stipple", picture, "--out", "o.png", "--radius", "NaN"]),
            "--radius",
        ),
        // A white 1 x 1 page, exit 0.
        (
            args(&["stipple", picture, "--out", "o.png", "--scale", "1e-300"]),
            "raster pixels across at scale 1e-300",
        ),
        // Two dots, exit 0.
        (
            args(&["stipple", picture, "--out", "o.png", "--points", "0"]),
            "points 0 must be positive",
        ),
        // An allocation of 82 PB and an abort.
        (
            args(&[
                "stipple",
                picture,
                "--out",
                "o.png",
                "--max-dots",
                "18446744073709551615",
                "--radius",
                "1e-6",
            ]),
            "raster pixels across",
        ),
        (
            args(&["tileset", "check", "x.ron", "--min-rho", "nan"]),
            "--min-rho",
        ),
    ];
    for (args, words) in runs {
        let a: Vec<&str> = args.iter().map(String::as_str).collect();
        refused(&rwt_limited(BOUNDED_MEMORY, &dir, &a), words);
    }
    assert_eq!(listing(&dir), ["picture.png"]);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn outputs_are_written_in_the_format_their_name_says() {
    let dir = scratch("formats");
    let picture = picture(&dir);
    let picture = picture.to_str().unwrap();
    std::fs::write(
        dir.join("points.txt"),
        (0..400)
            .map(|i| {
                format!(
                    "{} {}\n",
                    (i * 37 % 400) as f64 * 0.05,
                    (i * 91 % 400) as f64 * 0.05
                )
            })
            .collect::<String>(),
    )
    .unwrap();
    // PNG bytes were written under these names.
    for (list, words) in [
        (
            &["stipple", picture, "--out", "o.jpg"][..],
            "this writes .png or .svg",
        ),
        (
            &["stipple", picture, "--out", "o"],
            "this writes .png or .svg",
        ),
        (
            &["tileset", "render", "default.ron", "--out", "r.svg"],
            "this writes .png",
        ),
        (
            &["analyse", "points.txt", "--plot", "p.svg"],
            "this writes .png",
        ),
    ] {
        refused(&rwt(&dir, list), words);
    }
    assert_eq!(listing(&dir), ["picture.png", "points.txt"]);
    // Upper case is the same extension.
    let o = rwt(&dir, &["stipple", picture, "--out", "O.SVG"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        std::fs::read_to_string(dir.join("O.SVG"))
            .unwrap()
            .starts_with("<svg")
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn readers_refuse_devices_fifos_and_endless_lines() {
    let dir = scratch("readers");
    assert!(
        Command::new("mkfifo")
            .arg(dir.join("pipe"))
            .status()
            .unwrap()
            .success()
    );
    // One line of 20 MB (`/dev/zero` read as one endless line took 20 GB a minute).
    std::fs::write(dir.join("long.txt"), vec![b'1'; 20 << 20]).unwrap();
    for (list, words) in [
        (
            &["analyse", "/dev/zero"][..],
            "/dev/zero: is a device, not a regular file",
        ),
        (&["analyse", "pipe"], "pipe: is a FIFO"),
        (&["analyse", "."], "is a folder"),
        (&["analyse", "long.txt"], "line 1 is longer than 4096 bytes"),
        (&["stipple", "pipe", "--out", "o.png"], "is a FIFO"),
        (&["stipple", "/dev/zero", "--out", "o.png"], "is a device"),
        (
            &[
                "points",
                "--rect",
                "0",
                "0",
                "1",
                "1",
                "--density",
                "image:pipe",
            ],
            "is a FIFO",
        ),
        (
            &[
                "points",
                "--rect",
                "0",
                "0",
                "1",
                "1",
                "--density",
                "const:1",
                "--tileset",
                "pipe",
            ],
            "is a FIFO",
        ),
        (
            &["tileset", "render", "pipe", "--out", "r.png"],
            "is a FIFO",
        ),
    ] {
        let started = Instant::now();
        refused(&rwt_limited(BOUNDED_MEMORY, &dir, list), words);
        assert!(started.elapsed() < Duration::from_secs(20), "{list:?}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn points_on_a_degenerate_extent_are_not_analysed_into_nan() {
    let dir = scratch("degenerate");
    for (name, text) in [
        // NaN, inf and -1756 dB with exit 0.
        (
            "tiny.txt",
            (0..100)
                .map(|i| {
                    format!(
                        "{:e} {:e}\n",
                        i as f64 * 1e-310,
                        (i * 7 % 100) as f64 * 1e-310
                    )
                })
                .collect::<String>(),
        ),
        (
            "vast.txt",
            (0..100)
                .map(|i| {
                    format!(
                        "{:e} {:e}\n",
                        (i as f64 - 50.0) * 1e300,
                        ((i * 7 % 100) as f64 - 50.0) * 1e300
                    )
                })
                .collect(),
        ),
        (
            "far.txt",
            (0..100)
                .map(|i| {
                    format!(
                        "{} {}\n",
                        1e15 + i as f64 * 1e-3,
                        1e15 + (i * 7 % 100) as f64 * 1e-3
                    )
                })
                .collect(),
        ),
    ] {
        std::fs::write(dir.join(name), text).unwrap();
        let o = rwt(&dir, &["analyse", name]);
        refused(&o, "no area an analysis can measure");
        let out = String::from_utf8_lossy(&o.stdout);
        assert!(
            !out.contains("NaN") && !out.contains("inf"),
            "{name}: {out}"
        );
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_seam_far_outside_its_tile_is_refused_not_drawn_forever() {
    let dir = scratch("seam");
    let mut set = rwt_core::TileSet::embedded();
    set.tiles[1].seams[0][3] = [0.5, 1e30];
    std::fs::write(dir.join("far.ron"), set.to_ron()).unwrap();
    let started = Instant::now();
    refused(
        &rwt(&dir, &["tileset", "render", "far.ron", "--out", "r.png"]),
        "tile 1: seam point (0.5, 1000000000000000000000000000000) is outside",
    );
    assert!(started.elapsed() < Duration::from_secs(20));
    assert_eq!(listing(&dir), ["far.ron"]);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_thin_black_image_stipples_black_not_grey() {
    let dir = scratch("thin");
    image::GrayImage::from_pixel(20_000, 1, image::Luma([0]))
        .save(dir.join("thin.png"))
        .unwrap();
    let o = rwt(&dir, &["stipple", "thin.png", "--out", "out.png"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let mean = mean_grey(&dir.join("out.png"));
    // It was 0.225.
    assert!(mean < 0.05, "mean grey {mean}");
    // Dots the image cannot hold are refused, not drawn clipped.
    refused(
        &rwt(
            &dir,
            &["stipple", "thin.png", "--out", "r.png", "--radius", "2"],
        ),
        "do not fit an image 1 px across",
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Starts `rwt points` writing a large file into `dir`, and waits until its temporary
/// file exists.
fn start_writing(dir: &Path) -> std::process::Child {
    let mut child = Command::new(env!("CARGO_BIN_EXE_rwt"))
        .args([
            "points",
            "--rect",
            "0",
            "0",
            "3000",
            "3000",
            "--density",
            "const:2",
        ])
        .args(["--out", "big.txt"])
        .current_dir(dir)
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let started = Instant::now();
    while !listing(dir).iter().any(|n| n.ends_with(".rwt-tmp")) {
        assert!(
            started.elapsed() < Duration::from_secs(60),
            "no temporary file"
        );
        assert!(child.try_wait().unwrap().is_none(), "it ended");
        std::thread::sleep(Duration::from_millis(20));
    }
    // Well into the write.
    std::thread::sleep(Duration::from_millis(300));
    child
}

#[test]
fn signals_leave_no_temporary_file_and_the_previous_output() {
    let dir = scratch("signals");
    std::fs::write(dir.join("big.txt"), b"previous\n").unwrap();
    // Each left a hidden temporary file of 130-185 MB.
    for signal in ["INT", "TERM", "HUP"] {
        let mut child = start_writing(&dir);
        let killed = Command::new("kill")
            .args(["-s", signal, &child.id().to_string()])
            .status()
            .unwrap();
        assert!(killed.success());
        let status = child.wait().unwrap();
        assert_eq!(status.code(), Some(130), "SIG{signal}");
        assert_eq!(listing(&dir), ["big.txt"], "SIG{signal}");
        assert_eq!(std::fs::read(dir.join("big.txt")).unwrap(), b"previous\n");
    }
    // `kill -9` cannot be caught: the next write to the same target removes what it left.
    let mut child = start_writing(&dir);
    child.kill().unwrap();
    child.wait().unwrap();
    assert_eq!(listing(&dir).len(), 2);
    let o = small_points(&dir, &["--out", "big.txt"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(listing(&dir), ["big.txt"]);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_huge_parallel_query_writes_as_it_goes_within_bounded_memory() {
    let dir = scratch("window");
    // 10^12 points allowed: the plan of every block took 15 GB before a point was written.
    let mut child = Command::new("sh")
        .arg("-c")
        .arg(format!("{BOUNDED_MEMORY}; exec \"$0\" \"$@\""))
        .arg(env!("CARGO_BIN_EXE_rwt"))
        .args([
            "points",
            "--rect",
            "-1e5",
            "-1e5",
            "1e5",
            "1e5",
            "--density",
            "const:0.5",
        ])
        .args(["--budget", "1000000000000", "--out", "many.txt"])
        .env("RAYON_NUM_THREADS", "2")
        .env("MALLOC_ARENA_MAX", "2")
        .current_dir(&dir)
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let started = Instant::now();
    let written = || {
        std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().metadata().unwrap().len())
            .sum::<u64>()
    };
    while written() < 1 << 20 {
        assert!(
            started.elapsed() < Duration::from_secs(30),
            "nothing written in 30 s"
        );
        assert!(
            child.try_wait().unwrap().is_none(),
            "it ended: {:?}",
            child.wait_with_output()
        );
        std::thread::sleep(Duration::from_millis(50));
    }
    Command::new("kill")
        .args(["-s", "INT", &child.id().to_string()])
        .status()
        .unwrap();
    let out = child.wait_with_output().unwrap();
    assert_eq!(
        out.status.code(),
        Some(130),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(listing(&dir).is_empty(), "{:?}", listing(&dir));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn legal_output_names_and_link_chains_are_written() {
    let dir = scratch("names");
    // A name of 255 bytes: its temporary name was longer than a name may be.
    let long = "p".repeat(251) + ".txt";
    let dash = "-leading dash.txt";
    std::os::unix::fs::symlink("sub/hop", dir.join("chain.txt")).unwrap();
    std::fs::create_dir(dir.join("sub")).unwrap();
    std::os::unix::fs::symlink("../final.txt", dir.join("sub/hop")).unwrap();
    for name in [long.as_str(), dash, "chain.txt"] {
        let out = format!("--out={name}");
        let o = small_points(&dir, &[&out]);
        assert!(o.status.success(), "{name}: {}", stderr(&o));
    }
    for file in [long.as_str(), dash, "final.txt"] {
        let lines = std::fs::read_to_string(dir.join(file))
            .unwrap()
            .lines()
            .count();
        assert!(lines > 5, "{file}: {lines} lines");
    }
    assert!(
        std::fs::symlink_metadata(dir.join("sub/hop"))
            .unwrap()
            .is_symlink()
    );
    std::fs::remove_dir_all(&dir).unwrap();
}
