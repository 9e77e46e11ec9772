//! The recursive progressive Wang tile set: its data, file format, loading and validation.
//!
//! Positions are stored as 32-bit fixed point fractions of the tile (`x = X / 2^32`). The
//! subset property of the paper (section 5.2) then holds *exactly*: for every base point
//! `k` of tile `t`, the first `N` entries of `t`'s subdivision list name a point `k'` of the
//! child in cell `(a, b)` with `X_t[k] = floor((a * 2^32 + X_c[k']) / n)` (same for `y`).
//! A point reached through either level is the same stored number, so no tolerance is
//! involved anywhere.

use crate::files::{FileError, read_limited};
use crate::geometry::{closest_pair, hex_spacing};
use crate::wang::{EdgeColors, complete_set_size};
use glam::DVec2;
use serde::{Deserialize, Serialize};
use std::path::Path;
use thiserror::Error;

/// Version of the file format written by this crate.
pub const FORMAT_VERSION: u32 = 1;

/// The shipped tile set, built by `rwt tileset build` and embedded in the library.
const EMBEDDED: &[u8] = include_bytes!("../tilesets/default.ron");

/// Scale of the fixed-point tile coordinates.
pub const FIXED_ONE: f64 = 4_294_967_296.0;

/// Largest tile set file [`TileSet::read_file`] reads: 128 MiB (the shipped set is 4.6 MB;
/// a complete set of 4 colours with 2048 points per tile is about 75 MB).
pub const MAX_FILE_BYTES: u64 = 128 << 20;

/// Most edge colours of a set (`K`).
const MAX_COLORS: usize = 8;

/// Most tiles of a set (`K^4`).
const MAX_TILES: usize = MAX_COLORS.pow(4);

/// Most seam polylines a tile file may give a tile (a built tile has four).
const MAX_SEAMS: usize = 64;

/// Sequences read with a most length, refused as soon as they pass it: a file of nested
/// empty sequences (`[[],[],...]`, 3 bytes each in the file, 24 in memory) must not
/// balloon before the set is validated.
mod bounded {
    use serde::de::{Deserialize, Deserializer, Error, SeqAccess, Visitor};
    use std::marker::PhantomData;

    pub fn seq<'de, D: Deserializer<'de>, T: Deserialize<'de>, const MAX: usize>(
        d: D,
    ) -> Result<Vec<T>, D::Error> {
        struct Bounded<T, const MAX: usize>(PhantomData<T>);
        impl<'de, T: Deserialize<'de>, const MAX: usize> Visitor<'de> for Bounded<T, MAX> {
            type Value = Vec<T>;

            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                write!(f, "a sequence of at most {MAX} elements")
            }

            fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Vec<T>, A::Error> {
                let mut out = Vec::new();
                while let Some(item) = seq.next_element()? {
                    if out.len() == MAX {
                        return Err(A::Error::custom(format!(
                            "a sequence of more than {MAX} elements"
                        )));
                    }
                    out.push(item);
                }
                Ok(out)
            }
        }
        d.deserialize_seq(Bounded::<T, MAX>(PhantomData))
    }
}

/// Closest two points of one tile may be, as a fraction of the spacing of `N` points on a
/// hexagonal lattice (`rho`): blue-noise tiles reach 0.6 to 0.8, white noise about 0.01.
/// Closer points are a corrupt or degenerate set (coincident or crowded points).
pub const MIN_TILE_RHO: f64 = 0.2;

/// One Wang tile.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Tile {
    /// Edge colours (must equal the tile's index in the complete set).
    pub edges: EdgeColors,
    /// Subdivision rule: the `n * n` child tiles, row-major from the south-west cell
    /// (`cell = b * n + a`, `a` to the east, `b` to the north).
    pub children: Vec<u16>,
    /// Points in base-rank order, fixed point `[x, y]`.
    pub points: Vec<[u32; 2]>,
    /// Where each point came from (0 interior, 1..=4 the N, E, S, W edge source); used by
    /// rendering and seam analysis only.
    pub origins: Vec<u8>,
    /// The `n^2 N` points of the subdivision in subdivision-rank order, each `cell << 16 |
    /// child point index`. The first `N` entries are this tile's own points, in base order.
    pub subdivision: Vec<u32>,
    /// Seam polylines of the construction (for pictures), tile coordinates in `[0, 1]`.
    #[serde(default, deserialize_with = "bounded::seq::<_, _, MAX_SEAMS>")]
    pub seams: Vec<Vec<[f32; 2]>>,
}

/// A complete recursive Wang tile set.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TileSet {
    /// File format version.
    pub format: u32,
    /// Number of edge colours `K` (per orientation); the set has `K^4` tiles.
    pub colors: u8,
    /// Subdivision factor `n`: a tile splits into `n x n` children.
    pub subdivision: u8,
    /// Points per tile `N`.
    pub points_per_tile: u32,
    /// Seed the set was built from.
    pub seed: u64,
    /// `n`-colour sequence that replaces each horizontal edge colour on subdivision.
    #[serde(deserialize_with = "bounded::seq::<_, _, MAX_COLORS>")]
    pub horizontal_sequences: Vec<Vec<u8>>,
    /// `n`-colour sequence that replaces each vertical edge colour on subdivision.
    #[serde(deserialize_with = "bounded::seq::<_, _, MAX_COLORS>")]
    pub vertical_sequences: Vec<Vec<u8>>,
    /// Tiles, indexed by [`EdgeColors::complete_index`].
    #[serde(deserialize_with = "bounded::seq::<_, _, MAX_TILES>")]
    pub tiles: Vec<Tile>,
}

/// What is wrong with a tile set file.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum TileSetError {
    /// The bytes are not a valid RON tile set (truncated, corrupt or not a tile set).
    #[error("tile set is not valid RON: {0}")]
    Parse(String),
    /// Written by a different, incompatible format version.
    #[error("tile set format {found} is not supported (expected {expected})")]
    Format {
        /// Version in the file.
        found: u32,
        /// Version this library reads.
        expected: u32,
    },
    /// Header values out of range.
    #[error("invalid tile set header: {0}")]
    Header(String),
    /// Two points of a tile are closer than [`MIN_TILE_RHO`] of the spacing its points
    /// should have: coincident or crowded points, not blue noise.
    #[error(
        "tile {tile}: points {first} and {second} are {rho:.4} of the ideal spacing apart, \
         below {MIN_TILE_RHO} (coincident or crowded points: not a blue-noise tile set)"
    )]
    Crowded {
        /// Tile index.
        tile: usize,
        /// One point (base rank).
        first: usize,
        /// The point nearest to it.
        second: usize,
        /// Their distance over the hexagonal spacing of the tile's points.
        rho: f64,
    },
    /// The file could not be read, or is larger than the reader accepts.
    #[error(transparent)]
    File(#[from] FileError),
    /// A tile's data is inconsistent.
    #[error("tile {tile}: {problem}")]
    Tile {
        /// Tile index.
        tile: usize,
        /// What is wrong.
        problem: String,
    },
}

fn tile_err(tile: usize, problem: impl Into<String>) -> TileSetError {
    TileSetError::Tile {
        tile,
        problem: problem.into(),
    }
}

impl TileSet {
    /// A 64-bit hash of everything that decides the point set (colours, subdivision,
    /// sequences, every tile's children, points and subdivision ranking): two sets with one
    /// fingerprint give the same points for the same seed. Stored identities
    /// ([`crate::edits::EditStamp`]) name the set they refer to by it.
    pub fn fingerprint(&self) -> u64 {
        let mut words = vec![
            self.colors as u64,
            self.subdivision as u64,
            self.points_per_tile as u64,
        ];
        let sequences = self
            .horizontal_sequences
            .iter()
            .chain(&self.vertical_sequences);
        words.extend(sequences.flatten().map(|&c| c as u64));
        for t in &self.tiles {
            words.extend(t.children.iter().map(|&c| c as u64));
            words.extend(t.points.iter().map(|p| (p[0] as u64) << 32 | p[1] as u64));
            words.extend(t.subdivision.iter().map(|&e| e as u64));
        }
        crate::rng::hash_words(0xf1e9_e7a1, &words)
    }

    /// The tile set shipped with rwt (`assets/tilesets/default.ron`), parsed and validated
    /// once per call; keep the result around.
    pub fn embedded() -> TileSet {
        // The embedded file is validated by the test suite, so this cannot fail at run time.
        Self::from_ron_bytes(EMBEDDED).expect("embedded tile set is valid")
    }

    /// Parses and validates a tile set.
    pub fn from_ron_bytes(bytes: &[u8]) -> Result<TileSet, TileSetError> {
        let set = Self::from_ron_bytes_unchecked(bytes)?;
        set.validate()?;
        Ok(set)
    }

    /// Reads, parses and validates a tile set file of at most [`MAX_FILE_BYTES`] (see
    /// [`TileSet::read_file_with_limit`] for larger ones).
    pub fn read_file(path: &Path) -> Result<TileSet, TileSetError> {
        Self::read_file_with_limit(path, MAX_FILE_BYTES)
    }

    /// [`TileSet::read_file`] with another size limit in bytes: a larger file (or an endless
    /// device) is refused after reading at most `limit + 1` bytes.
    pub fn read_file_with_limit(path: &Path, limit: u64) -> Result<TileSet, TileSetError> {
        Self::from_ron_bytes(&read_limited(path, limit)?)
    }

    /// Parses without validation (for tools that want to report every problem themselves).
    pub fn from_ron_bytes_unchecked(bytes: &[u8]) -> Result<TileSet, TileSetError> {
        let text = std::str::from_utf8(bytes).map_err(|e| TileSetError::Parse(e.to_string()))?;
        ron::from_str(text).map_err(|e| TileSetError::Parse(e.to_string()))
    }

    /// Serializes to compact RON.
    pub fn to_ron(&self) -> String {
        // Serialization of plain data cannot fail.
        ron::to_string(self).expect("tile set serializes")
    }

    /// Number of points in each tile's subdivision (`n^2 N`).
    pub fn subdivision_len(&self) -> usize {
        let n = self.subdivision as usize;
        n * n * self.points_per_tile as usize
    }

    /// Checks every structural invariant: sizes, colours, subdivision rules that match at the
    /// borders and inside, rank lists that are permutations, and the exact subset property.
    pub fn validate(&self) -> Result<(), TileSetError> {
        self.validate_header()?;
        self.validate_sequences()?;
        for (t, tile) in self.tiles.iter().enumerate() {
            self.validate_tile(t, tile)?;
        }
        let violations = self.rule_violations();
        if violations > 0 {
            return Err(TileSetError::Header(format!(
                "{violations} edge colour mismatches in subdivision rules"
            )));
        }
        if let Some((t, k)) = self.first_subset_violation() {
            return Err(tile_err(
                t,
                format!("base point {k} is not exactly its subdivision point"),
            ));
        }
        self.validate_spacing()
    }

    /// No two points of a tile closer than [`MIN_TILE_RHO`] of their ideal spacing (a
    /// bucket grid per tile: linear in the points, coincident ones included).
    fn validate_spacing(&self) -> Result<(), TileSetError> {
        let spacing = hex_spacing(self.points_per_tile as f64);
        for (t, tile) in self.tiles.iter().enumerate() {
            let points: Vec<DVec2> = tile
                .points
                .iter()
                .map(|p| DVec2::new(fixed_to_unit(p[0]), fixed_to_unit(p[1])))
                .collect();
            if let Some((first, second, d)) = closest_pair(&points)
                && d < MIN_TILE_RHO * spacing
            {
                return Err(TileSetError::Crowded {
                    tile: t,
                    first,
                    second,
                    rho: d / spacing,
                });
            }
        }
        Ok(())
    }

    /// Format version, colours, subdivision factor, points per tile and tile count.
    fn validate_header(&self) -> Result<(), TileSetError> {
        if self.format != FORMAT_VERSION {
            return Err(TileSetError::Format {
                found: self.format,
                expected: FORMAT_VERSION,
            });
        }
        let k = self.colors;
        let n = self.subdivision as usize;
        let big_n = self.points_per_tile as usize;
        let header = |msg: String| Err(TileSetError::Header(msg));
        if !(1..=8).contains(&k) {
            return header(format!("colors {k} not in 1..=8"));
        }
        if !n.is_power_of_two() || !(2..=8).contains(&n) {
            return header(format!("subdivision {n} must be a power of two in 2..=8"));
        }
        if big_n == 0 || big_n > 65_536 {
            return header(format!("points per tile {big_n} not in 1..=65536"));
        }
        if self.tiles.len() != complete_set_size(k) {
            return header(format!(
                "{} tiles, a complete set of {k} colours has {}",
                self.tiles.len(),
                complete_set_size(k)
            ));
        }
        Ok(())
    }

    /// One unique sequence of `n` colours per edge colour and orientation.
    fn validate_sequences(&self) -> Result<(), TileSetError> {
        let (k, n) = (self.colors, self.subdivision as usize);
        for (name, seqs) in [
            ("horizontal", &self.horizontal_sequences),
            ("vertical", &self.vertical_sequences),
        ] {
            if seqs.len() != k as usize
                || seqs
                    .iter()
                    .any(|s| s.len() != n || s.iter().any(|&c| c >= k))
            {
                return Err(TileSetError::Header(format!(
                    "{name} sequences must be {k} sequences of {n} colours below {k}"
                )));
            }
            for i in 0..seqs.len() {
                if seqs[i + 1..].contains(&seqs[i]) {
                    return Err(TileSetError::Header(format!(
                        "{name} sequence of colour {i} is not unique"
                    )));
                }
            }
        }
        Ok(())
    }

    /// One tile's colours, point count, children and subdivision ranking.
    fn validate_tile(&self, t: usize, tile: &Tile) -> Result<(), TileSetError> {
        let (k, n, big_n) = (
            self.colors,
            self.subdivision as usize,
            self.points_per_tile as usize,
        );
        let e = &tile.edges;
        if e.complete_index(k) != t || [e.north, e.east, e.south, e.west].iter().any(|&c| c >= k) {
            return Err(tile_err(t, "edge colours do not match its index"));
        }
        if tile.points.len() != big_n || tile.origins.len() != big_n {
            return Err(tile_err(
                t,
                format!("has {} points, expected {big_n}", tile.points.len()),
            ));
        }
        if tile.children.len() != n * n {
            return Err(tile_err(
                t,
                format!("subdivision rule has {} children", tile.children.len()),
            ));
        }
        if let Some(&c) = tile
            .children
            .iter()
            .find(|&&c| c as usize >= self.tiles.len())
        {
            return Err(tile_err(t, format!("child {c} does not exist")));
        }
        if let Some(p) = tile
            .seams
            .iter()
            .flatten()
            .find(|p| !p.iter().all(|v| (0.0..=1.0).contains(v)))
        {
            return Err(tile_err(
                t,
                format!(
                    "seam point ({}, {}) is outside the tile's [0, 1] square",
                    p[0], p[1]
                ),
            ));
        }
        self.validate_ranking(t, tile)
    }

    /// The subdivision ranking lists each of the `n^2 N` subdivision points exactly once.
    fn validate_ranking(&self, t: usize, tile: &Tile) -> Result<(), TileSetError> {
        let (n, big_n) = (self.subdivision as usize, self.points_per_tile as usize);
        let sub_len = self.subdivision_len();
        if tile.subdivision.len() != sub_len {
            return Err(tile_err(
                t,
                format!(
                    "subdivision lists {} points, expected {sub_len}",
                    tile.subdivision.len()
                ),
            ));
        }
        let mut seen = vec![false; sub_len];
        for &e in &tile.subdivision {
            let (cell, idx) = ((e >> 16) as usize, (e & 0xffff) as usize);
            if cell >= n * n
                || idx >= big_n
                || std::mem::replace(&mut seen[cell * big_n + idx], true)
            {
                return Err(tile_err(t, "subdivision ranking is not a permutation"));
            }
        }
        Ok(())
    }

    /// Colour mismatches inside subdivision rules and between rules and the parent's edges.
    pub fn rule_violations(&self) -> usize {
        let n = self.subdivision as usize;
        let mut bad = 0;
        for tile in &self.tiles {
            let child = |a: usize, b: usize| &self.tiles[tile.children[b * n + a] as usize].edges;
            for b in 0..n {
                for a in 0..n {
                    let c = child(a, b);
                    if a + 1 < n && c.east != child(a + 1, b).west {
                        bad += 1;
                    }
                    if b + 1 < n && c.north != child(a, b + 1).south {
                        bad += 1;
                    }
                }
            }
            for i in 0..n {
                let h = |c: u8| self.horizontal_sequences[c as usize][i];
                let v = |c: u8| self.vertical_sequences[c as usize][i];
                bad += usize::from(child(i, 0).south != h(tile.edges.south));
                bad += usize::from(child(i, n - 1).north != h(tile.edges.north));
                bad += usize::from(child(0, i).west != v(tile.edges.west));
                bad += usize::from(child(n - 1, i).east != v(tile.edges.east));
            }
        }
        bad
    }

    /// Position of subdivision entry `e` of tile `t` in `t`'s fixed-point frame (floored).
    pub fn subdivision_point_fixed(&self, t: usize, e: u32) -> [u32; 2] {
        let n = self.subdivision as u64;
        let (cell, idx) = ((e >> 16) as usize, (e & 0xffff) as usize);
        let (a, b) = ((cell % n as usize) as u64, (cell / n as usize) as u64);
        let child = self.tiles[t].children[cell] as usize;
        let [cx, cy] = self.tiles[child].points[idx];
        [
            (((a << 32) + cx as u64) / n) as u32,
            (((b << 32) + cy as u64) / n) as u32,
        ]
    }

    /// Largest difference, in fixed-point units, between a base point and the subdivision
    /// point it is paired with. Zero for every valid set.
    pub fn max_subset_deviation(&self) -> u64 {
        let mut worst = 0u64;
        for (t, tile) in self.tiles.iter().enumerate() {
            for (k, p) in tile.points.iter().enumerate() {
                let q = self.subdivision_point_fixed(t, tile.subdivision[k]);
                for d in 0..2 {
                    worst = worst.max((p[d] as i64 - q[d] as i64).unsigned_abs());
                }
            }
        }
        worst
    }

    fn first_subset_violation(&self) -> Option<(usize, usize)> {
        for (t, tile) in self.tiles.iter().enumerate() {
            for (k, p) in tile.points.iter().enumerate() {
                if self.subdivision_point_fixed(t, tile.subdivision[k]) != *p {
                    return Some((t, k));
                }
            }
        }
        None
    }
}

/// Converts a fixed-point coordinate to a float in `[0, 1)`.
#[inline]
pub fn fixed_to_unit(v: u32) -> f64 {
    v as f64 / FIXED_ONE
}
