//! What a file's name says of its format.

use std::path::Path;

/// The extension of `path`, lowercase, without the dot (`"XYZ"` → `xyz`;
/// empty when there is none or it is not UTF-8): the readers and writers
/// choose formats by it, whatever its case.
pub fn extension(path: &Path) -> String {
    path.extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .unwrap_or_default()
}

/// The first `n` bytes of the file at `path` (fewer, or none, when it is
/// shorter or cannot be read: its reader then says why), for telling
/// formats apart by their magic numbers.
pub fn first_bytes(path: &Path, n: usize) -> Vec<u8> {
    use std::io::Read;
    let mut head = Vec::with_capacity(n);
    if let Ok(f) = std::fs::File::open(path) {
        let _ = f.take(n as u64).read_to_end(&mut head);
    }
    head
}

/// The first 8 bytes of an HDF5 file (at offset 0, 512, 1024, … when the
/// file has a user block, as MATLAB v7.3 files do): flights in the
/// MagNav/SGL layout and netCDF-4 grids are HDF5.
pub const HDF5_SIGNATURE: [u8; 8] = *b"\x89HDF\r\n\x1a\n";

/// Whether the file starts with the HDF5 signature (at 0 or at a user-block
/// offset 512, 1024, …, up to 64 KiB).
pub fn is_hdf5(path: &Path) -> bool {
    use std::io::{Read, Seek, SeekFrom};
    let Ok(mut f) = std::fs::File::open(path) else {
        return false;
    };
    let mut offset = 0u64;
    while offset <= 65_536 {
        let mut sig = [0u8; 8];
        if f.seek(SeekFrom::Start(offset)).is_err() || f.read_exact(&mut sig).is_err() {
            return false;
        }
        if sig == HDF5_SIGNATURE {
            return true;
        }
        offset = if offset == 0 { 512 } else { offset * 2 };
    }
    false
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn extensions_are_lowercase_and_empty_when_absent() {
        assert_eq!(extension(Path::new("a/OUT.XyZ")), "xyz");
        assert_eq!(extension(Path::new("grid.tif")), "tif");
        assert_eq!(extension(Path::new("noext")), "");
        assert_eq!(extension(Path::new(".hidden")), "");
    }
}
