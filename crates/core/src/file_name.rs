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
