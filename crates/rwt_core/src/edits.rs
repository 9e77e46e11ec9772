//! Edits of single points: a point removed (a tree chopped), or given another class (a tree
//! that became a stump). Points are deterministic and their [`PointId`]s stable, so a
//! world's edits are a sparse set keyed by identity whose size follows the edits, not the
//! world; applying the set where points are generated keeps an edited point edited however
//! often its region is generated again.
//!
//! The file format is small and checked: a header (magic, version, the [`EditStamp`] of the
//! point set the identities refer to: lattice, seed and tile set), the edits in identity order, each as the difference
//! from the one before (a few bytes), and a CRC-32 of everything before it.
//!
//! ```
//! use rwt_core::edits::{Edit, EditSet, EditStamp};
//! use rwt_core::{Constant, Rect, Sampler, TileSet};
//! use glam::DVec2;
//!
//! let sampler = Sampler::new(&TileSet::embedded(), 7);
//! let rect = Rect::new(DVec2::ZERO, DVec2::splat(4.0)).unwrap();
//! let mut points = Vec::new();
//! sampler.query(rect, &Constant(50.0), &mut points).unwrap();
//!
//! let mut edits = EditSet::default();
//! edits.set(points[0].id, Edit::Remove).unwrap();
//! edits.set(points[1].id, Edit::Reclass(2)).unwrap();
//! let stamp = EditStamp::of(&sampler);
//! let bytes = edits.to_bytes(&stamp);
//! assert_eq!(EditSet::from_bytes(&bytes, &stamp).unwrap(), edits);
//!
//! let before = points.len();
//! edits.apply(&mut points, 3);
//! assert_eq!(points.len(), before - 1);
//! assert_eq!(points[0].class, 2);
//! ```

use crate::query::{Lattice, MAX_LEVEL, Point, PointId, Sampler};
use std::collections::BTreeMap;
use thiserror::Error;

/// What an edit does to its point.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Edit {
    /// The point is gone.
    Remove,
    /// The point belongs to this class instead of the one its densities give it.
    Reclass(u16),
}

/// What the identities of an edit set refer to: the tiling seed, how it places the lattice,
/// and the tile set. Edits read back under another stamp would name other points, or put
/// them elsewhere, so they are refused.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct EditStamp {
    /// The tiling seed (a scatter layer's seed).
    pub seed: u64,
    /// How the seed places the lattice (files of format 1 are [`Lattice::Aligned`]).
    pub lattice: Lattice,
    /// [`crate::TileSet::fingerprint`] of the tile set.
    pub tile_set: u64,
}

impl EditStamp {
    /// The stamp of `sampler`'s point set.
    pub fn of(sampler: &Sampler) -> Self {
        Self {
            seed: sampler.seed(),
            lattice: sampler.lattice(),
            tile_set: sampler.tile_set_fingerprint(),
        }
    }
}

/// Most edits an [`EditSet`] holds and an edits file may declare: 4 million, 230 MB in
/// memory (an edit takes about 57 bytes of its ordered map, measured).
pub const MAX_EDITS: usize = 4_000_000;

/// Largest edits file read: 64 MiB, room for [`MAX_EDITS`] edits of 16 bytes each (a record
/// takes 2 to 28 bytes; a file that declares more edits than [`MAX_EDITS`] is refused from
/// its count, before any is decoded).
pub const MAX_EDITS_FILE_BYTES: u64 = 64 << 20;

/// First bytes of an edits file.
const MAGIC: &[u8; 4] = b"RWTE";
/// Version of the format this library writes (it reads this one and
/// [`EDITS_FORMAT_ALIGNED`]).
pub const EDITS_FORMAT: u8 = 2;
/// The format written before seeded lattices: no lattice in the header, its identities
/// name points of [`Lattice::Aligned`].
pub const EDITS_FORMAT_ALIGNED: u8 = 1;
/// Bytes of the header of format 1: magic, version, seed, tile set fingerprint (format 2
/// has a lattice byte after the version).
const HEADER_BYTES: usize = 4 + 1 + 8 + 8;

/// Why bytes are not an edits file for the expected point set.
#[derive(Debug, Error, Clone, PartialEq, Eq)]
pub enum EditsError {
    /// The bytes do not start like an edits file.
    #[error("not an rwt edits file (no RWTE header)")]
    Magic,
    /// Written in another format version.
    #[error("edits format {found} is not supported (this library reads {supported})")]
    Version {
        /// The file's version.
        found: u8,
        /// The version read here.
        supported: u8,
    },
    /// The file ends early or its checksum does not match: cut short or damaged.
    #[error("edits file is damaged or cut short (checksum {found:08x}, expected {expected:08x})")]
    Checksum {
        /// Checksum stored in the file.
        expected: u32,
        /// Checksum of the bytes before it.
        found: u32,
    },
    /// The edits refer to another point set (another seed, lattice or tile set).
    #[error(
        "edits were made for seed {} on the {} lattice and tile set {:016x}, not seed {} on the \
         {} lattice and tile set {:016x}",
        found.seed, found.lattice, found.tile_set, expected.seed, expected.lattice, expected.tile_set
    )]
    Mismatch {
        /// The stamp in the file.
        found: EditStamp,
        /// The stamp of the point set they were read for.
        expected: EditStamp,
    },
    /// A file of format 1 (its points on the aligned lattice) read for a point set on the
    /// seeded lattice: its points lie elsewhere there, so it is refused rather than
    /// shifted.
    #[error(
        "edits file of format {version} names points of the aligned lattice (written before \
         seeded lattices), and this point set lies on the {expected} lattice: read it for \
         `Lattice::Aligned` (a layer file's `lattice: Aligned`) to keep its places"
    )]
    FormatLattice {
        /// The file's format version.
        version: u8,
        /// The lattice it was read for.
        expected: Lattice,
    },
    /// More edits than [`MAX_EDITS`], in a file's count or in a set being edited.
    #[error("{count} edits, over the limit of {limit}")]
    TooMany {
        /// Edits there would be.
        count: u64,
        /// The limit.
        limit: usize,
    },
    /// A point identity the file format cannot hold (a level past the deepest a query
    /// reaches): refused when it is set, so that every set saves to a file that loads.
    #[error("point {level}:{x}:{y}:{index} has level {level}, past the deepest ({MAX_LEVEL})")]
    Unstorable {
        /// Its level.
        level: u8,
        /// Its column.
        x: i64,
        /// Its row.
        y: i64,
        /// Its index.
        index: u16,
    },
    /// The checksum holds but a record is malformed (written by another program).
    #[error("edit record {record} is malformed: {what}")]
    Record {
        /// Index of the record.
        record: usize,
        /// What is wrong with it.
        what: &'static str,
    },
}

/// Edits of one point set, by point identity (kept in identity order, so that the file of
/// one set is always the same bytes).
///
/// With `bevy_reflect`, an opaque value (edited through its methods, which keep it ordered).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
#[cfg_attr(
    feature = "bevy_reflect",
    derive(bevy_reflect::Reflect),
    reflect(opaque, Clone, Debug, PartialEq)
)]
pub struct EditSet(BTreeMap<PointId, Edit>);

impl EditSet {
    /// Sets the edit of `id`; returns the one it replaces. An identity the file format
    /// cannot hold, or a new edit past [`MAX_EDITS`], is refused and changes nothing.
    pub fn set(&mut self, id: PointId, edit: Edit) -> Result<Option<Edit>, EditsError> {
        if id.level as u32 > MAX_LEVEL {
            let PointId { level, x, y, index } = id;
            return Err(EditsError::Unstorable { level, x, y, index });
        }
        if self.0.len() >= MAX_EDITS && !self.0.contains_key(&id) {
            return Err(EditsError::TooMany {
                count: self.0.len() as u64 + 1,
                limit: MAX_EDITS,
            });
        }
        Ok(self.0.insert(id, edit))
    }

    /// Drops the edit of `id` (the point is as its densities make it again); returns it.
    pub fn restore(&mut self, id: &PointId) -> Option<Edit> {
        self.0.remove(id)
    }

    /// The edit of `id`.
    pub fn get(&self, id: &PointId) -> Option<Edit> {
        self.0.get(id).copied()
    }

    /// Number of edits.
    pub fn len(&self) -> usize {
        self.0.len()
    }

    /// Whether there is no edit.
    pub fn is_empty(&self) -> bool {
        self.0.is_empty()
    }

    /// Every edit, in identity order.
    pub fn iter(&self) -> impl Iterator<Item = (&PointId, &Edit)> {
        self.0.iter()
    }

    /// Applies the edits to `points` of a set of `classes` classes: removed ones leave,
    /// reclassed ones change class (a class at or past `classes`, from a layer that has lost
    /// classes since, leaves the point as it is); the others keep their order.
    pub fn apply(&self, points: &mut Vec<Point>, classes: usize) {
        if self.0.is_empty() {
            return;
        }
        // Queries yield a tile's points one after another: the tile's edits are looked up
        // once per run of points, and most tiles have none.
        let mut tile = None;
        let mut edits: Vec<(u16, Edit)> = Vec::new();
        points.retain_mut(|p| {
            let key = (p.id.level, p.id.x, p.id.y);
            if tile != Some(key) {
                tile = Some(key);
                edits.clear();
                let first = PointId { index: 0, ..p.id };
                let last = PointId {
                    index: u16::MAX,
                    ..p.id
                };
                edits.extend(self.0.range(first..=last).map(|(id, e)| (id.index, *e)));
            }
            // In index order (the set's order within a tile).
            match edits
                .binary_search_by_key(&p.id.index, |(index, _)| *index)
                .map(|k| edits[k].1)
            {
                Err(_) => true,
                Ok(Edit::Remove) => false,
                Ok(Edit::Reclass(class)) => {
                    if (class as usize) < classes {
                        p.class = class;
                    }
                    true
                }
            }
        });
    }

    /// The set as an edits file for the point set of `stamp`.
    pub fn to_bytes(&self, stamp: &EditStamp) -> Vec<u8> {
        let mut out = Vec::with_capacity(HEADER_BYTES + 9 + 6 * self.0.len());
        out.extend_from_slice(MAGIC);
        out.push(EDITS_FORMAT);
        out.push(lattice_byte(stamp.lattice));
        out.extend_from_slice(&stamp.seed.to_le_bytes());
        out.extend_from_slice(&stamp.tile_set.to_le_bytes());
        put_varint(&mut out, self.0.len() as u64);
        let mut previous: Option<PointId> = None;
        for (id, edit) in &self.0 {
            encode_record(&mut out, previous, id, *edit);
            previous = Some(*id);
        }
        let crc = crc32fast::hash(&out);
        out.extend_from_slice(&crc.to_le_bytes());
        out
    }

    /// Reads an edits file made for the point set of `expected`. Every byte is checked
    /// before the set is made: damaged, cut short, foreign or mismatched files are errors.
    pub fn from_bytes(bytes: &[u8], expected: &EditStamp) -> Result<Self, EditsError> {
        if bytes.len() < MAGIC.len() || &bytes[..MAGIC.len()] != MAGIC {
            return Err(EditsError::Magic);
        }
        if bytes.len() < HEADER_BYTES + 4 {
            return Err(EditsError::Checksum {
                expected: 0,
                found: crc32fast::hash(bytes),
            });
        }
        let (body, tail) = bytes.split_at(bytes.len() - 4);
        let stored = u32::from_le_bytes(tail.try_into().expect("four bytes"));
        let found = crc32fast::hash(body);
        if stored != found {
            return Err(EditsError::Checksum {
                expected: stored,
                found,
            });
        }
        let (stamp, header) = read_stamp(body)?;
        if stamp.lattice != expected.lattice
            && body[4] == EDITS_FORMAT_ALIGNED
            && (stamp.seed, stamp.tile_set) == (expected.seed, expected.tile_set)
        {
            return Err(EditsError::FormatLattice {
                version: body[4],
                expected: expected.lattice,
            });
        }
        if stamp != *expected {
            return Err(EditsError::Mismatch {
                found: stamp,
                expected: *expected,
            });
        }
        decode_records(&body[header..])
    }
}

/// A lattice as the header's byte.
fn lattice_byte(lattice: Lattice) -> u8 {
    match lattice {
        Lattice::Seeded => 0,
        Lattice::Aligned => 1,
    }
}

/// The stamp of a checksummed file's `body` (at least [`HEADER_BYTES`] long), and where its
/// records start.
fn read_stamp(body: &[u8]) -> Result<(EditStamp, usize), EditsError> {
    let (lattice, at) = match body[4] {
        EDITS_FORMAT_ALIGNED => (Lattice::Aligned, 5),
        EDITS_FORMAT => {
            let lattice = match body[5] {
                0 => Lattice::Seeded,
                1 => Lattice::Aligned,
                _ => {
                    return Err(EditsError::Record {
                        record: 0,
                        what: "unknown lattice in the header",
                    });
                }
            };
            (lattice, 6)
        }
        found => {
            return Err(EditsError::Version {
                found,
                supported: EDITS_FORMAT,
            });
        }
    };
    if body.len() < at + 16 {
        return Err(EditsError::Record {
            record: 0,
            what: "header cut short",
        });
    }
    let word = |at: usize| u64::from_le_bytes(body[at..at + 8].try_into().expect("8 bytes"));
    let stamp = EditStamp {
        seed: word(at),
        lattice,
        tile_set: word(at + 8),
    };
    Ok((stamp, at + 16))
}

/// How a record's identity differs from the one before it (identities are in order, so the
/// first field that differs grew).
#[derive(Clone, Copy)]
enum Step {
    /// Same tile: the index grew by the value that follows.
    Index = 0,
    /// Same level and column: the row grew; the index follows whole.
    Row = 1,
    /// Same level: the column grew; the row and index follow whole.
    Column = 2,
    /// The level grew (or the first record): level, column, row and index follow.
    Level = 3,
}

/// Appends one record: a tag (step, and whether a class follows), the changed fields, the
/// class.
fn encode_record(out: &mut Vec<u8>, previous: Option<PointId>, id: &PointId, edit: Edit) {
    let step = match previous {
        Some(p) if p.level == id.level && p.x == id.x && p.y == id.y => Step::Index,
        Some(p) if p.level == id.level && p.x == id.x => Step::Row,
        Some(p) if p.level == id.level => Step::Column,
        _ => Step::Level,
    };
    let reclass = matches!(edit, Edit::Reclass(_));
    put_varint(out, (step as u64) << 1 | reclass as u64);
    let p = previous.unwrap_or(PointId {
        level: 0,
        x: 0,
        y: 0,
        index: 0,
    });
    match step {
        Step::Index => put_varint(out, (id.index - p.index) as u64),
        Step::Row => {
            put_varint(out, id.y.wrapping_sub(p.y) as u64);
            put_varint(out, id.index as u64);
        }
        Step::Column => {
            put_varint(out, id.x.wrapping_sub(p.x) as u64);
            put_varint(out, zigzag(id.y));
            put_varint(out, id.index as u64);
        }
        Step::Level => {
            put_varint(out, id.level as u64);
            put_varint(out, zigzag(id.x));
            put_varint(out, zigzag(id.y));
            put_varint(out, id.index as u64);
        }
    }
    if let Edit::Reclass(class) = edit {
        put_varint(out, class as u64);
    }
}

/// Reads the count and the records (the checksum already matched).
fn decode_records(bytes: &[u8]) -> Result<EditSet, EditsError> {
    let mut r = Reader { bytes, at: 0 };
    let malformed = |record, what| EditsError::Record { record, what };
    let count = r.varint().ok_or(malformed(0, "no record count"))?;
    if count > MAX_EDITS as u64 {
        return Err(EditsError::TooMany {
            count,
            limit: MAX_EDITS,
        });
    }
    let mut set = BTreeMap::new();
    let mut previous: Option<PointId> = None;
    for record in 0..count as usize {
        let id = r
            .record(previous)
            .ok_or(malformed(record, "cut short or out of range"))?;
        if previous.is_some_and(|p| p >= id.0) {
            return Err(malformed(record, "identities out of order"));
        }
        set.insert(id.0, id.1);
        previous = Some(id.0);
    }
    if r.at != bytes.len() {
        return Err(malformed(count as usize, "bytes after the last record"));
    }
    Ok(EditSet(set))
}

/// A cursor over a file's records.
struct Reader<'a> {
    bytes: &'a [u8],
    at: usize,
}

impl Reader<'_> {
    /// An unsigned LEB128 number of at most 10 bytes.
    fn varint(&mut self) -> Option<u64> {
        let mut v = 0u64;
        for shift in (0..70).step_by(7) {
            let b = *self.bytes.get(self.at)?;
            self.at += 1;
            v |= ((b & 0x7f) as u64).checked_shl(shift)?;
            if b & 0x80 == 0 {
                return Some(v);
            }
        }
        None
    }

    fn small<T: TryFrom<u64>>(&mut self) -> Option<T> {
        T::try_from(self.varint()?).ok()
    }

    /// One record after `previous`.
    fn record(&mut self, previous: Option<PointId>) -> Option<(PointId, Edit)> {
        let tag = self.varint()?;
        let p = previous.unwrap_or(PointId {
            level: 0,
            x: 0,
            y: 0,
            index: 0,
        });
        let id = match (tag >> 1, previous) {
            (0, Some(_)) => PointId {
                index: p.index.checked_add(self.small()?)?,
                ..p
            },
            (1, Some(_)) => PointId {
                y: p.y.wrapping_add(self.varint()? as i64),
                index: self.small()?,
                ..p
            },
            (2, Some(_)) => PointId {
                x: p.x.wrapping_add(self.varint()? as i64),
                y: unzigzag(self.varint()?),
                index: self.small()?,
                ..p
            },
            (3, _) => PointId {
                level: self.small()?,
                x: unzigzag(self.varint()?),
                y: unzigzag(self.varint()?),
                index: self.small()?,
            },
            _ => return None,
        };
        if id.level as u32 > MAX_LEVEL {
            return None;
        }
        let edit = match tag & 1 {
            0 => Edit::Remove,
            _ => Edit::Reclass(self.small()?),
        };
        Some((id, edit))
    }
}

fn put_varint(out: &mut Vec<u8>, mut v: u64) {
    while v >= 0x80 {
        out.push((v as u8) | 0x80);
        v >>= 7;
    }
    out.push(v as u8);
}

fn zigzag(v: i64) -> u64 {
    ((v << 1) ^ (v >> 63)) as u64
}

fn unzigzag(v: u64) -> i64 {
    ((v >> 1) as i64) ^ -((v & 1) as i64)
}

#[cfg(test)]
mod tests;
