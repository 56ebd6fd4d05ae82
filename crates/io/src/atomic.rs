//! Output files that never lie: every file is written to a temporary name
//! in its target folder and renamed over the target when complete, so an
//! interrupted command (an error, Ctrl-C, SIGTERM, a full disk) never leaves
//! a complete-looking partial file.
//!
//! - [`write_atomically`] / [`write_file`]: write through a temporary
//!   `.NAME.PID.N.tmp` beside the target, then rename (atomic on one file
//!   system); on any error the temporary is removed.
//! - [`write_files`]: several files as a set: all written to temporaries
//!   first, then renamed one right after another.
//! - The temporaries being written are registered; [`remove_temporaries`]
//!   deletes them (the command-line program calls it on SIGINT/SIGTERM
//!   before exiting with 130/143).
//! - [`check_writable`]: before a command starts its work, make sure an
//!   output's folder exists (it is created) and takes a file.
//!
//! ```
//! let dir = std::env::temp_dir().join(format!("aeromag-atomic-doc-{}", std::process::id()));
//! let path = dir.join("sub/out.txt");
//! aeromag_io::atomic::check_writable(&path)?; // creates `sub/`
//! aeromag_io::atomic::write_file(&path, b"done\n")?;
//! assert_eq!(std::fs::read(&path)?, b"done\n");
//! # std::fs::remove_dir_all(&dir)?;
//! # Ok::<(), std::io::Error>(())
//! ```

use aeromag_core::output_target::{OutputTarget, output_target};
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};

/// Temporaries being written (removed by [`remove_temporaries`]).
static TEMPORARIES: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());
/// Counter that makes temporary names unique within the process.
static COUNTER: AtomicU64 = AtomicU64::new(0);
/// Set by [`remove_temporaries`]: no file is completed after it.
static INTERRUPTED: AtomicBool = AtomicBool::new(false);

/// The folder of `path` (`.` for a bare file name).
fn folder(path: &Path) -> &Path {
    match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    }
}

/// A new temporary name beside `path`, registered.
fn temporary(path: &Path) -> PathBuf {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "out".into());
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    let tmp = folder(path).join(format!(".{name}.{}.{n}.tmp", std::process::id()));
    lock().push(tmp.clone());
    tmp
}

fn lock() -> std::sync::MutexGuard<'static, Vec<PathBuf>> {
    // A panic while holding the lock leaves the list usable.
    TEMPORARIES.lock().unwrap_or_else(|e| e.into_inner())
}

fn unregister(tmp: &Path) {
    lock().retain(|p| p != tmp);
}

/// Writes `path` through a registered temporary beside it: `write` fills a
/// buffered writer ([`Output`]), which is flushed and synced, then the
/// temporary is renamed to `path`. On any error the temporary is removed
/// and `path` is left as it was. A symbolic link is followed (the file it
/// names is written); a device, FIFO or socket (`/dev/null`, a pipe) is
/// written directly ([`output_target`]).
pub fn write_atomically(
    path: &Path,
    write: impl FnOnce(&mut BufWriter<Output>) -> std::io::Result<()>,
) -> std::io::Result<()> {
    not_interrupted()?;
    let path = match output_target(path)? {
        // A device, FIFO or socket is written as it is: a rename would
        // replace it by a regular file.
        OutputTarget::Stream(p) => return write_stream(&p, write),
        OutputTarget::File(p) => p,
    };
    let path = path.as_path();
    let tmp = temporary(path);
    let result = write_temporary(&tmp, write).and_then(|()| {
        not_interrupted()?;
        std::fs::rename(&tmp, path)
    });
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    unregister(&tmp);
    result
}

/// An error once [`remove_temporaries`] has run: no file is completed
/// after it.
fn not_interrupted() -> std::io::Result<()> {
    if INTERRUPTED.load(Ordering::SeqCst) {
        Err(std::io::Error::new(
            std::io::ErrorKind::Interrupted,
            "interrupted",
        ))
    } else {
        Ok(())
    }
}

/// Write a device, FIFO or socket `p` directly through `write`.
fn write_stream(
    p: &Path,
    write: impl FnOnce(&mut BufWriter<Output>) -> std::io::Result<()>,
) -> std::io::Result<()> {
    let f = std::fs::OpenOptions::new().write(true).open(p)?;
    let mut w = BufWriter::with_capacity(1 << 20, Output::new(f));
    write(&mut w)?;
    w.flush()
}

/// Create the temporary `tmp`, fill it through `write`, flush and sync it.
fn write_temporary(
    tmp: &Path,
    write: impl FnOnce(&mut BufWriter<Output>) -> std::io::Result<()>,
) -> std::io::Result<()> {
    let f = File::create(tmp)?;
    let mut w = BufWriter::with_capacity(1 << 20, Output::new(f));
    write(&mut w)?;
    w.flush()?;
    let f = w.into_inner().map_err(|e| e.into_error())?.file;
    f.sync_all()
}

/// Writes several files as one set: every target is checked first
/// ([`check_writable`]: not a folder, its folder takes a file), then each
/// is written to a registered temporary beside it (flushed and synced),
/// and only when all are complete are the temporaries renamed over their
/// targets, one right after another (microseconds apart, where writing
/// them one by one left seconds between the first and the last). An error
/// or an interruption ([`remove_temporaries`]) before the renames removes
/// every temporary and leaves every target as it was; only a failure of a
/// rename itself leaves the earlier targets replaced. Devices, FIFOs and
/// sockets (`/dev/null`) are written directly, before the renames.
///
/// Errors name the path that failed.
pub fn write_files(files: &[(&Path, &[u8])]) -> Result<(), (PathBuf, std::io::Error)> {
    let at = |p: &Path| {
        let p = p.to_path_buf();
        move |e| (p, e)
    };
    for &(path, _) in files {
        check_writable(path).map_err(at(path))?;
    }
    let mut staged: Vec<(PathBuf, PathBuf)> = Vec::with_capacity(files.len());
    let mut stage = || -> Result<(), (PathBuf, std::io::Error)> {
        for &(path, bytes) in files {
            not_interrupted().map_err(at(path))?;
            match output_target(path).map_err(at(path))? {
                OutputTarget::Stream(p) => {
                    write_stream(&p, |w| w.write_all(bytes)).map_err(at(path))?;
                }
                OutputTarget::File(target) => {
                    let tmp = temporary(&target);
                    staged.push((tmp.clone(), target));
                    write_temporary(&tmp, |w| w.write_all(bytes)).map_err(at(path))?;
                }
            }
        }
        not_interrupted().map_err(at(files.last().map_or(Path::new("."), |f| f.0)))
    };
    let mut result = stage();
    let mut renamed = 0;
    if result.is_ok() {
        for (tmp, target) in &staged {
            if let Err(e) = std::fs::rename(tmp, target) {
                result = Err((target.clone(), e));
                break;
            }
            renamed += 1;
        }
    }
    for (tmp, _) in &staged[renamed..] {
        let _ = std::fs::remove_file(tmp);
    }
    for (tmp, _) in &staged {
        unregister(tmp);
    }
    result
}

/// Writes `bytes` to `path` atomically ([`write_atomically`]).
pub fn write_file(path: &Path, bytes: impl AsRef<[u8]>) -> std::io::Result<()> {
    write_atomically(path, |w| w.write_all(bytes.as_ref()))
}

/// Removes every temporary still being written and stops any file from
/// being completed afterwards; returns how many were removed. For a signal
/// handler (the process exits right after).
pub fn remove_temporaries() -> usize {
    INTERRUPTED.store(true, Ordering::SeqCst);
    let list = std::mem::take(&mut *lock());
    list.iter()
        .filter(|p| std::fs::remove_file(p).is_ok())
        .count()
}

/// Checks, before any work, that `path` can be written: its folder is
/// created if missing, must be a folder, and must take a new file (a probe
/// file is created and removed); `path` itself must not be a folder.
/// Symbolic links are followed; a device, FIFO or socket passes (it is
/// written directly).
pub fn check_writable(path: &Path) -> std::io::Result<()> {
    let err = |kind, msg: String| std::io::Error::new(kind, msg);
    let path = match output_target(path)? {
        OutputTarget::Stream(_) => return Ok(()),
        OutputTarget::File(p) => p,
    };
    let path = path.as_path();
    if path.is_dir() {
        return Err(err(
            std::io::ErrorKind::IsADirectory,
            "is a folder, expected a file name".into(),
        ));
    }
    let dir = folder(path);
    if !dir.exists() {
        std::fs::create_dir_all(dir)?;
    } else if !dir.is_dir() {
        return Err(err(
            std::io::ErrorKind::NotADirectory,
            format!("'{}' is not a folder", dir.display()),
        ));
    }
    let probe = temporary(path);
    let made = File::create(&probe);
    let _ = std::fs::remove_file(&probe);
    unregister(&probe);
    made.map(|_| ())
}

/// Checks that folder `dir` exists (created if missing) and takes new files.
pub fn check_writable_folder(dir: &Path) -> std::io::Result<()> {
    check_writable(&dir.join(".aeromag-probe"))
}

/// For the crate's tests that write files atomically: they run one at a
/// time, since one of them sets the process-wide interruption flag, which
/// fails any other write meanwhile (`cargo test` runs a crate's tests as
/// threads of one process).
#[cfg(test)]
pub(crate) fn serial() -> std::sync::MutexGuard<'static, ()> {
    static SERIAL: Mutex<()> = Mutex::new(());
    SERIAL.lock().unwrap_or_else(|e| e.into_inner())
}

/// The temporary file that [`write_atomically`] hands out (through a
/// `BufWriter`): a file that starts the disk write of every
/// [`WRITEBACK_BYTES`] written as it goes (Linux: `sync_file_range` with
/// `SYNC_FILE_RANGE_WRITE`, which starts the write and does not wait for
/// it), so the sync before the rename waits for the last part only.
///
/// `compensate` of 10⁶ rows (94 MB) with the CSV writer's formatting of the
/// next rows meanwhile: the write and sync 140 → 110 ms (the sync alone
/// 40 → 1 ms). The durability is the sync's, as before; a failed start of
/// a write is left to the sync to report.
pub struct Output {
    file: File,
    /// Bytes written so far.
    written: u64,
    /// Bytes whose disk write has been started.
    started: u64,
}

/// Bytes between two starts of a disk write ([`Output`]).
pub const WRITEBACK_BYTES: u64 = 8 << 20;

impl Output {
    fn new(file: File) -> Self {
        Self {
            file,
            written: 0,
            started: 0,
        }
    }

    /// Starts the disk write of the bytes written since the last start.
    fn start_writeback(&mut self) {
        #[cfg(target_os = "linux")]
        {
            use std::os::fd::AsRawFd;
            let (from, len) = (self.started as libc::off64_t, self.written - self.started);
            // SAFETY: a call on this open file's descriptor with plain
            // integers; it reads no memory of ours.
            unsafe {
                libc::sync_file_range(
                    self.file.as_raw_fd(),
                    from,
                    len as libc::off64_t,
                    libc::SYNC_FILE_RANGE_WRITE,
                );
            }
        }
        self.started = self.written;
    }
}

impl Write for Output {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        let n = self.file.write(buf)?;
        self.written += n as u64;
        if self.written - self.started >= WRITEBACK_BYTES {
            self.start_writeback();
        }
        Ok(n)
    }

    fn flush(&mut self) -> std::io::Result<()> {
        self.file.flush()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A fresh folder of the test's own, removed when the test ends (they
    /// were left in the system's temporary folder, three per run).
    struct Dir(PathBuf);

    impl std::ops::Deref for Dir {
        type Target = Path;
        fn deref(&self) -> &Path {
            &self.0
        }
    }

    impl Drop for Dir {
        fn drop(&mut self) {
            let _ = std::fs::remove_dir_all(&self.0);
        }
    }

    fn dir(name: &str) -> Dir {
        let d = std::env::temp_dir().join(format!("aeromag-atomic-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        Dir(d)
    }

    fn entries(d: &Path) -> Vec<String> {
        let mut v: Vec<String> = std::fs::read_dir(d)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    }

    /// A file written in pieces of odd sizes across several starts of its
    /// disk write ([`Output`]) holds every byte, in order.
    #[test]
    fn a_file_longer_than_the_writeback_step_is_written_whole() {
        let _serial = serial();
        let d = dir("writeback");
        let p = d.join("big.bin");
        let len = 2 * WRITEBACK_BYTES as usize + 12_345;
        let bytes: Vec<u8> = (0..len).map(|i| (i * 7 % 251) as u8).collect();
        write_atomically(&p, |w| {
            let mut rest = &bytes[..];
            let mut k = 0;
            while !rest.is_empty() {
                let n = rest.len().min([1, 4095, 1 << 20, 3 << 20][k % 4]);
                w.write_all(&rest[..n])?;
                rest = &rest[n..];
                k += 1;
            }
            Ok(())
        })
        .unwrap();
        assert!(std::fs::read(&p).unwrap() == bytes);
        assert_eq!(entries(&d), ["big.bin"]);
        std::fs::remove_dir_all(&*d).unwrap();
    }

    #[test]
    fn a_failed_write_leaves_the_old_file_and_no_temporary() {
        let _serial = serial();
        let d = dir("fail");
        let p = d.join("out.csv");
        write_file(&p, "old").unwrap();
        let e = write_atomically(&p, |w| {
            w.write_all(b"partial")?;
            Err(std::io::Error::other("disk full"))
        })
        .unwrap_err();
        assert_eq!(e.to_string(), "disk full");
        assert_eq!(std::fs::read_to_string(&p).unwrap(), "old");
        assert_eq!(entries(&d), ["out.csv"]);
    }

    /// A set of files is replaced whole or not at all: with a folder in
    /// place of the last file, none of the earlier ones is replaced and
    /// no temporary is left (`em study` into a folder of an earlier study
    /// left old and new files mixed when interrupted).
    #[test]
    fn a_set_of_files_is_replaced_whole_or_not_at_all() {
        let _serial = serial();
        let d = dir("set");
        let names = ["a.json", "b.json", "c.html"];
        let paths: Vec<PathBuf> = names.iter().map(|n| d.join(n)).collect();
        let set = |text: &'static str| -> Vec<(&Path, &[u8])> {
            paths
                .iter()
                .map(|p| (p.as_path(), text.as_bytes()))
                .collect()
        };
        write_files(&set("old")).unwrap();
        std::fs::remove_file(&paths[2]).unwrap();
        std::fs::create_dir(&paths[2]).unwrap();
        let (at, e) = write_files(&set("new")).unwrap_err();
        assert_eq!(at, paths[2]);
        assert_eq!(e.kind(), std::io::ErrorKind::IsADirectory, "{e}");
        for p in &paths[..2] {
            assert_eq!(
                std::fs::read_to_string(p).unwrap(),
                "old",
                "{}",
                p.display()
            );
        }
        assert_eq!(entries(&d), names);
        std::fs::remove_dir(&paths[2]).unwrap();
        write_files(&set("new")).unwrap();
        for p in &paths {
            assert_eq!(std::fs::read_to_string(p).unwrap(), "new");
        }
        assert_eq!(entries(&d), names);
    }

    #[test]
    fn temporaries_in_progress_are_removed_on_request() {
        let _serial = serial();
        let d = dir("signal");
        let p = d.join("big.csv");
        write_atomically(&p, |w| {
            w.write_all(b"half")?;
            w.flush()?;
            assert_eq!(entries(&d).len(), 1, "the temporary exists while writing");
            // What the signal handler does mid-write.
            assert!(remove_temporaries() >= 1);
            assert!(entries(&d).is_empty());
            Ok(())
        })
        .unwrap_err(); // nothing is completed after an interruption
        assert!(entries(&d).is_empty(), "{:?}", entries(&d));
        assert!(write_file(&p, "x").is_err());
        assert!(entries(&d).is_empty());
        INTERRUPTED.store(false, Ordering::SeqCst); // for the other tests
    }

    #[test]
    fn check_writable_creates_folders_and_rejects_folders_and_files_as_folders() {
        let _serial = serial();
        let d = dir("check");
        check_writable(&d.join("a/b/out.json")).unwrap();
        assert!(d.join("a/b").is_dir());
        assert!(entries(&d.join("a/b")).is_empty(), "the probe is removed");
        assert!(check_writable(&d.join("a")).is_err());
        write_file(&d.join("f"), "x").unwrap();
        assert!(check_writable(&d.join("f/out.csv")).is_err());
        check_writable_folder(&d.join("report")).unwrap();
        assert!(d.join("report").is_dir());
    }
}
