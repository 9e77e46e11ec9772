use super::*;
use crate::density::Constant;
use crate::query::Rect;
use crate::tileset::TileSet;
use glam::DVec2;

/// The shipped set, parsed once for every test here.
fn embedded() -> &'static TileSet {
    static SET: std::sync::OnceLock<TileSet> = std::sync::OnceLock::new();
    SET.get_or_init(TileSet::embedded)
}

fn stamp() -> EditStamp {
    EditStamp {
        seed: 11,
        lattice: Lattice::Seeded,
        tile_set: embedded().fingerprint(),
    }
}

/// Every point of a square of `side` tiles, at `density` per unit area.
fn points(side: f64, density: f64) -> (Sampler, Vec<Point>) {
    let sampler = Sampler::new(embedded(), 11).with_tile_size(4.0);
    let rect = Rect::new(DVec2::splat(-2.0 * side), DVec2::splat(2.0 * side)).unwrap();
    let mut out = Vec::new();
    sampler.query(rect, &Constant(density), &mut out).unwrap();
    (sampler, out)
}

/// Every other point removed, every third reclassed, identities from several levels and
/// both signs of coordinates.
fn sample_edits(points: &[Point]) -> EditSet {
    let mut edits = EditSet::default();
    for (i, p) in points.iter().enumerate() {
        match i % 6 {
            0 | 2 | 4 => edits.set(p.id, Edit::Remove).unwrap(),
            3 => edits.set(p.id, Edit::Reclass((i % 300) as u16)).unwrap(),
            _ => None,
        };
    }
    edits
}

#[test]
fn a_set_round_trips_bit_for_bit() {
    let (sampler, points) = points(3.0, 300.0);
    assert!(points.iter().any(|p| p.id.level > 0));
    assert!(points.iter().any(|p| p.id.x < 0) && points.iter().any(|p| p.id.y > 0));
    let edits = sample_edits(&points);
    let stamp = EditStamp::of(&sampler);
    let bytes = edits.to_bytes(&stamp);
    let back = EditSet::from_bytes(&bytes, &stamp).unwrap();
    assert_eq!(back, edits);
    assert_eq!(back.to_bytes(&stamp), bytes);
    // The extremes of every field.
    let mut extreme = EditSet::default();
    for (level, x, y, index) in [
        (0, i64::MIN, i64::MIN, 0),
        (0, i64::MIN, i64::MAX, u16::MAX),
        (0, i64::MAX, 0, 1),
        (MAX_LEVEL as u8, -1, 1, 7),
    ] {
        let id = PointId { level, x, y, index };
        extreme.set(id, Edit::Reclass(u16::MAX)).unwrap();
    }
    let bytes = extreme.to_bytes(&stamp);
    assert_eq!(EditSet::from_bytes(&bytes, &stamp).unwrap(), extreme);
}

#[test]
fn edits_apply_to_exactly_their_points() {
    let (_, points) = points(3.0, 30.0);
    let edits = sample_edits(&points);
    for classes in [300, 100] {
        let mut edited = points.clone();
        edits.apply(&mut edited, classes);
        let mut expected = Vec::new();
        for p in &points {
            match edits.get(&p.id) {
                None => expected.push(*p),
                Some(Edit::Remove) => {}
                Some(Edit::Reclass(c)) if (c as usize) < classes => {
                    expected.push(Point { class: c, ..*p })
                }
                Some(Edit::Reclass(_)) => expected.push(*p),
            }
        }
        assert_eq!(edited, expected);
    }
    let mut restored = edits.clone();
    for p in &points {
        restored.restore(&p.id);
    }
    assert!(restored.is_empty());
}

#[test]
fn a_file_takes_a_few_bytes_per_edit() {
    let (_, points) = points(12.0, 40.0);
    let mut edits = EditSet::default();
    for p in points.iter().step_by(3) {
        edits.set(p.id, Edit::Remove).unwrap();
    }
    let bytes = edits.to_bytes(&stamp()).len();
    let per_edit = bytes as f64 / edits.len() as f64;
    assert!(edits.len() > 10_000, "{}", edits.len());
    println!("{} edits, {per_edit:.2} bytes per edit", edits.len());
    assert!(per_edit < 8.0, "{per_edit} bytes per edit");
}

#[test]
fn damaged_cut_short_and_foreign_files_are_refused() {
    let (_, points) = points(3.0, 30.0);
    let bytes = sample_edits(&points).to_bytes(&stamp());
    for cut in [0, 3, 10, HEADER_BYTES, bytes.len() / 2, bytes.len() - 1] {
        let e = EditSet::from_bytes(&bytes[..cut], &stamp()).unwrap_err();
        assert!(
            matches!(e, EditsError::Magic | EditsError::Checksum { .. }),
            "{cut}: {e}"
        );
    }
    for at in [4, 7, HEADER_BYTES + 1, bytes.len() - 2] {
        let mut flipped = bytes.clone();
        flipped[at] ^= 0x10;
        let e = EditSet::from_bytes(&flipped, &stamp()).unwrap_err();
        assert!(matches!(e, EditsError::Checksum { .. }), "{at}: {e}");
    }
    let other = EditStamp {
        seed: 12,
        ..stamp()
    };
    let e = EditSet::from_bytes(&bytes, &other).unwrap_err();
    assert_eq!(
        e,
        EditsError::Mismatch {
            found: stamp(),
            expected: other
        }
    );
    assert!(e.to_string().contains("seed 11"), "{e}");
    assert_eq!(
        EditSet::from_bytes(b"PNG\x89 not edits", &stamp()),
        Err(EditsError::Magic)
    );
}

/// A body with a valid checksum: what another program could write.
fn sealed(body: &[u8]) -> Vec<u8> {
    let mut out = body.to_vec();
    out.extend_from_slice(&crc32fast::hash(body).to_le_bytes());
    out
}

#[test]
fn malformed_records_under_a_good_checksum_are_refused() {
    let stamp = stamp();
    let empty = EditSet::default().to_bytes(&stamp);
    // Format 2's header: a lattice byte after the version.
    let header = &empty[..HEADER_BYTES + 1];
    let cases: [(&[u8], &str); 5] = [
        (
            &[2, 6, 0, 0, 0, 0, 6, 0, 0, 0, 0],
            "identities out of order",
        ),
        (&[1, 6, 200, 0, 0, 0], "cut short or out of range"),
        (&[2, 6, 0, 0, 0, 0], "cut short or out of range"),
        (&[0, 6, 0, 0, 0, 0], "bytes after the last record"),
        (&[1, 2, 5], "cut short or out of range"),
    ];
    for (records, what) in cases {
        let file = sealed(&[header, records].concat());
        match EditSet::from_bytes(&file, &stamp) {
            Err(EditsError::Record { what: w, .. }) => assert_eq!(w, what, "{records:?}"),
            other => panic!("{records:?}: {other:?}"),
        }
    }
    let mut version = empty.clone();
    version[4] = 9;
    assert_eq!(
        EditSet::from_bytes(&sealed(&version[..version.len() - 4]), &stamp),
        Err(EditsError::Version {
            found: 9,
            supported: EDITS_FORMAT
        })
    );
}

#[test]
fn fingerprints_tell_tile_sets_apart() {
    let set = embedded();
    let mut other = set.clone();
    other.tiles[3].points.swap(0, 1);
    assert_ne!(set.fingerprint(), other.fingerprint());
    assert_eq!(set.fingerprint(), set.clone().fingerprint());
}

#[test]
fn identities_a_file_cannot_hold_and_too_many_edits_are_refused() {
    let stamp = EditStamp {
        seed: 1,
        lattice: Lattice::Seeded,
        tile_set: 2,
    };
    // Level 30 was accepted, saved, and the whole file then refused to load.
    let mut edits = EditSet::default();
    let deep = PointId {
        level: MAX_LEVEL as u8 + 1,
        x: 3,
        y: -4,
        index: 5,
    };
    assert_eq!(
        edits.set(deep, Edit::Remove),
        Err(EditsError::Unstorable {
            level: MAX_LEVEL as u8 + 1,
            x: 3,
            y: -4,
            index: 5
        })
    );
    assert!(edits.is_empty());
    // A file within the byte limit declaring 33.5 million edits (2 bytes each: index
    // steps) took 1.9 GB; its count is refused before any record is decoded.
    let declared = 33_554_432u64;
    let mut bytes = EditSet::default().to_bytes(&stamp);
    bytes.truncate(bytes.len() - 5);
    let mut count = declared;
    while count >= 0x80 {
        bytes.push(count as u8 | 0x80);
        count >>= 7;
    }
    bytes.push(count as u8);
    bytes.extend_from_slice(&[3 << 1, 0, 0, 0, 0]);
    bytes.extend(std::iter::repeat_n([0u8, 1], 1000).flatten());
    let crc = crc32fast::hash(&bytes);
    bytes.extend_from_slice(&crc.to_le_bytes());
    assert_eq!(
        EditSet::from_bytes(&bytes, &stamp),
        Err(EditsError::TooMany {
            count: declared,
            limit: MAX_EDITS
        })
    );
}

/// `bytes` (of format 2) as format 1 wrote them: no lattice byte.
fn as_format_1(bytes: &[u8]) -> Vec<u8> {
    let body = &bytes[..bytes.len() - 4];
    assert_eq!(body[4], EDITS_FORMAT);
    let mut old = body[..5].to_vec();
    old[4] = EDITS_FORMAT_ALIGNED;
    old.extend_from_slice(&body[6..]);
    sealed(&old)
}

#[test]
fn files_of_format_1_keep_their_aligned_places_or_are_refused() {
    let aligned = Sampler::new(embedded(), 11)
        .with_tile_size(4.0)
        .with_lattice(Lattice::Aligned);
    let rect = Rect::new(DVec2::splat(-6.0), DVec2::splat(6.0)).unwrap();
    let mut points = Vec::new();
    aligned.query(rect, &Constant(30.0), &mut points).unwrap();
    let edits = sample_edits(&points);
    let stamp = EditStamp::of(&aligned);
    assert_eq!(stamp.lattice, Lattice::Aligned);
    let old = as_format_1(&edits.to_bytes(&stamp));
    // Read for the aligned lattice: the same edits, naming the same points.
    assert_eq!(EditSet::from_bytes(&old, &stamp), Ok(edits.clone()));
    // Read for the seeded lattice: refused, naming the version, never shifted.
    let seeded = EditStamp {
        lattice: Lattice::Seeded,
        ..stamp
    };
    let e = EditSet::from_bytes(&old, &seeded).unwrap_err();
    assert_eq!(
        e,
        EditsError::FormatLattice {
            version: 1,
            expected: Lattice::Seeded
        }
    );
    assert!(e.to_string().contains("format 1"), "{e}");
    // A file of format 2 names its lattice: read for another, a mismatch.
    let e = EditSet::from_bytes(&edits.to_bytes(&stamp), &seeded).unwrap_err();
    assert!(matches!(e, EditsError::Mismatch { .. }), "{e}");
    assert!(e.to_string().contains("aligned lattice"), "{e}");
}
