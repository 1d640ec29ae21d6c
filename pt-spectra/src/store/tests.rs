//! Tests of the table store: checksums, fault injection, locks, failed writes.

use super::*;
use crate::loops::basis::LinearBasis;
use crate::progress::Silent;
use std::fs::{File, TryLockError};
use std::sync::atomic::{AtomicUsize, Ordering};

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("pt-spectra-store-{}-{name}", std::process::id()));
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

/// `table` with notes, run on another thread so that a hang (a FIFO opened for reading) fails the
/// test after two minutes instead of blocking the suite.
fn table_with_notes(path: &Path, builds: &Arc<AtomicUsize>) -> (Vec<f64>, Vec<String>) {
    let (path, builds) = (path.to_path_buf(), Arc::clone(builds));
    let (send, receive) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        let notes = Notes(Mutex::new(Vec::new()));
        let t = cached(
            &path,
            "test",
            |v: &[f64]| (v.len() == 3).then(|| v.to_vec()),
            || {
                builds.fetch_add(1, Ordering::Relaxed);
                vec![4.5; 3]
            },
            Clone::clone,
            &notes,
        )
        .unwrap();
        let _ = send.send((t, notes.0.into_inner().unwrap()));
    });
    receive
        .recv_timeout(std::time::Duration::from_secs(120))
        .expect("the cache hung")
}

/// A cache directory that cannot hold the table never fails the run: the table is built in memory
/// and a note names the path and the reason. Tests run as root, which ignores permission bits, so
/// the unwritable directories are ones no one can write: a path under a regular file (ENOTDIR) and,
/// on Linux, `/proc/self`, an existing directory where no file can be created (the lock file fails
/// there, as in a read-only directory).
#[test]
fn an_unusable_cache_directory_is_used_from_memory_with_a_note() {
    let dir = scratch("unwritable");
    std::fs::create_dir_all(&dir).unwrap();
    // A file where the cache directory should be.
    let blocker = dir.join("file");
    std::fs::write(&blocker, "x").unwrap();
    let mut paths = vec![blocker.join("t.bin"), blocker.join("sub/t.bin")];
    if Path::new("/proc/self/status").is_file() {
        paths.push(PathBuf::from("/proc/self/pt-spectra-t.bin"));
    }
    for path in paths {
        let builds = Arc::new(AtomicUsize::new(0));
        let (t, notes) = table_with_notes(&path, &builds);
        assert_eq!(t, vec![4.5; 3], "{}", path.display());
        assert_eq!(builds.load(Ordering::Relaxed), 1);
        let parent = path.parent().unwrap().display().to_string();
        assert!(
            notes.len() == 1
                && notes[0].contains("from memory")
                && (notes[0].contains(&parent)
                    || notes[0].contains(&blocker.display().to_string())),
            "{}: {notes:?}",
            path.display()
        );
    }
    assert_eq!(std::fs::read_to_string(&blocker).unwrap(), "x");
}

/// Makes a FIFO at `path` with `mkfifo`.
#[cfg(unix)]
fn mkfifo(path: &Path) {
    let status = std::process::Command::new("mkfifo")
        .arg(path)
        .status()
        .expect("mkfifo");
    assert!(status.success());
}

/// A FIFO in place of a table file is not read (that would wait for a writer forever): it is
/// reported and replaced by the table; a FIFO in place of the lock file means a table built in
/// memory, with a note.
#[cfg(unix)]
#[test]
fn a_fifo_in_place_of_a_cache_file_never_hangs() {
    use std::os::unix::fs::FileTypeExt;
    let dir = scratch("fifo");
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("t.bin");
    mkfifo(&path);
    let builds = Arc::new(AtomicUsize::new(0));
    let (t, notes) = table_with_notes(&path, &builds);
    assert_eq!(t, vec![4.5; 3]);
    assert!(
        notes.len() == 1 && notes[0].contains("not a regular file") && notes[0].contains("t.bin"),
        "{notes:?}"
    );
    assert!(std::fs::metadata(&path).unwrap().is_file());
    let (again, _) = table_with_notes(&path, &builds);
    assert_eq!((again, builds.load(Ordering::Relaxed)), (vec![4.5; 3], 1));
    // A FIFO as the lock file (and no table yet).
    let other = dir.join("u.bin");
    mkfifo(&other.with_extension("lock"));
    let (t, notes) = table_with_notes(&other, &builds);
    assert_eq!(t, vec![4.5; 3]);
    assert!(
        notes.len() == 1
            && notes[0].contains("u.lock")
            && notes[0].contains("not a regular file")
            && notes[0].contains("from memory"),
        "{notes:?}"
    );
    assert!(std::fs::metadata(other.with_extension("lock"))
        .unwrap()
        .file_type()
        .is_fifo());
    // The read-only path (cached tensors, never built) reports it too.
    let notes = Notes(Mutex::new(Vec::new()));
    let none = read_cached(&dir.join("u.lock"), "test tensors", &notes, |v| {
        Some(v.to_vec())
    });
    assert!(none.is_none());
    let notes = notes.0.into_inner().unwrap();
    assert!(notes[0].contains("not a regular file"), "{notes:?}");
}

/// A tensor file with a valid checksum but a crafted basis size (one whose product with the lattice
/// length wraps to 2048, which panicked when the basis was sliced) is rebuilt with a note naming the
/// file, never a panic.
#[test]
fn a_crafted_basis_size_with_a_valid_checksum_is_rebuilt() {
    use crate::loops::lattice::Lattice;
    let dir = scratch("crafted");
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("basis.bin");
    let lattice = Lattice::new(1e-5, 1e3, 0.05);
    let n = crate::loops::basis::wrapping_basis_size(lattice.len);
    let mut values = vec![n];
    values.extend(vec![1.0; lattice.len + 4096]);
    file::write_f64s(&path, &values).unwrap();
    let notes = Notes(Mutex::new(Vec::new()));
    let n = cached(
        &path,
        "crafted basis",
        |v: &[f64]| LinearBasis::from_f64s(lattice.clone(), v).map(|(b, _)| b.len()),
        || 0,
        |_| vec![0.0],
        &notes,
    )
    .unwrap();
    assert_eq!(n, 0, "built, not read");
    let notes = notes.0.into_inner().unwrap();
    assert!(
        notes[0].contains("basis.bin") && notes[0].contains("consistency checks"),
        "{notes:?}"
    );
}
