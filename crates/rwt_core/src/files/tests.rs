//! Atomic writes, transactions, temporaries and limited reads against failures.

use super::*;

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("rwt-files-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn names(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

#[test]
fn a_failing_writer_leaves_the_previous_file_and_no_temporary() {
    let dir = scratch("fail");
    let path = dir.join("out.txt");
    write_atomic(&path, b"previous contents\n").unwrap();
    let err = write_atomic_with(&path, |w| {
        w.write_all(&[b'x'; 200_000])?;
        Err(io::Error::new(io::ErrorKind::StorageFull, "no space left"))
    })
    .unwrap_err();
    assert!(
        matches!(&err, FileError::Io { kind: io::ErrorKind::StorageFull, action: FileAction::Write, path: p, .. } if p == &path),
        "{err:?}"
    );
    assert_eq!(std::fs::read(&path).unwrap(), b"previous contents\n");
    assert_eq!(names(&dir), ["out.txt"]);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[cfg(unix)]
#[test]
fn a_link_is_followed_and_stays_a_link() {
    let dir = scratch("link");
    let real = dir.join("real.ron");
    std::fs::write(&real, "old").unwrap();
    let link = dir.join("link.ron");
    std::os::unix::fs::symlink("real.ron", &link).unwrap();
    write_atomic(&link, b"new").unwrap();
    assert!(
        std::fs::symlink_metadata(&link)
            .unwrap()
            .file_type()
            .is_symlink()
    );
    assert_eq!(std::fs::read(&real).unwrap(), b"new");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[cfg(unix)]
#[test]
fn devices_are_written_in_place_not_replaced() {
    write_atomic(Path::new("/dev/null"), b"gone").unwrap();
    let m = std::fs::metadata("/dev/null").unwrap();
    assert!(!m.is_file(), "/dev/null must stay a device");
    let leftovers = std::fs::read_dir("/dev")
        .unwrap()
        .filter(|e| {
            let name = e.as_ref().unwrap().file_name();
            name.to_string_lossy().ends_with(TEMP_SUFFIX)
        })
        .count();
    assert_eq!(leftovers, 0);
}

#[cfg(unix)]
#[test]
fn link_chains_are_followed_to_the_end_and_loops_refused() {
    use std::os::unix::fs::symlink;
    let dir = scratch("chain");
    std::fs::create_dir(dir.join("sub")).unwrap();
    // out -> sub/hop -> ../final.txt (missing: written there).
    symlink("sub/hop", dir.join("out")).unwrap();
    symlink("../final.txt", dir.join("sub/hop")).unwrap();
    write_atomic(&dir.join("out"), b"one").unwrap();
    assert_eq!(std::fs::read(dir.join("final.txt")).unwrap(), b"one");
    write_atomic(&dir.join("out"), b"two").unwrap();
    assert_eq!(std::fs::read(dir.join("final.txt")).unwrap(), b"two");
    assert!(
        std::fs::symlink_metadata(dir.join("sub/hop"))
            .unwrap()
            .is_symlink()
    );
    assert_eq!(names(&dir), ["final.txt", "out", "sub"]);
    symlink("b", dir.join("a")).unwrap();
    symlink("a", dir.join("b")).unwrap();
    let err = write_atomic(&dir.join("a"), b"x").unwrap_err();
    assert!(err.to_string().contains("loop of links"), "{err}");
    assert!(
        std::fs::symlink_metadata(dir.join("a"))
            .unwrap()
            .is_symlink()
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn reads_are_limited_before_memory_is_spent() {
    let dir = scratch("limit");
    let path = dir.join("big");
    std::fs::write(&path, vec![7u8; 1000]).unwrap();
    assert_eq!(read_limited(&path, 1000).unwrap().len(), 1000);
    assert_eq!(
        read_limited(&path, 999),
        Err(FileError::TooLarge {
            path: path.clone(),
            limit: 999
        })
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_temporary_name_fits_wherever_its_target_name_fits() {
    let dir = scratch("long");
    for len in [2, 200, 214, 215, 255] {
        let name = "n".repeat(len - 2) + "é";
        assert_eq!(name.len(), len);
        let path = dir.join(&name);
        write_atomic(&path, b"bytes").unwrap_or_else(|e| panic!("{len}: {e}"));
        assert_eq!(std::fs::read(&path).unwrap(), b"bytes");
        assert!(temp_beside(&path).file_name().unwrap().len() <= NAME_MAX);
    }
    // Two long names that share their first 200 bytes get their own temporaries.
    let (a, b) = ("x".repeat(240) + "a", "x".repeat(240) + "b");
    assert_ne!(temp_prefix(&dir.join(a)), temp_prefix(&dir.join(b)));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn abandoned_temporaries_are_removed_by_the_next_write_and_live_ones_kept() {
    let dir = scratch("stale");
    let path = dir.join("points.txt");
    // What a `kill -9` leaves: a temporary file no process holds.
    let mut dead = temp_prefix(&path);
    dead.push(format!("999999-0{TEMP_SUFFIX}"));
    std::fs::write(dir.join(&dead), vec![1u8; 4096]).unwrap();
    // Another target's temporary file stays.
    let mut other = temp_prefix(&dir.join("other.txt"));
    other.push(format!("999999-0{TEMP_SUFFIX}"));
    std::fs::write(dir.join(&other), b"x").unwrap();
    // A writer still at work on the same target: its file is locked.
    let mut busy = AtomicFile::create(&path).unwrap();
    busy.write_all(b"busy").unwrap();
    write_atomic(&path, b"done").unwrap();
    let names = names(&dir);
    assert!(
        !names.contains(&dead.to_string_lossy().into_owned()),
        "{names:?}"
    );
    assert!(
        names.contains(&other.to_string_lossy().into_owned()),
        "{names:?}"
    );
    assert_eq!(names.len(), 3, "{names:?}");
    busy.commit().unwrap();
    assert_eq!(std::fs::read(&path).unwrap(), b"busy");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[cfg(unix)]
#[test]
fn readers_refuse_fifos_devices_and_folders() {
    let dir = scratch("fifo");
    let fifo = dir.join("pipe");
    assert!(
        std::process::Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .unwrap()
            .success()
    );
    for (path, what) in [
        (fifo.as_path(), "a FIFO"),
        (Path::new("/dev/zero"), "a device"),
        (dir.as_path(), "a folder"),
    ] {
        assert_eq!(
            read_limited(path, 1 << 20),
            Err(FileError::NotAFile {
                path: path.to_path_buf(),
                what
            })
        );
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A folder holding a first save of `a.png` ("a1") and `index.ron` ("i1").
fn saved_once(name: &str) -> PathBuf {
    let dir = scratch(name);
    let mut save = SaveTransaction::begin(&dir).unwrap();
    save.write("a.png", b"a1").unwrap();
    save.write("index.ron", b"i1").unwrap();
    save.commit().unwrap();
    dir
}

#[test]
fn a_transaction_that_fails_part_way_changes_nothing() {
    let dir = saved_once("txn");
    let mut save = SaveTransaction::begin(&dir).unwrap();
    save.write("a.png", b"a2").unwrap();
    let err = save.write_with("index.ron", |w| {
        w.write_all(b"i2 part")?;
        Err(io::Error::new(io::ErrorKind::StorageFull, "full"))
    });
    assert!(err.is_err());
    assert!(save.write("a.png", b"again").is_err(), "twice in one save");
    drop(save);
    assert_eq!(std::fs::read(dir.join("a.png")).unwrap(), b"a1");
    assert_eq!(std::fs::read(dir.join("index.ron")).unwrap(), b"i1");
    assert_eq!(names(&dir), ["a.png", "index.ron"]);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[cfg(unix)]
#[test]
fn a_save_replaces_a_link_in_its_folder() {
    let dir = saved_once("save-link");
    let elsewhere = scratch("save-link-target");
    std::fs::write(elsewhere.join("kept.png"), b"theirs").unwrap();
    std::fs::remove_file(dir.join("a.png")).unwrap();
    std::os::unix::fs::symlink(elsewhere.join("kept.png"), dir.join("a.png")).unwrap();
    let mut save = SaveTransaction::begin(&dir).unwrap();
    save.write("a.png", b"a2").unwrap();
    save.commit().unwrap();
    assert!(
        std::fs::symlink_metadata(dir.join("a.png"))
            .unwrap()
            .is_file()
    );
    assert_eq!(std::fs::read(dir.join("a.png")).unwrap(), b"a2");
    assert_eq!(
        std::fs::read(elsewhere.join("kept.png")).unwrap(),
        b"theirs"
    );
    assert_eq!(names(&elsewhere), ["kept.png"]);
    std::fs::remove_dir_all(&dir).unwrap();
    std::fs::remove_dir_all(&elsewhere).unwrap();
}

#[test]
fn a_save_interrupted_after_its_journal_is_finished_by_recover() {
    let dir = saved_once("journal");
    // A crash after the journal and the first rename: stage, journal, rename one by
    // hand, then forget the transaction.
    let mut save = SaveTransaction::begin(&dir).unwrap();
    save.write("a.png", b"a2").unwrap();
    save.write("index.ron", b"i2").unwrap();
    let staged = std::mem::take(&mut save.staged);
    std::fs::write(dir.join(JOURNAL_FILE), ron::to_string(&staged).unwrap()).unwrap();
    std::fs::rename(dir.join(&staged[0].temp), dir.join("a.png")).unwrap();
    // A temporary file of a save that crashed before its journal.
    std::fs::write(dir.join(format!(".x.png.1-1{TEMP_SUFFIX}")), b"junk").unwrap();
    assert_eq!(recover(&dir), Ok(true));
    assert_eq!(std::fs::read(dir.join("a.png")).unwrap(), b"a2");
    assert_eq!(std::fs::read(dir.join("index.ron")).unwrap(), b"i2");
    assert_eq!(names(&dir), ["a.png", "index.ron"]);
    assert_eq!(recover(&dir), Ok(false));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn without_a_file_system_files_are_a_typed_error_naming_path_and_action() {
    const { assert!(HAS_FILE_SYSTEM, "tests run where files exist") };
    let path = Path::new("painted/flowers.png");
    assert!(require_files(true, path, FileAction::Create).is_ok());
    let err = require_files(false, path, FileAction::Create).unwrap_err();
    assert!(
        matches!(&err, FileError::NoFileSystem { path: p, action: FileAction::Create } if p == path),
        "{err:?}"
    );
    assert_eq!(
        err.to_string(),
        "painted/flowers.png: cannot create on the web: a browser's page has no file system"
    );
}
