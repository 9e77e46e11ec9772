//! `files::remove_temporaries`, alone in its process: it removes every temporary file the
//! process is writing, which would break other tests writing at the same time.

use rwt_core::files::{AtomicFile, remove_temporaries, write_atomic};
use std::io::Write;

#[test]
fn temporaries_are_removed_when_the_program_is_told_to_end() {
    let dir = std::env::temp_dir().join(format!("rwt-temporaries-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let path = dir.join("out.txt");
    write_atomic(&path, b"previous").unwrap();
    let mut file = AtomicFile::create(&path).unwrap();
    file.write_all(&[7u8; 100_000]).unwrap();
    let count = || std::fs::read_dir(&dir).unwrap().count();
    assert_eq!(count(), 2);
    remove_temporaries();
    assert_eq!(count(), 1);
    assert!(file.commit().is_err());
    assert_eq!(std::fs::read(&path).unwrap(), b"previous");
    std::fs::remove_dir_all(&dir).unwrap();
}
