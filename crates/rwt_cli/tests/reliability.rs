//! The `rwt` binary against unlucky and hostile conditions: a full disk (a file-size limit
//! with SIGXFSZ ignored, so writes fail with EFBIG as on a full disk), refused work, and
//! inputs that took gigabytes (run under a 500 MB address-space limit: any larger
//! allocation fails and aborts the process). Every previous output must stay byte for byte.

#![cfg(unix)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// A fresh folder for one test.
fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("rwt-cli-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Runs `rwt` with shell limits (`ulimit ...`) applied first. Two threads and two malloc
/// arenas whatever the machine: an address-space limit counts what those reserve.
fn rwt_limited(limits: &str, dir: &Path, args: &[&str]) -> Output {
    Command::new("sh")
        .arg("-c")
        .arg(format!("{limits}; trap '' XFSZ; exec \"$0\" \"$@\""))
        .arg(env!("CARGO_BIN_EXE_rwt"))
        .args(args)
        .env("RAYON_NUM_THREADS", "2")
        .env("MALLOC_ARENA_MAX", "2")
        .current_dir(dir)
        .output()
        .unwrap()
}

fn rwt(dir: &Path, args: &[&str]) -> Output {
    rwt_limited("true", dir, args)
}

/// Files smaller than 512 * `blocks` bytes only (writes past it fail as on a full disk).
fn full_disk(blocks: u32) -> String {
    format!("ulimit -f {blocks}")
}

/// 500 MB of address space.
const BOUNDED_MEMORY: &str = "ulimit -v 500000";

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// The names in a folder, sorted (temporary files would show here).
fn listing(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

/// Asserts the command failed with exit code 2 and a message containing `words`.
#[track_caller]
fn refused(o: &Output, words: &str) {
    let e = stderr(o);
    assert_eq!(o.status.code(), Some(2), "{e}");
    assert!(e.contains(words), "expected {words:?} in: {e}");
}

/// A valid PNG of `width x height` black 8-bit grey pixels, small however large: its
/// scanlines (a filter byte and zeros, all zero bytes) deflated by hand as one literal and
/// then copies of 258 bytes at distance 1, with the fixed Huffman codes.
fn black_png(width: u32, height: u32) -> Vec<u8> {
    struct Bits {
        out: Vec<u8>,
        acc: u64,
        n: u32,
    }
    impl Bits {
        /// `len` bits of `v`, least significant first.
        fn put(&mut self, v: u64, len: u32) {
            self.acc |= v << self.n;
            self.n += len;
            while self.n >= 8 {
                self.out.push(self.acc as u8);
                self.acc >>= 8;
                self.n -= 8;
            }
        }
        /// A Huffman code of `len` bits, most significant first.
        fn code(&mut self, code: u64, len: u32) {
            let reversed = (0..len).fold(0, |r, i| r << 1 | (code >> i) & 1);
            self.put(reversed, len);
        }
    }
    let total = height as u64 * (width as u64 + 1);
    let mut b = Bits {
        out: vec![0x78, 0x01],
        acc: 0,
        n: 0,
    };
    b.put(1, 1); // last block
    b.put(1, 2); // fixed Huffman codes
    b.code(0x30, 8); // literal 0
    let mut left = total - 1;
    while left >= 258 {
        b.code(0xc5, 8); // length 258
        b.code(0, 5); // distance 1
        left -= 258;
    }
    for _ in 0..left {
        b.code(0x30, 8);
    }
    b.code(0, 7); // end of block
    b.put(0, 7); // to a byte boundary
    // Adler-32 of zeros: a stays 1, b counts the bytes.
    let adler = ((total % 65521) << 16) as u32 | 1;
    let mut zlib = b.out;
    zlib.extend(adler.to_be_bytes());
    let chunk = |png: &mut Vec<u8>, kind: &[u8], data: &[u8]| {
        png.extend((data.len() as u32).to_be_bytes());
        let mut body = kind.to_vec();
        body.extend(data);
        png.extend(&body);
        png.extend(crc32(&body).to_be_bytes());
    };
    let mut png = b"\x89PNG\r\n\x1a\n".to_vec();
    let mut ihdr = width.to_be_bytes().to_vec();
    ihdr.extend(height.to_be_bytes());
    ihdr.extend([8, 0, 0, 0, 0]);
    chunk(&mut png, b"IHDR", &ihdr);
    chunk(&mut png, b"IDAT", &zlib);
    chunk(&mut png, b"IEND", &[]);
    png
}

fn crc32(bytes: &[u8]) -> u32 {
    let table: Vec<u32> = (0..256u32)
        .map(|n| {
            (0..8).fold(n, |c, _| {
                if c & 1 == 1 {
                    0xedb8_8320 ^ (c >> 1)
                } else {
                    c >> 1
                }
            })
        })
        .collect();
    !bytes.iter().fold(!0u32, |c, &b| {
        table[((c ^ b as u32) & 0xff) as usize] ^ (c >> 8)
    })
}

/// A 64 x 48 grey gradient with a dark disc, as a PNG.
fn picture(dir: &Path) -> PathBuf {
    let img = image::GrayImage::from_fn(64, 48, |x, y| {
        let (dx, dy) = (x as f32 - 30.0, y as f32 - 22.0);
        let disc = if dx * dx + dy * dy < 150.0 { 0.3 } else { 1.0 };
        image::Luma([(disc * (80.0 + 2.5 * x as f32)) as u8])
    });
    let path = dir.join("picture.png");
    img.save(&path).unwrap();
    path
}

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
    std::fs::write(dir.join("black.png"), black_png(8192, 8192)).unwrap();
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
            "more than 134217728 bytes",
        ),
        (
            vec!["tileset".into(), "check".into(), "/dev/zero".into()],
            "more than 134217728",
        ),
        (
            points("image:huge.png", None),
            "over the limit of 67108864 pixels",
        ),
        (
            points("dark:huge.png:5", None),
            "over the limit of 67108864 pixels",
        ),
        (
            ["stipple", "huge.png", "--out", "x.png"]
                .map(String::from)
                .to_vec(),
            "--max-raster-pixels",
        ),
        (
            ["stipple", "black.png", "--out", "x.png"]
                .map(String::from)
                .to_vec(),
            "--max-raster-pixels",
        ),
        (
            ["stipple", "black.png", "--out", "x.png", "--scale", "1"]
                .map(String::from)
                .to_vec(),
            "--max-dots",
        ),
        // Decoded (8192 x 8192 is within the pixel limit), then refused from its ink.
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
    assert_eq!(listing(&dir), ["black.png", "huge.png"]);
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
    let out = image::open(dir.join("dot-out.png")).unwrap().to_luma8();
    let mean = out.pixels().map(|p| p[0] as f64).sum::<f64>() / out.len() as f64 / 255.0;
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
