//! What the command-line tests share: scratch folders, running `rwt` under shell limits,
//! and generated inputs.

#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
/// A fresh folder for one test.
pub fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("rwt-cli-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Runs `rwt` with shell limits (`ulimit ...`) applied first. Two threads and two malloc
/// arenas whatever the machine: an address-space limit counts what those reserve.
pub fn rwt_limited(limits: &str, dir: &Path, args: &[&str]) -> Output {
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

pub fn rwt(dir: &Path, args: &[&str]) -> Output {
    rwt_limited("true", dir, args)
}

/// Files smaller than 512 * `blocks` bytes only (writes past it fail as on a full disk).
pub fn full_disk(blocks: u32) -> String {
    format!("ulimit -f {blocks}")
}

/// 500 MB of address space.
pub const BOUNDED_MEMORY: &str = "ulimit -v 500000";

pub fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// The names in a folder, sorted (temporary files would show here).
pub fn listing(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

/// Asserts the command failed with exit code 2 and a message containing `words`.
#[track_caller]
pub fn refused(o: &Output, words: &str) {
    let e = stderr(o);
    assert_eq!(o.status.code(), Some(2), "{e}");
    assert!(e.contains(words), "expected {words:?} in: {e}");
}

/// A valid PNG of `width x height` black 8-bit grey pixels, small however large: its
/// scanlines (a filter byte and zeros, all zero bytes) deflated by hand as one literal and
/// then copies of 258 bytes at distance 1, with the fixed Huffman codes.
pub fn black_png(width: u32, height: u32) -> Vec<u8> {
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

pub fn crc32(bytes: &[u8]) -> u32 {
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
pub fn picture(dir: &Path) -> PathBuf {
    let img = image::GrayImage::from_fn(64, 48, |x, y| {
        let (dx, dy) = (x as f32 - 30.0, y as f32 - 22.0);
        let disc = if dx * dx + dy * dy < 150.0 { 0.3 } else { 1.0 };
        image::Luma([(disc * (80.0 + 2.5 * x as f32)) as u8])
    });
    let path = dir.join("picture.png");
    img.save(&path).unwrap();
    path
}

/// The mean grey (0 black .. 1 white) of an image file.
pub fn mean_grey(path: &Path) -> f64 {
    let img = image::open(path).unwrap().to_luma8();
    img.pixels().map(|p| p[0] as f64).sum::<f64>() / img.len() as f64 / 255.0
}

/// `rwt points` of a 2 x 2 square at 3 points per unit area, with `extra` arguments.
pub fn small_points(dir: &Path, extra: &[&str]) -> Output {
    let mut args = vec![
        "points",
        "--rect",
        "0",
        "0",
        "2",
        "2",
        "--density",
        "const:3",
    ];
    args.extend(extra);
    rwt(dir, &args)
}
