//! Parsing of one table cell into a number or a missing marker.
//!
//! A cell is trimmed of ASCII whitespace, then:
//! - empty → missing ([`Missing::blank`](crate::Missing));
//! - `NaN` in any case, optionally signed → missing (`nan`);
//! - `*` → missing (`dummy`, the Geosoft convention);
//! - otherwise Rust's `f64` syntax: `12`, `+5`, `-1.5`, `.5`, `5.`, `1e-3`,
//!   `1E+3`, `inf`, `-infinity`. The parser is exact (correctly rounded), so
//!   the shortest round-trip text written by [`write_csv`](crate::write_csv)
//!   reads back bit for bit.

/// A parsed cell.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Cell {
    Value(f64),
    Missing(MissingKind),
}

/// Why a cell is missing.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum MissingKind {
    Blank,
    Nan,
    Dummy,
}

/// Why a cell is not a number.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum CellError {
    /// Valid UTF-8 text that is not a number.
    NotNumber,
    /// A NUL byte (binary data).
    Nul,
    /// Invalid UTF-8.
    NotUtf8,
}

/// Parses one cell (see the module docs).
#[inline]
pub(crate) fn parse_cell(bytes: &[u8]) -> Result<Cell, CellError> {
    let b = bytes.trim_ascii();
    match b {
        [] => return Ok(Cell::Missing(MissingKind::Blank)),
        [b'*'] => return Ok(Cell::Missing(MissingKind::Dummy)),
        _ => {}
    }
    let unsigned = match b {
        [b'+' | b'-', rest @ ..] => rest,
        _ => b,
    };
    if unsigned.eq_ignore_ascii_case(b"nan") {
        return Ok(Cell::Missing(MissingKind::Nan));
    }
    match std::str::from_utf8(b) {
        Ok(s) => s
            .parse::<f64>()
            .map(Cell::Value)
            .map_err(|_| text_error(bytes)),
        Err(_) => Err(text_error(bytes)),
    }
}

/// Classifies a cell that is not a number: binary or plain text.
pub(crate) fn text_error(bytes: &[u8]) -> CellError {
    if bytes.contains(&0) {
        CellError::Nul
    } else if std::str::from_utf8(bytes).is_err() {
        CellError::NotUtf8
    } else {
        CellError::NotNumber
    }
}

/// Checks a text cell: valid UTF-8 without NUL bytes.
pub(crate) fn check_text(bytes: &[u8]) -> Result<&str, CellError> {
    if bytes.contains(&0) {
        return Err(CellError::Nul);
    }
    std::str::from_utf8(bytes).map_err(|_| CellError::NotUtf8)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_in_many_spellings() {
        let cases: [(&str, f64); 9] = [
            ("12", 12.0),
            (" 12 ", 12.0),
            ("+5", 5.0),
            ("1e-3", 1e-3),
            ("1E+3", 1e3),
            ("-.5", -0.5),
            ("5.", 5.0),
            ("\t-0.0\t", -0.0),
            ("inf", f64::INFINITY),
        ];
        for (text, v) in cases {
            match parse_cell(text.as_bytes()) {
                Ok(Cell::Value(x)) => assert_eq!(x.to_bits(), v.to_bits(), "{text}"),
                other => panic!("{text}: {other:?}"),
            }
        }
    }

    #[test]
    fn missing_markers() {
        for (text, kind) in [
            ("", MissingKind::Blank),
            ("   ", MissingKind::Blank),
            ("NaN", MissingKind::Nan),
            ("nan", MissingKind::Nan),
            ("-NAN", MissingKind::Nan),
            (" * ", MissingKind::Dummy),
        ] {
            assert_eq!(
                parse_cell(text.as_bytes()),
                Ok(Cell::Missing(kind)),
                "{text:?}"
            );
        }
    }

    #[test]
    fn errors_are_classified() {
        assert_eq!(parse_cell(b"abc"), Err(CellError::NotNumber));
        assert_eq!(parse_cell(b"1,5"), Err(CellError::NotNumber));
        assert_eq!(parse_cell(b"**"), Err(CellError::NotNumber));
        assert_eq!(parse_cell(b"1\x002"), Err(CellError::Nul));
        assert_eq!(parse_cell(b"\xff\xfe"), Err(CellError::NotUtf8));
        assert_eq!(check_text(b"F-1001"), Ok("F-1001"));
        assert_eq!(check_text(b"a\x00"), Err(CellError::Nul));
    }
}
