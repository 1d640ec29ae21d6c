//! Files written whole or not at all: every file pt-spectra writes (tables, plots, reports, cached
//! tables) is written to a temporary file in the target's directory, flushed to the disk (`fsync`)
//! and renamed over the target, so the target holds either its old content or the whole new one,
//! whatever happens meanwhile (a full disk, a failed writer, a killed process).
//!
//! ```
//! use pt_spectra::output::write_atomic;
//! let path = std::env::temp_dir().join(format!("pt-spectra-atomic-doc-{}", std::process::id()));
//! write_atomic(&path, b"old\n")?;
//! let failed = pt_spectra::output::write_atomic_with(&path, |file| {
//!     use std::io::Write;
//!     file.write_all(b"half a tab")?;
//!     Err(std::io::Error::other("no space left on device"))
//! });
//! assert!(failed.is_err());
//! assert_eq!(std::fs::read(&path)?, b"old\n"); // the old file is intact
//! # std::fs::remove_file(&path)?;
//! # Ok::<(), std::io::Error>(())
//! ```

use std::fs::File;
use std::io::{self, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};

/// Writes `bytes` to `path` atomically (see the module docs).
///
/// # Errors
/// The [`io::Error`] of the first step that fails (creating, writing, syncing or renaming the
/// temporary file); `path` is then unchanged and the temporary file removed.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> io::Result<()> {
    write_atomic_with(path, |file| file.write_all(bytes))
}

/// Writes `path` atomically through `write`, which gets the temporary file (opened for writing).
///
/// # Errors
/// As [`write_atomic`], or the error `write` returns.
pub fn write_atomic_with(
    path: &Path,
    write: impl FnOnce(&mut File) -> io::Result<()>,
) -> io::Result<()> {
    replace_with(path, |tmp| {
        let mut file = File::create(tmp)?;
        write(&mut file)?;
        file.flush()
    })
}

/// Writes `path` atomically through `write`, which gets the path of a temporary file in the same
/// directory to create and fill; its name ends in the target's extension (`.png`, `.svg`, …), for
/// writers that choose the format by it. The temporary file is then synced and renamed over `path`
/// (over the file a symbolic link `path` points to, which stays a link), keeping the permissions of
/// the file it replaces. A `path` that is neither a regular file nor a directory (`/dev/null`,
/// `/dev/stdout`, a FIFO) is given to `write` itself: nothing can be renamed over it.
///
/// # Errors
/// As [`write_atomic`], or the error `write` returns.
pub fn replace_with(path: &Path, write: impl FnOnce(&Path) -> io::Result<()>) -> io::Result<()> {
    if std::fs::metadata(path).is_ok_and(|m| !m.is_file() && !m.is_dir()) {
        // A device, FIFO or terminal (`/dev/null`, `/dev/stdout`): written in place, since renaming
        // a file over it would replace the device itself.
        return write(path);
    }
    let target = resolved(path);
    let tmp = temporary(&target);
    let result = write(&tmp).and_then(|()| {
        let file = File::open(&tmp)?;
        if let Ok(old) = std::fs::metadata(&target) {
            file.set_permissions(old.permissions())?;
        }
        file.sync_all()?;
        std::fs::rename(&tmp, &target)
    });
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
        return result;
    }
    // The rename itself is durable once the directory is synced; where a directory cannot be opened
    // (not Unix), the file is whole anyway.
    if let Some(dir) = target.parent().filter(|d| !d.as_os_str().is_empty()) {
        if let Ok(d) = File::open(dir) {
            let _ = d.sync_all();
        }
    }
    Ok(())
}

/// `path`, or the file it points to if it is a symbolic link.
fn resolved(path: &Path) -> PathBuf {
    match std::fs::symlink_metadata(path) {
        Ok(m) if m.file_type().is_symlink() => {
            std::fs::canonicalize(path).unwrap_or_else(|_| path.to_path_buf())
        }
        _ => path.to_path_buf(),
    }
}

/// A temporary file name beside `target`, unique in this process and among processes:
/// `.<name>.<pid>-<n>.tmp[.<extension>]`.
fn temporary(target: &Path) -> PathBuf {
    static NEXT: AtomicUsize = AtomicUsize::new(0);
    let name = target
        .file_name()
        .map_or_else(|| "out".into(), |n| n.to_string_lossy());
    let mut tmp = format!(
        ".{name}.{}-{}.tmp",
        std::process::id(),
        NEXT.fetch_add(1, Ordering::Relaxed)
    );
    if let Some(extension) = target.extension() {
        tmp = format!("{tmp}.{}", extension.to_string_lossy());
    }
    target.with_file_name(tmp)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch(name: &str) -> PathBuf {
        let dir =
            std::env::temp_dir().join(format!("pt-spectra-atomic-{}-{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    fn leftovers(dir: &Path) -> Vec<String> {
        std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .filter(|n| n.contains(".tmp"))
            .collect()
    }

    /// A writer that fails after writing half its output (a full disk) leaves the old file whole and
    /// no temporary file; a writer that succeeds replaces it.
    #[test]
    fn a_failing_write_leaves_the_old_file_intact() {
        let dir = scratch("fail");
        let path = dir.join("table.dat");
        let old = "# k P\n0.1 1.0\n0.2 2.0\n".repeat(1000);
        write_atomic(&path, old.as_bytes()).unwrap();
        let e = write_atomic_with(&path, |f| {
            f.write_all(&old.as_bytes()[..old.len() / 2])?;
            Err(io::Error::other("No space left on device"))
        })
        .unwrap_err();
        assert!(e.to_string().contains("No space"), "{e}");
        assert_eq!(std::fs::read_to_string(&path).unwrap(), old);
        assert!(leftovers(&dir).is_empty(), "{:?}", leftovers(&dir));
        write_atomic(&path, b"new\n").unwrap();
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "new\n");
        assert!(leftovers(&dir).is_empty(), "{:?}", leftovers(&dir));
    }

    /// A target that cannot be replaced (a directory in its place: the rename fails after the whole
    /// file was written) is an error and the temporary file is removed.
    #[test]
    fn a_failed_rename_removes_the_temporary_file() {
        let dir = scratch("rename");
        let path = dir.join("out.png");
        std::fs::create_dir_all(path.join("inside")).unwrap();
        let mut seen = None;
        assert!(replace_with(&path, |tmp| {
            seen = Some(tmp.to_path_buf());
            std::fs::write(tmp, b"png")
        })
        .is_err());
        let seen = seen.unwrap();
        assert_eq!(seen.extension().unwrap(), "png", "{}", seen.display());
        assert_eq!(seen.parent(), Some(dir.as_path()));
        assert!(leftovers(&dir).is_empty(), "{:?}", leftovers(&dir));
    }

    /// A FIFO (as `/dev/stdout` can be) is written through, not replaced by a regular file.
    #[cfg(unix)]
    #[test]
    fn a_fifo_is_written_in_place() {
        use std::os::unix::fs::FileTypeExt;
        let dir = scratch("fifo");
        let fifo = dir.join("pipe.dat");
        assert!(std::process::Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .unwrap()
            .success());
        let reader = {
            let fifo = fifo.clone();
            std::thread::spawn(move || std::fs::read(fifo).unwrap())
        };
        write_atomic(&fifo, b"# k P\n").unwrap();
        assert_eq!(reader.join().unwrap(), b"# k P\n");
        assert!(std::fs::metadata(&fifo).unwrap().file_type().is_fifo());
        assert!(leftovers(&dir).is_empty());
    }

    /// A symbolic link keeps pointing to the replaced file, and the file keeps its permissions.
    #[cfg(unix)]
    #[test]
    fn links_and_permissions_are_kept() {
        use std::os::unix::fs::PermissionsExt;
        let dir = scratch("link");
        let real = dir.join("real.dat");
        std::fs::write(&real, "old").unwrap();
        std::fs::set_permissions(&real, std::fs::Permissions::from_mode(0o640)).unwrap();
        let link = dir.join("link.dat");
        std::os::unix::fs::symlink(&real, &link).unwrap();
        write_atomic(&link, b"new").unwrap();
        assert!(std::fs::symlink_metadata(&link)
            .unwrap()
            .file_type()
            .is_symlink());
        assert_eq!(std::fs::read_to_string(&real).unwrap(), "new");
        let mode = std::fs::metadata(&real).unwrap().permissions().mode();
        assert_eq!(mode & 0o777, 0o640);
    }
}
