//! The `rwt` binary against unlucky and hostile conditions: a full disk (a file-size limit
//! with SIGXFSZ ignored, so writes fail with EFBIG as on a full disk), refused work, and
//! inputs that took gigabytes (run under a 500 MB address-space limit: any larger
//! allocation fails and aborts the process). Every previous output must stay byte for byte.

#![cfg(unix)]

mod common;

use common::*;

#[test]
fn the_generated_pngs_are_what_they_say() {
    let png = black_png(300, 7);
    let img = image::load_from_memory(&png).unwrap().to_luma8();
    assert_eq!(img.dimensions(), (300, 7));
    assert!(img.pixels().all(|p| p[0] == 0));
    // 20000 x 20000 pixels in 2.5 MB; 8192 x 8192 in 0.4 MB.
    assert!(black_png(8192, 8192).len() < 500_000);
}

#[test]
fn refused_queries_leave_the_output_untouched() {
    let dir = scratch("refused");
    let keep = dir.join("keep.txt");
    let before: Vec<u8> = (0..5863).map(|i| b"0123456789 \n"[i % 12]).collect();
    std::fs::write(&keep, &before).unwrap();
    let runs: [(&[&str], &str); 4] = [
        (
            &["--rect", "0", "0", "1e6", "1e6", "--density", "const:100"],
            "over the budget",
        ),
        (
            &[
                "--rect",
                "9e11",
                "0",
                "900000000000.01",
                "0.01",
                "--density",
                "const:1e9",
            ],
            "nearer the origin",
        ),
        (
            &["--rect", "0", "0", "4", "4", "--density", "const:5:garbage"],
            "at most 1",
        ),
        (
            &["--rect", "0", "0", "4", "4", "--density", "noise:5:0.1:4.7"],
            "octaves",
        ),
    ];
    for (args, words) in runs {
        let mut all = vec!["points", "--out", "keep.txt"];
        all.extend(args);
        refused(&rwt(&dir, &all), words);
        assert_eq!(std::fs::read(&keep).unwrap(), before, "{args:?}");
        assert_eq!(listing(&dir), ["keep.txt"], "{args:?}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_full_disk_leaves_every_previous_output_as_it_was() {
    let dir = scratch("full");
    let picture = picture(&dir);
    let picture = picture.to_str().unwrap();
    // Good outputs first.
    let small = ["--rect", "0", "0", "3", "3", "--density", "const:20"];
    let large = ["--rect", "0", "0", "40", "40", "--density", "const:20"];
    let outputs: [(&str, Vec<&str>, Vec<&str>); 5] = [
        (
            "points.txt",
            [&["points", "--out", "points.txt"][..], &small].concat(),
            // 32 000 points (over 256 tiles: the parallel writer).
            [&["points", "--out", "points.txt"][..], &large].concat(),
        ),
        (
            "stipple.png",
            vec!["stipple", picture, "--out", "stipple.png", "--scale", "1"],
            vec!["stipple", picture, "--out", "stipple.png", "--scale", "6"],
        ),
        (
            "stipple.svg",
            vec!["stipple", picture, "--out", "stipple.svg", "--points", "50"],
            vec![
                "stipple",
                picture,
                "--out",
                "stipple.svg",
                "--points",
                "3000",
            ],
        ),
        (
            "set.ron",
            vec!["tileset", "build", "--out", "set.ron", "--points", "16"],
            vec!["tileset", "build", "--out", "set.ron", "--points", "64"],
        ),
        (
            "plot.png",
            vec!["analyse", "points.txt"],
            vec!["analyse", "points.txt", "--plot", "plot.png"],
        ),
    ];
    for (_, good, _) in &outputs {
        let o = rwt(&dir, good);
        assert!(o.status.success(), "{good:?}: {}", stderr(&o));
    }
    // A previous plot to keep.
    std::fs::write(dir.join("plot.png"), b"an earlier plot").unwrap();
    let files: Vec<(&str, Vec<u8>)> = outputs
        .iter()
        .map(|(f, ..)| (*f, std::fs::read(dir.join(f)).unwrap()))
        .collect();
    let names = listing(&dir);
    // The same commands with more to write, on a disk with 8 KB left per file.
    for (file, _, big) in &outputs {
        let o = rwt_limited(&full_disk(16), &dir, big);
        refused(&o, "File too large");
        for (f, bytes) in &files {
            assert_eq!(&std::fs::read(dir.join(f)).unwrap(), bytes, "{file}: {f}");
        }
        assert_eq!(listing(&dir), names, "{file}: no temporary file left");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn tileset_build_writes_through_a_link_atomically() {
    let dir = scratch("link");
    std::fs::write(dir.join("default.ron"), b"the embedded set").unwrap();
    std::os::unix::fs::symlink("default.ron", dir.join("link.ron")).unwrap();
    let args = ["tileset", "build", "--out", "link.ron", "--points", "16"];
    refused(&rwt_limited(&full_disk(8), &dir, &args), "File too large");
    assert_eq!(
        std::fs::read(dir.join("default.ron")).unwrap(),
        b"the embedded set"
    );
    let o = rwt(&dir, &args);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(String::from_utf8_lossy(&o.stdout).contains("(a link to"));
    // The link is still a link, and the file it names is the new set.
    let link = std::fs::symlink_metadata(dir.join("link.ron")).unwrap();
    assert!(link.file_type().is_symlink());
    let set = std::fs::read(dir.join("default.ron")).unwrap();
    assert!(rwt_core::TileSet::from_ron_bytes(&set).is_ok());
    assert_eq!(listing(&dir), ["default.ron", "link.ron"]);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn hostile_inputs_are_refused_within_500_mb() {
    let dir = scratch("hostile");
    // 20000 x 20000 grey (2.5 MB here; 389 KB with a better deflater) used 7.5 GB as a
    // density; an 8192 x 8192 black PNG grew past 5.9 GB in the stipple.
    std::fs::write(dir.join("huge.png"), black_png(20_000, 20_000)).unwrap();
    std::fs::write(dir.join("big.png"), black_png(8192, 8192)).unwrap();
    std::fs::write(dir.join("black.png"), black_png(2048, 2048)).unwrap();
    let points = |density: &str, tileset: Option<&str>| {
        let mut a = vec!["points", "--rect", "0", "0", "8", "8", "--density"];
        a.push(density);
        if let Some(t) = tileset {
            a.extend(["--tileset", t]);
        }
        a.into_iter().map(String::from).collect::<Vec<_>>()
    };
    let runs: Vec<(Vec<String>, &str)> = vec![
        (
            points("const:5", Some("/dev/zero")),
            "/dev/zero: is a device, not a regular file",
        ),
        (
            vec!["tileset".into(), "check".into(), "/dev/zero".into()],
            "is a device",
        ),
        (
            points("image:huge.png", None),
            "would take 2133 MB decoded and as a density, over the limit of 470 MB",
        ),
        (points("dark:huge.png:5", None), "over the limit of 470 MB"),
        (
            ["stipple", "huge.png", "--out", "x.png"]
                .map(String::from)
                .to_vec(),
            "--max-image-pixels",
        ),
        // An 8192 x 8192 image took 1.5 GB at a small scale and a large radius.
        (
            [
                "stipple", "big.png", "--out", "x.png", "--scale", "0.5", "--radius", "5",
            ]
            .map(String::from)
            .to_vec(),
            "--max-image-pixels",
        ),
        (
            ["stipple", "black.png", "--out", "x.png", "--scale", "4"]
                .map(String::from)
                .to_vec(),
            "--max-raster-pixels",
        ),
        (
            [
                "stipple",
                "black.png",
                "--out",
                "x.png",
                "--points",
                "5000000",
            ]
            .map(String::from)
            .to_vec(),
            "--max-dots",
        ),
        // Decoded (2048 x 2048 is within the image limit), then refused from its ink.
        (
            [
                "stipple",
                "black.png",
                "--out",
                "x.png",
                "--scale",
                "1",
                "--radius",
                "1e-3",
            ]
            .map(String::from)
            .to_vec(),
            "--max-dots",
        ),
    ];
    for (args, words) in runs {
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        refused(&rwt_limited(BOUNDED_MEMORY, &dir, &args), words);
    }
    assert_eq!(listing(&dir), ["big.png", "black.png", "huge.png"]);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn stipple_settings_that_aborted_are_typed_errors() {
    let dir = scratch("stipple");
    let picture = picture(&dir);
    let picture = picture.to_str().unwrap();
    for (extra, words) in [
        (&["--radius", "1e-9"][..], "over the limit of 4000000"),
        (&["--radius", "1e-3"], "--max-dots"),
        (&["--points", "1000000000000"], "--max-dots"),
        (&["--scale", "1e4"], "--max-raster-pixels"),
        (&["--radius=-2"], "radius -2 must be positive"),
    ] {
        let mut args = vec!["stipple", picture, "--out", "out.png"];
        args.extend(extra);
        refused(&rwt_limited(BOUNDED_MEMORY, &dir, &args), words);
        assert!(!dir.join("out.png").exists());
    }
    // A 1 x 1 black image is a black page, not a white one.
    image::GrayImage::from_pixel(1, 1, image::Luma([0]))
        .save(dir.join("dot.png"))
        .unwrap();
    let o = rwt(&dir, &["stipple", "dot.png", "--out", "dot-out.png"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let mean = mean_grey(&dir.join("dot-out.png"));
    assert!(mean < 0.15, "mean grey {mean}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn paths_with_colons_are_densities() {
    let dir = scratch("colons");
    let picture = picture(&dir);
    std::fs::copy(&picture, dir.join("a:b.png")).unwrap();
    std::fs::copy(&picture, dir.join("x:5")).unwrap();
    for density in [
        "image:a:b.png",
        "image:a:b.png:40",
        "image:\"x:5\":40",
        "dark:./a:b.png",
    ] {
        let o = rwt(
            &dir,
            &[
                "points",
                "--rect",
                "0",
                "0",
                "10",
                "10",
                "--density",
                density,
            ],
        );
        assert!(o.status.success(), "{density}: {}", stderr(&o));
        assert!(!o.stdout.is_empty(), "{density}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_degenerate_tile_set_fails_its_check() {
    let dir = scratch("degenerate");
    let mut set = rwt_core::TileSet::embedded();
    let (cells, n) = ((set.subdivision as u32).pow(2), set.points_per_tile);
    for tile in &mut set.tiles {
        tile.points = vec![[0, 0]; n as usize];
        tile.subdivision = (0..cells)
            .flat_map(|cell| (0..n).map(move |k| cell << 16 | k))
            .collect();
    }
    std::fs::write(dir.join("flat.ron"), set.to_ron()).unwrap();
    let o = rwt(&dir, &["tileset", "check", "flat.ron"]);
    let out = String::from_utf8_lossy(&o.stdout);
    assert_eq!(o.status.code(), Some(1), "{out}");
    assert!(
        out.contains("INVALID") && out.contains("coincident"),
        "{out}"
    );
    refused(
        &rwt(
            &dir,
            &[
                "points",
                "--rect",
                "0",
                "0",
                "1",
                "1",
                "--density",
                "const:5",
                "--tileset",
                "flat.ron",
            ],
        ),
        "coincident",
    );
    std::fs::remove_dir_all(&dir).unwrap();
}
