//! Where an output file goes: the writers of every crate write a regular
//! file through a temporary renamed over it (atomic), which must neither
//! replace a device, a FIFO or a socket nor a symbolic link by a regular
//! file.
//!
//! Found by fuzzing: `--out /dev/full` replaced the system's `/dev/full`
//! with a regular file and reported success (run as root, `/dev/null`
//! likewise), and an output path that was a symbolic link became a
//! regular file instead of writing the file the link names.
//!
//! ```
//! use aeromag_core::output_target::{OutputTarget, output_target};
//! # #[cfg(unix)]
//! assert_eq!(
//!     output_target(std::path::Path::new("/dev/null"))?,
//!     OutputTarget::Stream("/dev/null".into())
//! );
//! let new = std::env::temp_dir().join("aeromag-doc-not-there.csv");
//! assert_eq!(output_target(&new)?, OutputTarget::File(new.clone()));
//! # Ok::<(), std::io::Error>(())
//! ```

use std::path::{Path, PathBuf};

/// Symbolic links followed before giving up (as Linux's `ELOOP`).
pub const MAX_LINKS: usize = 40;

/// What an output path names.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum OutputTarget {
    /// A regular file, existing or not, after following symbolic links:
    /// written through a temporary beside it and renamed over it.
    File(PathBuf),
    /// An existing device, FIFO or socket (`/dev/null`, `/dev/stdout`, a
    /// pipe): written directly, with neither temporary nor rename, which
    /// would replace it.
    Stream(PathBuf),
}

/// The target of output `path` ([`OutputTarget`]), symbolic links followed
/// (a dangling link names the file to create). Errors: a link loop or
/// chain longer than [`MAX_LINKS`], and the errors of reading the links.
pub fn output_target(path: &Path) -> std::io::Result<OutputTarget> {
    // What the path opens, links followed by the system: `/dev/stdout`
    // reaches a pipe through `/proc/self/fd/1`, a link whose text
    // (`pipe:[…]`) names no file.
    if let Ok(m) = std::fs::metadata(path) {
        let kind = m.file_type();
        if !kind.is_file() && !kind.is_dir() {
            return Ok(OutputTarget::Stream(path.to_path_buf()));
        }
    }
    let mut p = path.to_path_buf();
    for _ in 0..MAX_LINKS {
        let meta = match std::fs::symlink_metadata(&p) {
            Ok(m) => m,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
                return Ok(OutputTarget::File(p));
            }
            Err(e) => return Err(e),
        };
        let kind = meta.file_type();
        if kind.is_symlink() {
            let link = std::fs::read_link(&p)?;
            p = match p.parent() {
                Some(dir) => dir.join(link),
                None => link,
            };
            continue;
        }
        return Ok(if kind.is_file() || kind.is_dir() {
            // A folder is the callers' error to name.
            OutputTarget::File(p)
        } else {
            OutputTarget::Stream(p)
        });
    }
    Err(std::io::Error::other(format!(
        "more than {MAX_LINKS} symbolic links to follow from '{}' (a loop?)",
        path.display()
    )))
}

/// Whether `a` and `b` name the same existing file (the same device and
/// inode on Unix; the same canonical path elsewhere). `false` when either
/// does not exist.
pub fn same_file(a: &Path, b: &Path) -> bool {
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        match (std::fs::metadata(a), std::fs::metadata(b)) {
            (Ok(x), Ok(y)) => x.dev() == y.dev() && x.ino() == y.ino(),
            _ => false,
        }
    }
    #[cfg(not(unix))]
    {
        match (std::fs::canonicalize(a), std::fs::canonicalize(b)) {
            (Ok(x), Ok(y)) => x == y,
            _ => false,
        }
    }
}

#[cfg(all(test, unix))]
mod tests {
    use super::*;

    fn dir(name: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("aeromag-target-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    #[test]
    fn links_are_followed_and_special_files_are_streams() {
        let d = dir("links");
        let file = d.join("a.csv");
        std::fs::write(&file, "x").unwrap();
        std::os::unix::fs::symlink("a.csv", d.join("l1")).unwrap();
        std::os::unix::fs::symlink(d.join("l1"), d.join("l2")).unwrap();
        assert_eq!(
            output_target(&d.join("l2")).unwrap(),
            OutputTarget::File(d.join("a.csv"))
        );
        // A dangling link names the file to create.
        std::os::unix::fs::symlink("new.csv", d.join("dangling")).unwrap();
        assert_eq!(
            output_target(&d.join("dangling")).unwrap(),
            OutputTarget::File(d.join("new.csv"))
        );
        // A loop is an error naming the path.
        std::os::unix::fs::symlink("loop2", d.join("loop1")).unwrap();
        std::os::unix::fs::symlink("loop1", d.join("loop2")).unwrap();
        let e = output_target(&d.join("loop1")).unwrap_err();
        assert!(e.to_string().contains("loop1"), "{e}");
        // Devices and links to them are streams, opened by the name given.
        assert_eq!(
            output_target(Path::new("/dev/null")).unwrap(),
            OutputTarget::Stream("/dev/null".into())
        );
        std::os::unix::fs::symlink("/dev/null", d.join("null")).unwrap();
        assert_eq!(
            output_target(&d.join("null")).unwrap(),
            OutputTarget::Stream(d.join("null"))
        );
        // A pipe reached through /proc's fd links (what /dev/stdout is when
        // the output is piped): a stream.
        let (r, w) = std::io::pipe().unwrap();
        let fd = std::os::fd::AsRawFd::as_raw_fd(&w);
        let via_proc = PathBuf::from(format!("/proc/self/fd/{fd}"));
        if via_proc.exists() {
            assert_eq!(
                output_target(&via_proc).unwrap(),
                OutputTarget::Stream(via_proc.clone())
            );
        }
        drop((r, w));
        assert!(same_file(&d.join("l2"), &file));
        assert!(!same_file(&d.join("new.csv"), &file));
        std::fs::remove_dir_all(&d).unwrap();
    }
}
