//! Files a user keeps: written atomically, alone or several together, and read within a
//! size limit.
//!
//! A write never truncates the file it replaces: [`AtomicFile`] writes a temporary file in
//! the same folder, flushes and syncs it, and renames it over the target, so on any error (a
//! full disk, a failing writer, a crash) the target keeps its previous bytes and the
//! temporary file is removed. A link is followed: the file it points to is replaced and the
//! link stays a link.
//!
//! [`SaveTransaction`] commits several files of one folder all-or-nothing: each is staged
//! as a temporary file; only when every one is written and synced does a journal naming
//! them make the save durable, and the renames follow (a link in the folder is replaced by
//! the file, not followed). A failure while staging leaves every
//! previous file as it was; a crash after the journal is finished by [`recover`] (which
//! [`SaveTransaction::begin`] calls), so a reader never sees half of a save. One writer per
//! folder at a time.
//!
//! ```
//! use std::io::Write;
//! let dir = std::env::temp_dir().join(format!("rwt-files-doc-{}", std::process::id()));
//! std::fs::create_dir_all(&dir).unwrap();
//! let path = dir.join("points.txt");
//! rwt_core::files::write_atomic(&path, b"1 2\n").unwrap();
//! // A writer that fails part-way leaves the previous file as it was.
//! let failed = rwt_core::files::write_atomic_with(&path, |w| {
//!     w.write_all(b"3 4\n")?;
//!     Err(std::io::Error::other("disk full"))
//! });
//! assert!(failed.is_err());
//! assert_eq!(std::fs::read(&path).unwrap(), b"1 2\n");
//! # std::fs::remove_dir_all(&dir).unwrap();
//! ```

use serde::{Deserialize, Serialize};
use std::fs::File;
use std::io::{self, BufWriter, Read, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

/// Ends the names of temporary files (`.NAME.PID-N.rwt-tmp`).
pub const TEMP_SUFFIX: &str = ".rwt-tmp";

/// The journal of a [`SaveTransaction`] whose renames are under way.
pub const JOURNAL_FILE: &str = ".rwt-commit.ron";

/// What was being done to a file when it failed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FileAction {
    /// Creating a folder or a temporary file.
    Create,
    /// Writing, flushing or syncing.
    Write,
    /// Renaming the temporary file over the target.
    Rename,
    /// Opening or reading.
    Read,
}

impl std::fmt::Display for FileAction {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            FileAction::Create => "create",
            FileAction::Write => "write",
            FileAction::Rename => "replace",
            FileAction::Read => "read",
        })
    }
}

/// Why a file could not be written or read.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum FileError {
    /// The operating system refused.
    #[error("{}: cannot {action}: {reason}", path.display())]
    Io {
        /// The file (the target, not its temporary file).
        path: PathBuf,
        /// What was being done.
        action: FileAction,
        /// The kind of error.
        kind: io::ErrorKind,
        /// The operating system's words.
        reason: String,
    },
    /// The file holds more bytes than the reader accepts.
    #[error("{}: more than {limit} bytes, over the limit for this kind of file", path.display())]
    TooLarge {
        /// The file.
        path: PathBuf,
        /// The limit in bytes.
        limit: u64,
    },
    /// The path names something that is not a regular file (a folder, a FIFO, a device, a
    /// socket): readers refuse it rather than block on it or read it without end.
    #[error("{}: is {what}, not a regular file", path.display())]
    NotAFile {
        /// The path.
        path: PathBuf,
        /// What it is instead: "a folder", "a FIFO", "a device", "a socket".
        what: &'static str,
    },
    /// The platform gives no file system (`wasm32-unknown-unknown`: a page in a browser):
    /// nothing is read or written, and nothing panics.
    #[error("{}: cannot {action} on the web: a browser's page has no file system", path.display())]
    NoFileSystem {
        /// The file or folder.
        path: PathBuf,
        /// What was asked.
        action: FileAction,
    },
    /// A transaction was asked to write one file twice.
    #[error("{}: written twice in one save", path.display())]
    Duplicate {
        /// The file.
        path: PathBuf,
    },
}

/// Whether this platform has files to read and write: not a browser's page.
pub const HAS_FILE_SYSTEM: bool = !cfg!(all(target_family = "wasm", target_os = "unknown"));

/// [`FileError::NoFileSystem`] for `path` where the platform has no files.
fn file_system(path: &Path, action: FileAction) -> Result<(), FileError> {
    require_files(HAS_FILE_SYSTEM, path, action)
}

/// [`FileError::NoFileSystem`] for `path` unless `has` files.
fn require_files(has: bool, path: &Path, action: FileAction) -> Result<(), FileError> {
    if has {
        return Ok(());
    }
    Err(FileError::NoFileSystem {
        path: path.to_path_buf(),
        action,
    })
}

impl FileError {
    /// An I/O error on `path` while doing `action`.
    pub fn io(path: &Path, action: FileAction, error: &io::Error) -> Self {
        FileError::Io {
            path: path.to_path_buf(),
            action,
            kind: error.kind(),
            reason: error.to_string(),
        }
    }
}

/// The file a write to `path` replaces: the target of a link, followed link by link to the
/// end (a dangling chain writes where its last link points), else `path` itself. A loop
/// of links is an error, as the system's own open reports it.
fn resolve_target(path: &Path) -> Result<PathBuf, FileError> {
    /// Links followed before a chain counts as a loop (Linux's limit).
    const MAX_LINKS: usize = 40;
    let mut at = path.to_path_buf();
    for _ in 0..MAX_LINKS {
        match std::fs::symlink_metadata(&at) {
            Ok(m) if m.file_type().is_symlink() => {
                let to = std::fs::read_link(&at)
                    .map_err(|e| FileError::io(path, FileAction::Create, &e))?;
                at = at.parent().unwrap_or(Path::new("")).join(to);
            }
            _ => return Ok(at),
        }
    }
    Err(FileError::Io {
        path: path.to_path_buf(),
        action: FileAction::Create,
        kind: io::ErrorKind::Other,
        reason: format!("more than {MAX_LINKS} links in a row (a loop of links?)"),
    })
}

/// Longest file name the systems rwt runs on accept, in bytes.
const NAME_MAX: usize = 255;

/// The start of every temporary file name beside `target`: `.NAME.`, where a name too long
/// to take the rest of a temporary name is cut (at a character) and ends in a hash of
/// itself, so that a temporary name fits wherever the target's name fits.
fn temp_prefix(target: &Path) -> std::ffi::OsString {
    let name = target.file_name().unwrap_or_default();
    // `.`, `.`, a process id and counter (at most 10 + 1 + 20) and the suffix.
    let room = NAME_MAX - 2 - 31 - TEMP_SUFFIX.len();
    let mut prefix = std::ffi::OsString::from(".");
    if name.len() <= room {
        prefix.push(name);
    } else {
        let text = name.to_string_lossy();
        let mut cut = room - 17;
        while !text.is_char_boundary(cut.min(text.len())) {
            cut -= 1;
        }
        let hash = crate::rng::fnv1a(name.as_encoded_bytes());
        prefix.push(format!("{}~{hash:016x}", &text[..cut.min(text.len())]));
    }
    prefix.push(".");
    prefix
}

/// A temporary file name beside `target`, unique within this process.
fn temp_beside(target: &Path) -> PathBuf {
    static NEXT: AtomicU64 = AtomicU64::new(0);
    let n = NEXT.fetch_add(1, Ordering::Relaxed);
    let mut name = temp_prefix(target);
    name.push(format!("{}-{n}{TEMP_SUFFIX}", std::process::id()));
    target.with_file_name(name)
}

/// Removes the temporary files that writers to `target` which died without cleaning up
/// (`kill -9`, a power cut) left beside it. A live writer holds a lock on its temporary
/// file, so only abandoned ones are removed, whichever process made them.
fn remove_stale_temporaries(target: &Path) {
    let prefix = temp_prefix(target);
    let dir = match target.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for entry in entries.flatten() {
        let name = entry.file_name();
        let bytes = name.as_encoded_bytes();
        if !(bytes.starts_with(prefix.as_encoded_bytes())
            && bytes.ends_with(TEMP_SUFFIX.as_bytes()))
        {
            continue;
        }
        let abandoned = File::options()
            .write(true)
            .open(entry.path())
            .is_ok_and(|f| f.try_lock().is_ok());
        if abandoned {
            let _ = std::fs::remove_file(entry.path());
        }
    }
}

/// Temporary files being written by this process, for [`remove_temporaries`].
static LIVE: std::sync::Mutex<Vec<PathBuf>> = std::sync::Mutex::new(Vec::new());

fn live() -> std::sync::MutexGuard<'static, Vec<PathBuf>> {
    LIVE.lock().unwrap_or_else(|poisoned| poisoned.into_inner())
}

/// Removes every temporary file this process is writing: what a program calls when a
/// signal (Ctrl-C, `SIGTERM`, `SIGHUP`) is about to end it, so that no half-written file
/// outlives it. The targets keep their previous bytes. The `rwt` command line does this on
/// those signals; a `kill -9` cannot be caught, and the next write to the same target
/// removes what it left.
pub fn remove_temporaries() {
    for temp in live().drain(..) {
        let _ = std::fs::remove_file(temp);
    }
}

/// Forgets a temporary file that is renamed or removed.
fn forget(temp: &Path) {
    live().retain(|t| t != temp);
}

/// Syncs a folder, so that renames in it survive a crash (best effort: not every system
/// opens folders as files).
fn sync_dir(dir: &Path) {
    let dir = if dir.as_os_str().is_empty() {
        Path::new(".")
    } else {
        dir
    };
    if let Ok(d) = File::open(dir) {
        let _ = d.sync_all();
    }
}

/// A file being written in place of another: bytes go to a temporary file beside the
/// target, which [`AtomicFile::commit`] renames over it. Dropped without a commit (an error
/// on the way), the temporary file is removed and the target is untouched. A target that is
/// not a regular file (`/dev/null`, a pipe, a terminal) is written in place: it has no
/// previous bytes to keep, and renaming over it would replace the device.
pub struct AtomicFile {
    target: PathBuf,
    /// What the error messages name: the path the caller gave.
    shown: PathBuf,
    /// The temporary file; empty when writing in place or once renamed.
    temp: PathBuf,
    file: Option<BufWriter<File>>,
}

impl AtomicFile {
    /// Starts replacing `path` (creating its folder when missing).
    pub fn create(path: &Path) -> Result<Self, FileError> {
        file_system(path, FileAction::Create)?;
        let target = resolve_target(path)?;
        if std::fs::metadata(&target).is_ok_and(|m| !m.is_file() && !m.is_dir()) {
            let file = File::options()
                .write(true)
                .open(&target)
                .map_err(|e| FileError::io(path, FileAction::Create, &e))?;
            return Ok(Self {
                target,
                shown: path.to_path_buf(),
                temp: PathBuf::new(),
                file: Some(BufWriter::with_capacity(1 << 16, file)),
            });
        }
        Self::beside(target, path)
    }

    /// Starts replacing `target` itself (a link is replaced, not followed), through a
    /// temporary file beside it; errors name `shown`.
    fn beside(target: PathBuf, shown: &Path) -> Result<Self, FileError> {
        if let Some(dir) = target.parent().filter(|d| !d.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir).map_err(|e| FileError::io(dir, FileAction::Create, &e))?;
        }
        remove_stale_temporaries(&target);
        let temp = temp_beside(&target);
        live().push(temp.clone());
        let file = File::options()
            .write(true)
            .create_new(true)
            .open(&temp)
            .map_err(|e| {
                forget(&temp);
                FileError::io(shown, FileAction::Create, &e)
            })?;
        // Held until the file is closed: tells other writers this one is not abandoned.
        let _ = file.try_lock();
        Ok(Self {
            target,
            shown: shown.to_path_buf(),
            temp,
            file: Some(BufWriter::with_capacity(1 << 16, file)),
        })
    }

    /// The file this replaces (a link's target when `path` was a link).
    pub fn target(&self) -> &Path {
        &self.target
    }

    /// Flushes and syncs the temporary file and leaves it in place, not renamed.
    fn finish(&mut self) -> Result<(), FileError> {
        let shown = &self.shown;
        let writer = self.file.take().expect("not finished twice");
        let file = writer
            .into_inner()
            .map_err(|e| FileError::io(shown, FileAction::Write, e.error()))?;
        if self.temp.as_os_str().is_empty() {
            // Written in place: a device or a pipe may not sync, and has nothing to keep.
            return Ok(());
        }
        file.sync_all()
            .map_err(|e| FileError::io(shown, FileAction::Write, &e))
    }

    /// Makes the new bytes the target's: flush, sync, rename over the target, sync the
    /// folder. On error the target is untouched and the temporary file removed.
    pub fn commit(mut self) -> Result<(), FileError> {
        self.finish()?;
        if self.temp.as_os_str().is_empty() {
            return Ok(());
        }
        std::fs::rename(&self.temp, &self.target)
            .map_err(|e| FileError::io(&self.shown, FileAction::Rename, &e))?;
        // Renamed: nothing left for `drop` to remove.
        forget(&std::mem::take(&mut self.temp));
        sync_dir(self.target.parent().unwrap_or(Path::new("")));
        Ok(())
    }
}

impl Write for AtomicFile {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        match &mut self.file {
            Some(f) => f.write(buf),
            None => Err(io::Error::other("file already committed")),
        }
    }

    fn flush(&mut self) -> io::Result<()> {
        match &mut self.file {
            Some(f) => f.flush(),
            None => Ok(()),
        }
    }
}

impl Drop for AtomicFile {
    fn drop(&mut self) {
        // Uncommitted: the writer's buffer is discarded with it, then the file removed.
        if let Some(writer) = self.file.take() {
            let (file, _) = writer.into_parts();
            drop(file);
        }
        if !self.temp.as_os_str().is_empty() {
            let _ = std::fs::remove_file(&self.temp);
            forget(&self.temp);
        }
    }
}

/// Replaces `path` by `bytes` atomically (see [`AtomicFile`]).
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), FileError> {
    write_atomic_with(path, |w| w.write_all(bytes))
}

/// Replaces `path` by what `write` writes, atomically: when `write` fails, the file keeps
/// its previous bytes (see [`AtomicFile`]).
pub fn write_atomic_with(
    path: &Path,
    write: impl FnOnce(&mut dyn Write) -> io::Result<()>,
) -> Result<(), FileError> {
    let mut file = AtomicFile::create(path)?;
    write(&mut file).map_err(|e| FileError::io(path, FileAction::Write, &e))?;
    file.commit()
}

/// Opens a file to read, refusing what is not a regular file ([`FileError::NotAFile`]): a
/// FIFO would block until a writer comes, a device such as `/dev/zero` never ends, a folder
/// has no bytes. A link is followed.
pub fn open_regular(path: &Path) -> Result<File, FileError> {
    file_system(path, FileAction::Read)?;
    let read_err = |e: io::Error| FileError::io(path, FileAction::Read, &e);
    let regular = |metadata: std::fs::Metadata| match metadata.file_type() {
        kind if kind.is_file() => Ok(()),
        kind => Err(FileError::NotAFile {
            path: path.to_path_buf(),
            what: what_is(kind),
        }),
    };
    // Checked before opening (opening a FIFO blocks), and after: the path may have been
    // swapped in between.
    regular(std::fs::metadata(path).map_err(read_err)?)?;
    let file = File::open(path).map_err(read_err)?;
    regular(file.metadata().map_err(read_err)?)?;
    Ok(file)
}

/// What a file type that is not a regular file is, in words.
fn what_is(kind: std::fs::FileType) -> &'static str {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if kind.is_fifo() {
            return "a FIFO";
        }
        if kind.is_socket() {
            return "a socket";
        }
        if kind.is_block_device() || kind.is_char_device() {
            return "a device";
        }
    }
    if kind.is_dir() {
        "a folder"
    } else {
        "not a file"
    }
}

/// Reads a whole regular file (see [`open_regular`]) of at most `limit` bytes: a larger one
/// (or one that grows while it is read) is [`FileError::TooLarge`] after reading at most
/// `limit + 1` bytes.
pub fn read_limited(path: &Path, limit: u64) -> Result<Vec<u8>, FileError> {
    let read_err = |e: io::Error| FileError::io(path, FileAction::Read, &e);
    let file = open_regular(path)?;
    let too_large = || FileError::TooLarge {
        path: path.to_path_buf(),
        limit,
    };
    let len = file.metadata().map(|m| m.len()).unwrap_or(0);
    if len > limit {
        return Err(too_large());
    }
    let mut bytes = Vec::with_capacity(len as usize);
    file.take(limit.saturating_add(1))
        .read_to_end(&mut bytes)
        .map_err(read_err)?;
    if bytes.len() as u64 > limit {
        return Err(too_large());
    }
    Ok(bytes)
}

/// One staged file of a transaction: its temporary name and its name, in the folder.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
struct Staged {
    temp: String,
    name: String,
}

/// Several files of one folder written all-or-nothing (see the [module](self) docs).
///
/// ```
/// use rwt_core::files::SaveTransaction;
/// let dir = std::env::temp_dir().join(format!("rwt-save-doc-{}", std::process::id()));
/// let mut save = SaveTransaction::begin(&dir).unwrap();
/// save.write("map.png", b"...").unwrap();
/// save.write("index.ron", b"(maps: [\"map.png\"])").unwrap();
/// save.commit().unwrap();
/// assert_eq!(std::fs::read(dir.join("map.png")).unwrap(), b"...");
/// # std::fs::remove_dir_all(&dir).unwrap();
/// ```
pub struct SaveTransaction {
    dir: PathBuf,
    staged: Vec<Staged>,
}

impl SaveTransaction {
    /// Starts a save into `dir` (created when missing), first finishing a save a crash
    /// interrupted there (see [`recover`]).
    pub fn begin(dir: &Path) -> Result<Self, FileError> {
        file_system(dir, FileAction::Create)?;
        std::fs::create_dir_all(dir).map_err(|e| FileError::io(dir, FileAction::Create, &e))?;
        recover(dir)?;
        Ok(Self {
            dir: dir.to_path_buf(),
            staged: Vec::new(),
        })
    }

    /// The folder.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// Stages `bytes` as the file `name` of the folder.
    pub fn write(&mut self, name: &str, bytes: &[u8]) -> Result<(), FileError> {
        self.write_with(name, |w| w.write_all(bytes))
    }

    /// Stages what `write` writes as the file `name` of the folder; nothing of the folder's
    /// files changes before [`SaveTransaction::commit`].
    pub fn write_with(
        &mut self,
        name: &str,
        write: impl FnOnce(&mut dyn Write) -> io::Result<()>,
    ) -> Result<(), FileError> {
        let path = self.dir.join(name);
        if self.staged.iter().any(|s| s.name == name) {
            return Err(FileError::Duplicate { path });
        }
        // Staged beside its name in the folder (a link there is replaced, not followed: the
        // journal names files of this folder only).
        let mut file = AtomicFile::beside(path.clone(), &path)?;
        write(&mut file).map_err(|e| FileError::io(&path, FileAction::Write, &e))?;
        file.finish()?;
        // Still live (a signal removes it) until the commit renames it.
        let temp = std::mem::take(&mut file.temp);
        self.staged.push(Staged {
            temp: file_name(&temp),
            name: name.to_string(),
        });
        Ok(())
    }

    /// Makes every staged file the folder's: the journal is written (from then on the save
    /// is durable), the files are renamed into place, and the journal removed.
    pub fn commit(mut self) -> Result<(), FileError> {
        let staged = std::mem::take(&mut self.staged);
        let journal = ron::to_string(&staged).expect("plain data serializes");
        write_atomic(&self.dir.join(JOURNAL_FILE), journal.as_bytes())?;
        finish_journal(&self.dir, &staged)
    }
}

impl Drop for SaveTransaction {
    fn drop(&mut self) {
        // Not committed: the staged files go, the folder's files stay as they were.
        for s in &self.staged {
            let temp = self.dir.join(&s.temp);
            let _ = std::fs::remove_file(&temp);
            forget(&temp);
        }
    }
}

fn file_name(path: &Path) -> String {
    path.file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default()
}

/// Renames the journal's files into place and removes the journal.
fn finish_journal(dir: &Path, staged: &[Staged]) -> Result<(), FileError> {
    for s in staged {
        let (temp, target) = (dir.join(&s.temp), dir.join(&s.name));
        // A temporary file already gone was renamed before an interruption.
        if temp.exists() {
            std::fs::rename(&temp, &target)
                .map_err(|e| FileError::io(&dir.join(&s.name), FileAction::Rename, &e))?;
        }
        forget(&temp);
    }
    sync_dir(dir);
    let journal = dir.join(JOURNAL_FILE);
    std::fs::remove_file(&journal).map_err(|e| FileError::io(&journal, FileAction::Write, &e))?;
    sync_dir(dir);
    Ok(())
}

/// Finishes a [`SaveTransaction`] that a crash interrupted in `dir` after its journal was
/// written, and removes temporary files a crash left before that. Returns whether a save was
/// finished. Readers of a saved folder call it before reading.
pub fn recover(dir: &Path) -> Result<bool, FileError> {
    file_system(dir, FileAction::Read)?;
    let journal_path = dir.join(JOURNAL_FILE);
    let finished = match std::fs::read_to_string(&journal_path) {
        Ok(text) => match ron::from_str::<Vec<Staged>>(&text) {
            Ok(staged)
                if staged
                    .iter()
                    .all(|s| is_plain_name(&s.temp) && is_plain_name(&s.name)) =>
            {
                finish_journal(dir, &staged)?;
                true
            }
            // A journal is written atomically, so a broken one is not ours: leave it.
            _ => false,
        },
        Err(e) if e.kind() == io::ErrorKind::NotFound => false,
        Err(e) => return Err(FileError::io(&journal_path, FileAction::Read, &e)),
    };
    if let Ok(entries) = std::fs::read_dir(dir) {
        for entry in entries.flatten() {
            let name = entry.file_name();
            if name.to_string_lossy().ends_with(TEMP_SUFFIX) {
                let _ = std::fs::remove_file(entry.path());
            }
        }
    }
    Ok(finished)
}

/// Whether `name` names a file of a folder itself: no folders, not `..` (journal and index
/// entries never leave their folder).
pub fn is_plain_name(name: &str) -> bool {
    Path::new(name).file_name().is_some_and(|n| n == name) && name != ".."
}

#[cfg(test)]
mod tests;
