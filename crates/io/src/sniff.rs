//! A look at the start of a file before reading it: emptiness, binary
//! content, byte-order mark, and the first line that is not a comment.

use std::fs::File;
use std::io::Read;
use std::path::Path;

use crate::error::{IoError, Result};

/// The UTF-8 byte-order mark.
pub(crate) const BOM: &[u8] = b"\xEF\xBB\xBF";

/// Bytes examined at first; extended (up to [`MAX_PREFIX`]) until a content line is complete.
const PREFIX: usize = 64 * 1024;
const MAX_PREFIX: usize = 1024 * 1024;

/// The start of a file.
pub(crate) struct Prefix {
    /// Bytes after the BOM (at most about 1 MiB).
    pub bytes: Vec<u8>,
    /// Size of the whole file in bytes.
    pub file_size: u64,
}

/// Reads the start of `path`; errors on a missing/unreadable file, on a
/// UTF-16 byte-order mark and on NUL bytes in the first 64 KiB (binary file).
pub(crate) fn read_prefix(path: &Path) -> Result<Prefix> {
    let file_label = || path.display().to_string();
    let open_err = |source| IoError::Open {
        file: file_label(),
        source,
    };
    let mut f = File::open(path).map_err(open_err)?;
    let meta = f.metadata().map_err(open_err)?;
    if meta.is_dir() {
        return Err(open_err(std::io::Error::other("it is a directory")));
    }
    let mut bytes = Vec::with_capacity(PREFIX);
    let read_err = |source| IoError::Read {
        file: file_label(),
        line: 1,
        source,
    };
    let mut read_chunk = |bytes: &mut Vec<u8>| -> Result<bool> {
        let n = (&mut f)
            .take(PREFIX as u64)
            .read_to_end(bytes)
            .map_err(read_err)?;
        Ok(n < PREFIX)
    };
    let mut eof = read_chunk(&mut bytes)?;
    // Extend until the first content line is complete (very long headers).
    let comment = |l: &[u8]| l.starts_with(b"#") || l.starts_with(b"/");
    while !eof
        && bytes.len() < MAX_PREFIX
        && !first_content_line(&bytes, comment).is_some_and(|(_, _, complete)| complete)
    {
        eof = read_chunk(&mut bytes)?;
    }
    if bytes.starts_with(b"\xFF\xFE") || bytes.starts_with(b"\xFE\xFF") {
        return Err(IoError::Binary {
            file: file_label(),
            line: 1,
            what: "UTF-16 byte-order mark (save the file as UTF-8)".to_string(),
        });
    }
    if let Some(pos) = bytes.iter().take(PREFIX).position(|&b| b == 0) {
        return Err(IoError::Binary {
            file: file_label(),
            line: line_at(&bytes, pos),
            what: "NUL byte".to_string(),
        });
    }
    if bytes.starts_with(BOM) {
        bytes.drain(..BOM.len());
    }
    Ok(Prefix {
        bytes,
        file_size: meta.len(),
    })
}

/// 1-based line number of byte offset `pos`.
pub(crate) fn line_at(bytes: &[u8], pos: usize) -> u64 {
    1 + bytes[..pos].iter().filter(|&&b| b == b'\n').count() as u64
}

/// The first line that is neither blank nor a comment (`is_comment`):
/// `(1-based line number, line without "\r\n", complete)`, where `complete`
/// is false when the line may continue beyond `bytes`.
pub(crate) fn first_content_line(
    bytes: &[u8],
    is_comment: impl Fn(&[u8]) -> bool,
) -> Option<(u64, &[u8], bool)> {
    let mut start = 0;
    let mut line = 1;
    while start < bytes.len() {
        let end = bytes[start..]
            .iter()
            .position(|&b| b == b'\n')
            .map(|p| start + p);
        let raw = &bytes[start..end.unwrap_or(bytes.len())];
        let text = raw.strip_suffix(b"\r").unwrap_or(raw);
        if !text.trim_ascii().is_empty() && !is_comment(text) {
            return Some((line, text, end.is_some()));
        }
        match end {
            Some(e) => start = e + 1,
            None => break,
        }
        line += 1;
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_first_content_line() {
        let b = b"# c\r\n\r\n  \n#x\ntime,mag\r\n1,2\n";
        let (line, text, complete) = first_content_line(b, |l| l.starts_with(b"#")).unwrap();
        assert_eq!((line, text, complete), (5, &b"time,mag"[..], true));
        assert!(first_content_line(b"# only\n\n", |l| l.starts_with(b"#")).is_none());
        let (_, text, complete) = first_content_line(b"a,b", |_| false).unwrap();
        assert_eq!((text, complete), (&b"a,b"[..], false));
        assert_eq!(line_at(b"a\nb\nc", 4), 3);
    }
}
