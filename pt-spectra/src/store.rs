//! [`TableStore`]: the cosmology-independent angular tables (P15, P17), built once and cached in a
//! directory the caller chooses.
//!
//! A table file is a header (the magic `PTSTAB01`, the number of values, and the 64-bit FNV-1a hash of
//! the payload's bytes) followed by the values as little-endian f64. A table is read from its file if
//! the file is there, its hash matches and the values pass the table's own checks (size, finite
//! values, a few entries recomputed); otherwise it is built and written atomically (a temporary file
//! renamed into place), so a reader never sees half a table, and a corrupted, truncated or stale file
//! is rebuilt, with a note through [`Progress::note`] that says why. A table that cannot be written
//! (full disk, read-only directory) is used from memory, with a note, and the temporary file is
//! removed. While a
//! process builds a table it holds an operating-system lock on `<table>.lock` beside it
//! ([`std::fs::File::lock`]): another process that needs the same table waits for it (and says so
//! through [`Progress::note`]) instead of building it twice, and a process that dies while building
//! releases the lock with its death, so an interrupted build never blocks later runs.
//!
//! ```no_run
//! use pt_spectra::{progress::Silent, store::TableStore};
//! let store = TableStore::new("/tmp/pt-spectra-cache");
//! let p15 = store.p15(&Silent)?; // built on first use (~35 s on 2 cores), then read from the file
//! # Ok::<(), pt_spectra::error::Error>(())
//! ```

use crate::error::{Error, Result};
use crate::loops::basis::TwoLoopBasis;
use crate::loops::{P15Table, P17Table};
use crate::precision::Precision;
use crate::progress::{Progress, Stage};
use std::fs::{File, OpenOptions, TryLockError};
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

/// Where the angular tables live, and the tables this store has already loaded.
#[derive(Debug, Default)]
pub struct TableStore {
    dir: Option<PathBuf>,
    p15: Mutex<Option<Arc<P15Table>>>,
    p17: Mutex<Option<Arc<P17Table>>>,
}

impl TableStore {
    /// A store caching its tables in `dir` (created when first needed).
    pub fn new(dir: impl Into<PathBuf>) -> Self {
        Self {
            dir: Some(dir.into()),
            ..Self::default()
        }
    }

    /// A store without a directory: tables are built in memory by each store that needs them.
    pub fn in_memory() -> Self {
        Self::default()
    }

    /// The conventional cache directory: `$PT_SPECTRA_CACHE`, else `$XDG_CACHE_HOME/pt-spectra`, else
    /// `$HOME/.cache/pt-spectra`; in memory if none of them is set.
    pub fn from_env() -> Self {
        let dir = std::env::var_os("PT_SPECTRA_CACHE")
            .map(PathBuf::from)
            .or_else(|| {
                std::env::var_os("XDG_CACHE_HOME").map(|d| PathBuf::from(d).join("pt-spectra"))
            })
            .or_else(|| {
                std::env::var_os("HOME").map(|d| PathBuf::from(d).join(".cache/pt-spectra"))
            });
        Self {
            dir,
            ..Self::default()
        }
    }

    /// The cache directory, if any.
    pub fn dir(&self) -> Option<&Path> {
        self.dir.as_deref()
    }

    /// The file a table of this store lives in (`file_name` as the table names it).
    fn path(&self, file_name: &str) -> Option<PathBuf> {
        self.dir.as_ref().map(|d| d.join(file_name))
    }

    /// The P15 angular table ([`P15Table`]): loaded by this store already, read from its file, or built
    /// (reporting [`Stage::P15Table`]) and written.
    ///
    /// # Errors
    /// [`Error::Cache`] if the directory cannot be created or the table cannot be written or locked.
    pub fn p15(&self, progress: &dyn Progress) -> Result<Arc<P15Table>> {
        load(
            &self.p15,
            self.path(&P15Table::file_name()),
            "P15",
            P15Table::from_f64s,
            || P15Table::build(&|d, t| progress.update(Stage::P15Table, d, t)),
            P15Table::to_f64s,
            progress,
        )
    }

    /// The P17 angular table ([`P17Table`]), as [`p15`](Self::p15).
    ///
    /// # Errors
    /// As [`p15`](Self::p15).
    pub fn p17(&self, progress: &dyn Progress) -> Result<Arc<P17Table>> {
        load(
            &self.p17,
            self.path(&P17Table::file_name()),
            "P17",
            P17Table::from_f64s,
            || P17Table::build(&|d, t| progress.update(Stage::P17Table, d, t)),
            P17Table::to_f64s,
            progress,
        )
    }
}

impl TableStore {
    /// The 2-loop basis tensors ([`TwoLoopBasis`]) for the wavenumbers `k` and `precision`: read
    /// from their file, or built with the P15 `table` (reporting [`Stage::TwoLoopBasis`]; minutes)
    /// and written. Without a directory they are built each time.
    ///
    /// # Errors
    /// [`Error::Cache`] if the directory cannot be created or the file cannot be written or locked.
    pub fn two_loop_basis(
        &self,
        k: &[f64],
        precision: &Precision,
        table: &P15Table,
        progress: &dyn Progress,
    ) -> Result<Arc<TwoLoopBasis>> {
        let build = || {
            TwoLoopBasis::build(k, precision, table, &|d, t| {
                progress.update(Stage::TwoLoopBasis, d, t)
            })
        };
        let tensors = match self.path(&TwoLoopBasis::file_name(k, precision)) {
            None => build(),
            Some(path) => cached(
                &path,
                "2-loop basis",
                |v| TwoLoopBasis::from_f64s(v, k, precision),
                build,
                TwoLoopBasis::to_f64s,
                progress,
            )?,
        };
        Ok(Arc::new(tensors))
    }

    /// The 2-loop basis tensors for `k` and `precision` if their file is in the directory and valid
    /// (never builds them; a corrupted file is reported to `progress` and not used).
    pub fn cached_two_loop_basis(
        &self,
        k: &[f64],
        precision: &Precision,
        progress: &dyn Progress,
    ) -> Option<Arc<TwoLoopBasis>> {
        let path = self.path(&TwoLoopBasis::file_name(k, precision))?;
        let tensors = match read_f64s(&path) {
            Stored::Missing => None,
            Stored::Invalid(why) => {
                progress.note(&format!(
                    "the cached 2-loop basis tensors `{}` {why}: not used (method basis rebuilds them)",
                    path.display()
                ));
                return None;
            }
            Stored::Values(v) => TwoLoopBasis::from_f64s(&v, k, precision),
        };
        if tensors.is_none() && path.exists() {
            progress.note(&format!(
                "the cached 2-loop basis tensors `{}` fail their consistency checks: not used \
                 (method basis rebuilds them)",
                path.display()
            ));
        }
        tensors.map(Arc::new)
    }
}

/// The table in `slot`, else from [`cached`], kept in `slot`.
fn load<T>(
    slot: &Mutex<Option<Arc<T>>>,
    path: Option<PathBuf>,
    name: &str,
    read: impl Fn(&[f64]) -> Option<T>,
    build: impl FnOnce() -> T,
    write: impl Fn(&T) -> Vec<f64>,
    progress: &dyn Progress,
) -> Result<Arc<T>> {
    // Holding the slot while loading makes threads of one process share one build.
    let mut slot = slot
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner);
    if let Some(t) = slot.as_ref() {
        return Ok(Arc::clone(t));
    }
    let t = Arc::new(match path {
        None => build(),
        Some(path) => cached(&path, name, read, build, write, progress)?,
    });
    *slot = Some(Arc::clone(&t));
    Ok(t)
}

/// The table at `path` if it is there and valid, otherwise built under an exclusive lock on
/// `<path>.lock` (after waiting for any other process holding it, which may have built it meanwhile)
/// and written atomically.
///
/// # Errors
/// [`Error::Cache`] naming the file when the directory, the lock or the table file fails.
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
    let lock = OpenOptions::new()
        .create(true)
        .truncate(false)
        .write(true)
        .open(&lock_path)
        .map_err(fail(&lock_path, "open the lock file"))?;
    acquire(&lock, &lock_path, name, progress)?;
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
const HEADER: usize = 24;

/// The 64-bit FNV-1a hash of `bytes` (Fowler, Noll & Vo): any change of one byte changes it, and a
/// random change goes unnoticed with probability 2^-64.
pub(crate) fn fnv1a(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, &b| {
        (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3)
    })
}

/// Writes `values` to `path` atomically (a temporary file of this process, then renamed into place)
/// behind the [`HEADER`]; the temporary file is removed if anything fails.
fn write_f64s(path: &Path, values: &[f64]) -> std::io::Result<()> {
    let payload: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
    let mut bytes = Vec::with_capacity(HEADER + payload.len());
    bytes.extend_from_slice(MAGIC);
    bytes.extend_from_slice(&(values.len() as u64).to_le_bytes());
    bytes.extend_from_slice(&fnv1a(&payload).to_le_bytes());
    bytes.extend_from_slice(&payload);
    let tmp = path.with_extension(format!("tmp{}", std::process::id()));
    let result = std::fs::write(&tmp, &bytes).and_then(|()| std::fs::rename(&tmp, path));
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result
}

/// What a table file holds.
enum Stored {
    /// No file (or none that can be read): build the table without comment.
    Missing,
    /// A file that is not a whole, intact table: why.
    Invalid(String),
    /// The values, their hash verified.
    Values(Vec<f64>),
}

/// Reads a table file written by [`write_f64s`], verifying its header, length and hash.
fn read_f64s(path: &Path) -> Stored {
    let Ok(bytes) = std::fs::read(path) else {
        return Stored::Missing;
    };
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::progress::Silent;
    use std::sync::atomic::{AtomicUsize, Ordering};

    fn scratch(name: &str) -> PathBuf {
        let dir =
            std::env::temp_dir().join(format!("pt-spectra-store-{}-{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        dir
    }

    fn table(path: &Path, builds: &AtomicUsize, value: f64) -> Result<Vec<f64>> {
        cached(
            path,
            "test",
            |v: &[f64]| (v.len() == 3).then(|| v.to_vec()),
            || {
                builds.fetch_add(1, Ordering::Relaxed);
                vec![value; 3]
            },
            Clone::clone,
            &Silent,
        )
    }

    #[test]
    fn a_table_is_built_once_then_read_and_a_corrupt_file_is_rebuilt() {
        let dir = scratch("once");
        let path = dir.join("t.bin");
        let builds = AtomicUsize::new(0);
        assert_eq!(table(&path, &builds, 1.5).unwrap(), vec![1.5; 3]);
        assert_eq!(table(&path, &builds, 2.5).unwrap(), vec![1.5; 3]);
        assert_eq!(builds.load(Ordering::Relaxed), 1);
        std::fs::write(&path, [0u8; 13]).unwrap();
        assert_eq!(table(&path, &builds, 2.5).unwrap(), vec![2.5; 3]);
        assert_eq!(builds.load(Ordering::Relaxed), 2);
    }

    /// Notes received, for the test below.
    struct Notes(Mutex<Vec<String>>);
    impl Progress for Notes {
        fn note(&self, message: &str) {
            self.0.lock().unwrap().push(message.to_string());
        }
    }

    /// Run by [`a_killed_build_releases_its_lock`] in a child process: starts building a table that
    /// takes a minute, holding its lock, and is killed meanwhile.
    #[test]
    #[ignore = "a child process of a_killed_build_releases_its_lock"]
    fn child_builds_slowly() {
        let Some(dir) = std::env::var_os("PT_SPECTRA_STORE_CHILD") else {
            return;
        };
        let path = PathBuf::from(dir).join("t.bin");
        let _ = cached(
            &path,
            "test",
            |_: &[f64]| None::<Vec<f64>>,
            || {
                std::thread::sleep(std::time::Duration::from_secs(60));
                vec![0.0]
            },
            Clone::clone,
            &Silent,
        );
    }

    #[test]
    fn a_killed_build_releases_its_lock() {
        let dir = scratch("killed");
        std::fs::create_dir_all(&dir).unwrap();
        let mut child = std::process::Command::new(std::env::current_exe().unwrap())
            .args(["store::tests::child_builds_slowly", "--exact", "--ignored"])
            .env("PT_SPECTRA_STORE_CHILD", &dir)
            .stdout(std::process::Stdio::null())
            .spawn()
            .unwrap();
        // Wait until the child holds the lock.
        let lock_path = dir.join("t.lock");
        let start = std::time::Instant::now();
        loop {
            let held = File::open(&lock_path)
                .map(|f| matches!(f.try_lock(), Err(TryLockError::WouldBlock)))
                .unwrap_or(false);
            if held {
                break;
            }
            assert!(
                start.elapsed().as_secs() < 30,
                "the child never took the lock"
            );
            std::thread::sleep(std::time::Duration::from_millis(20));
        }
        // This process now waits for the child, says so, and builds the table as soon as the child
        // is killed (the operating system releases its lock).
        let killer = std::thread::spawn(move || {
            std::thread::sleep(std::time::Duration::from_millis(500));
            child.kill().unwrap();
            child.wait().unwrap();
        });
        let notes = Notes(Mutex::new(Vec::new()));
        let builds = AtomicUsize::new(0);
        let waited = std::time::Instant::now();
        let t = cached(
            &dir.join("t.bin"),
            "test",
            |v: &[f64]| (v.len() == 3).then(|| v.to_vec()),
            || {
                builds.fetch_add(1, Ordering::Relaxed);
                vec![7.0; 3]
            },
            Clone::clone,
            &notes,
        )
        .unwrap();
        killer.join().unwrap();
        assert_eq!(t, vec![7.0; 3]);
        assert_eq!(builds.load(Ordering::Relaxed), 1);
        assert!(waited.elapsed().as_secs() < 20, "{:?}", waited.elapsed());
        let notes = notes.0.into_inner().unwrap();
        assert!(
            notes.len() == 1 && notes[0].contains("waiting") && notes[0].contains("t.lock"),
            "{notes:?}"
        );
    }

    #[test]
    fn fnv1a_has_its_published_values() {
        assert_eq!(fnv1a(b""), 0xcbf2_9ce4_8422_2325);
        assert_eq!(fnv1a(b"a"), 0xaf63_dc4c_8601_ec8c);
        assert_eq!(fnv1a(b"foobar"), 0x8594_4171_f739_67e8);
    }

    /// Builds (or reads) a table of 1000 values at `path`, counting builds and collecting notes.
    fn long_table(path: &Path, builds: &AtomicUsize, notes: &Notes) -> Vec<f64> {
        cached(
            path,
            "test",
            |v: &[f64]| (v.len() == 1000).then(|| v.to_vec()),
            || {
                builds.fetch_add(1, Ordering::Relaxed);
                (0..1000).map(f64::from).collect()
            },
            Clone::clone,
            notes,
        )
        .unwrap()
    }

    /// Fault injection: bytes overwritten in the middle, values scaled, the file truncated or of an
    /// older format; each is noticed, said, and rebuilt, never used.
    #[test]
    fn a_corrupted_table_is_rebuilt_with_a_note() {
        let dir = scratch("corrupt");
        let path = dir.join("t.bin");
        let builds = AtomicUsize::new(0);
        let notes = Notes(Mutex::new(Vec::new()));
        let good: Vec<f64> = (0..1000).map(f64::from).collect();
        assert_eq!(long_table(&path, &builds, &notes), good);
        let intact = std::fs::read(&path).unwrap();
        type Corruption = Box<dyn Fn(&mut Vec<u8>)>;
        let corruptions: [(&str, Corruption, &str); 5] = [
            (
                "random bytes",
                Box::new(|b: &mut Vec<u8>| {
                    let at = b.len() / 2 + 3;
                    for (i, x) in b[at..at + 64].iter_mut().enumerate() {
                        *x ^= 0x5a ^ (i as u8);
                    }
                }),
                "corrupted",
            ),
            (
                "values x 1.5",
                Box::new(|b: &mut Vec<u8>| {
                    for i in 500..510 {
                        let at = HEADER + 8 * i;
                        let v = f64::from_le_bytes(b[at..at + 8].try_into().unwrap()) * 1.5;
                        b[at..at + 8].copy_from_slice(&v.to_le_bytes());
                    }
                }),
                "corrupted",
            ),
            (
                "truncated",
                Box::new(|b: &mut Vec<u8>| b.truncate(b.len() - 8)),
                "truncated",
            ),
            (
                "older format",
                Box::new(|b: &mut Vec<u8>| {
                    b.drain(..HEADER);
                }),
                "no PTSTAB01 header",
            ),
            (
                "empty",
                Box::new(|b: &mut Vec<u8>| b.clear()),
                "no PTSTAB01",
            ),
        ];
        for (i, (what, corrupt, needle)) in corruptions.iter().enumerate() {
            let mut bytes = intact.clone();
            corrupt(&mut bytes);
            std::fs::write(&path, &bytes).unwrap();
            assert_eq!(long_table(&path, &builds, &notes), good, "{what}");
            assert_eq!(builds.load(Ordering::Relaxed), i + 2, "{what}");
            let last = notes.0.lock().unwrap().last().cloned().unwrap_or_default();
            assert!(
                last.contains(needle) && last.contains("rebuilding") && last.contains("t.bin"),
                "{what}: {last}"
            );
            assert_eq!(std::fs::read(&path).unwrap(), intact, "{what}: rewritten");
        }
    }

    #[test]
    fn a_table_that_cannot_be_written_is_used_from_memory() {
        let dir = scratch("unwritable-table");
        let path = dir.join("t.bin");
        // A directory where the table file should be: the rename fails after the build.
        std::fs::create_dir_all(path.join("inside")).unwrap();
        let builds = AtomicUsize::new(0);
        let notes = Notes(Mutex::new(Vec::new()));
        assert_eq!(long_table(&path, &builds, &notes).len(), 1000);
        let notes = notes.0.into_inner().unwrap();
        assert!(
            notes
                .iter()
                .any(|n| n.contains("cannot write") && n.contains("from memory")),
            "{notes:?}"
        );
        let left: Vec<_> = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().into_string().unwrap())
            .filter(|n| n.contains(".tmp"))
            .collect();
        assert!(left.is_empty(), "temporary files left: {left:?}");
    }

    #[test]
    fn an_unwritable_directory_is_an_error_naming_it() {
        let dir = scratch("unwritable");
        std::fs::create_dir_all(&dir).unwrap();
        // A file where the cache directory should be.
        let blocker = dir.join("file");
        std::fs::write(&blocker, "x").unwrap();
        let e = table(&blocker.join("t.bin"), &AtomicUsize::new(0), 1.0).unwrap_err();
        let text = e.to_string();
        assert!(
            text.contains("file")
                && text.contains("cache directory")
                && text.contains("not a directory"),
            "{text}"
        );
    }
}
