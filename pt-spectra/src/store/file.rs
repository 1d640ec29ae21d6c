//! The table files of the store: their format (header, length, hash), the lock beside each, and the
//! rules that keep a bad cache from stopping a run: a directory that cannot hold the tables
//! (read-only, a file in its place) means tables built in memory, with a note; a file that is not a
//! regular file (a FIFO, a device) is never opened for reading as a table, so it cannot hang a run.

use crate::error::{Error, Result};
use crate::progress::Progress;
use std::fs::{File, OpenOptions, TryLockError};
use std::io::Read;
use std::path::Path;

/// The table at `path` if it is there and valid, otherwise built under an exclusive lock on
/// `<path>.lock` (after waiting for any other process holding it, which may have built it meanwhile)
/// and written atomically. If the directory cannot be created or the lock cannot be taken (a
/// read-only directory, a file in its place, a lock file that is not a regular file), the table is
/// built and used from memory, with a note through `progress` naming the path and the reason.
///
/// # Errors
/// None at present: every cache failure falls back to memory (the `Result` is kept for callers).
pub(crate) fn cached<T>(
    path: &Path,
    name: &str,
    read: impl Fn(&[f64]) -> Option<T>,
    build: impl FnOnce() -> T,
    write: impl Fn(&T) -> Vec<f64>,
    progress: &dyn Progress,
) -> Result<T> {
    // The table if the file holds a valid one; else why not (None: no file, nothing to say).
    let read_file = || -> std::result::Result<T, Option<String>> {
        match read_f64s(path) {
            Stored::Missing => Err(None),
            Stored::Invalid(why) => Err(Some(why)),
            Stored::Values(v) => {
                read(&v).ok_or_else(|| Some("fails the table's consistency checks".to_string()))
            }
        }
    };
    let first = match read_file() {
        Ok(t) => return Ok(t),
        Err(why) => why,
    };
    let lock = match lock_beside(path, name, progress) {
        Ok(lock) => lock,
        Err(e) => {
            let why = first.map_or(String::new(), |why| {
                format!("the cached file `{}` {why}; ", path.display())
            });
            progress.note(&format!(
                "{why}{e}: the {name} table is built and used from memory (not saved: the next \
                 process builds it again)"
            ));
            return Ok(build());
        }
    };
    // Another process may have finished the table while this one waited.
    let why = match read_file() {
        Ok(t) => return Ok(t),
        Err(why) => why.or(first),
    };
    if let Some(why) = why {
        progress.note(&format!(
            "the cached {name} table `{}` {why}: rebuilding it",
            path.display()
        ));
    }
    let t = build();
    if let Err(e) = write_f64s(path, &write(&t)) {
        progress.note(&format!(
            "cannot write the {name} table to `{}` ({e}): using it from memory; it will be built \
             again by the next process",
            path.display()
        ));
    }
    // The lock is released when `lock` is dropped (or the process dies); the file stays, empty.
    drop(lock);
    Ok(t)
}

/// The directory of `path` created if needed, and the exclusive lock on `<path>.lock` taken.
///
/// # Errors
/// [`Error::Cache`] naming the directory or lock file that fails.
fn lock_beside(path: &Path, name: &str, progress: &dyn Progress) -> Result<File> {
    let fail = |path: &Path, what: &'static str| {
        let path = path.to_path_buf();
        move |source| Error::Cache { path, what, source }
    };
    if let Some(dir) = path.parent() {
        if dir.exists() && !dir.is_dir() {
            return Err(Error::Cache {
                path: dir.to_path_buf(),
                what: "use as the cache directory",
                source: std::io::Error::other("it exists and is not a directory"),
            });
        }
        std::fs::create_dir_all(dir).map_err(fail(dir, "create the cache directory"))?;
    }
    let lock_path = path.with_extension("lock");
    let mut options = OpenOptions::new();
    options.create(true).truncate(false).write(true);
    let lock =
        open_regular(&lock_path, &mut options).map_err(fail(&lock_path, "open the lock file"))?;
    acquire(&lock, &lock_path, name, progress)?;
    Ok(lock)
}

/// Opens `path` with `options` if it is a regular file (or, with `create`, does not exist yet):
/// checked before the open, and again on the open file, and opened without blocking, so that a
/// FIFO or device put in its place (even between the check and the open) is an error, never a hang.
///
/// # Errors
/// The [`std::io::Error`] of the open, or one saying the file is not a regular file.
fn open_regular(path: &Path, options: &mut OpenOptions) -> std::io::Result<File> {
    let not_regular = || std::io::Error::other("it is not a regular file (a FIFO, a device?)");
    if std::fs::metadata(path).is_ok_and(|m| !m.is_file()) {
        return Err(not_regular());
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::OpenOptionsExt;
        options.custom_flags(libc::O_NONBLOCK);
    }
    let file = options.open(path)?;
    if !file.metadata()?.is_file() {
        return Err(not_regular());
    }
    Ok(file)
}

/// Takes the exclusive lock on `lock`, telling `progress` when it has to wait for another process.
fn acquire(lock: &File, lock_path: &Path, name: &str, progress: &dyn Progress) -> Result<()> {
    let fail = |source| Error::Cache {
        path: lock_path.to_path_buf(),
        what: "lock the table",
        source,
    };
    match lock.try_lock() {
        Ok(()) => Ok(()),
        Err(TryLockError::WouldBlock) => {
            progress.note(&format!(
                "waiting for another process that is building the {name} table (it holds the lock \
                 `{}`)",
                lock_path.display()
            ));
            lock.lock().map_err(fail)
        }
        Err(TryLockError::Error(e)) => Err(fail(e)),
    }
}

/// The first bytes of every table file (the format's version is its last two characters).
const MAGIC: &[u8; 8] = b"PTSTAB01";
/// The header: [`MAGIC`], the number of values (u64) and the [`fnv1a`] hash of the payload (u64).
pub(super) const HEADER: usize = 24;

/// The 64-bit FNV-1a hash of `bytes` (Fowler, Noll & Vo): any change of one byte changes it, and a
/// random change goes unnoticed with probability 2^-64.
pub(super) fn fnv1a(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, &b| {
        (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3)
    })
}

/// Writes `values` to `path` behind the [`HEADER`], atomically
/// ([`write_atomic`](crate::output::write_atomic)), replacing a FIFO or device there.
pub(super) fn write_f64s(path: &Path, values: &[f64]) -> std::io::Result<()> {
    let payload: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
    let mut bytes = Vec::with_capacity(HEADER + payload.len());
    bytes.extend_from_slice(MAGIC);
    bytes.extend_from_slice(&(values.len() as u64).to_le_bytes());
    bytes.extend_from_slice(&fnv1a(&payload).to_le_bytes());
    bytes.extend_from_slice(&payload);
    // A FIFO or device in place of the table is removed, then replaced: written through, it would
    // wait for a reader (write_atomic writes such targets in place, for `--out /dev/stdout`).
    if std::fs::symlink_metadata(path).is_ok_and(|m| {
        let t = m.file_type();
        !t.is_file() && !t.is_dir() && !t.is_symlink()
    }) {
        std::fs::remove_file(path)?;
    }
    crate::output::write_atomic(path, &bytes)
}

/// What a table file holds.
pub(super) enum Stored {
    /// No file (or none that can be read): build the table without comment.
    Missing,
    /// A file that is not a whole, intact table: why.
    Invalid(String),
    /// The values, their hash verified.
    Values(Vec<f64>),
}

/// Reads a table file written by [`write_f64s`], verifying that it is a regular file, its header,
/// length and hash.
pub(super) fn read_f64s(path: &Path) -> Stored {
    let mut file = match open_regular(path, OpenOptions::new().read(true)) {
        Ok(file) => file,
        Err(e) if e.kind() == std::io::ErrorKind::Other => {
            return Stored::Invalid(format!("is not a table file: {e}"))
        }
        Err(_) => return Stored::Missing,
    };
    let mut bytes = Vec::new();
    let length = file.metadata().map_or(0, |m| m.len());
    if usize::try_from(length)
        .ok()
        .and_then(|n| bytes.try_reserve_exact(n).ok())
        .is_none()
    {
        return Stored::Invalid(format!(
            "is too large to read ({}): not a table file",
            crate::memory::size(length as f64)
        ));
    }
    if file.read_to_end(&mut bytes).is_err() {
        return Stored::Missing;
    }
    let word = |i: usize| {
        let mut b = [0u8; 8];
        b.copy_from_slice(&bytes[8 * i..8 * i + 8]);
        u64::from_le_bytes(b)
    };
    if bytes.len() < HEADER || &bytes[..8] != MAGIC {
        return Stored::Invalid(
            "is not a table file of this version (no PTSTAB01 header)".to_string(),
        );
    }
    let payload = &bytes[HEADER..];
    let (count, hash) = (word(1), word(2));
    if payload.len() as u64 != count.saturating_mul(8) {
        return Stored::Invalid(format!(
            "is truncated or extended: {} bytes of values where the header says {count} values",
            payload.len()
        ));
    }
    let actual = fnv1a(payload);
    if actual != hash {
        return Stored::Invalid(format!(
            "is corrupted: its checksum is {actual:016x}, the header says {hash:016x}"
        ));
    }
    Stored::Values(
        payload
            .chunks_exact(8)
            .map(|c| {
                let mut b = [0u8; 8];
                b.copy_from_slice(c);
                f64::from_le_bytes(b)
            })
            .collect(),
    )
}
