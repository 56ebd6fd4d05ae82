//! Helpers shared by the fuzz targets.

use std::path::PathBuf;

/// A per-process scratch file in /dev/shm (falls back to the temp dir) that
/// each run overwrites with the fuzz input: the readers take paths.
pub fn scratch(name: &str, data: &[u8]) -> PathBuf {
    use std::sync::OnceLock;
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    let dir = DIR.get_or_init(|| {
        let base = if std::path::Path::new("/dev/shm").is_dir() {
            PathBuf::from("/dev/shm")
        } else {
            std::env::temp_dir()
        };
        let d = base.join(format!("aeromag-fuzz-{}", std::process::id()));
        std::fs::create_dir_all(&d).expect("scratch dir");
        d
    });
    let p = dir.join(name);
    if std::fs::write(&p, data).is_err() {
        // Removed from outside (e.g. /dev/shm cleaned): make it again.
        std::fs::create_dir_all(dir).expect("scratch dir");
        std::fs::write(&p, data).expect("write scratch file");
    }
    p
}
