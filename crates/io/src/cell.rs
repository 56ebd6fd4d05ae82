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
    if let Some(v) = plain_decimal(b) {
        return Ok(Cell::Value(v));
    }
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

/// Powers of ten exactly representable as `f64` (10²² is the last).
pub(crate) const EXACT_POWERS_OF_TEN: [f64; 23] = [
    1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15, 1e16,
    1e17, 1e18, 1e19, 1e20, 1e21, 1e22,
];

/// The value of the most common cell, a plain decimal (`-1234.5678`:
/// optional sign, digits, optional point and digits, no exponent), when it
/// is exactly `m / 10^k` with `m < 2⁵³` and `k ≤ 22`; `None` sends the cell
/// to the general parser.
///
/// Both `m` and `10^k` are then exact in `f64` and IEEE division rounds
/// correctly, so the result is the correctly rounded value, the bits
/// `str::parse::<f64>` gives (Clinger 1990, "How to read floating point
/// numbers accurately", the fast path); it skips the UTF-8 check and the
/// general algorithm, which were a third of reading a flight file.
#[inline]
fn plain_decimal(b: &[u8]) -> Option<f64> {
    plain_decimal_prefix(b)
        .filter(|&(_, _, len)| len == b.len())
        .map(|(v, _, _)| v)
}

/// The plain decimal at the start of `b` (it ends at the first byte that
/// cannot continue it): its value as [`plain_decimal`] gives it, whether it
/// is written as an integer (no point, at most 15 digits: the
/// [`crate::builder`]'s integer flag), and its length in bytes. `None` when
/// it has no digit, more than 19 digits, `m ≥ 2⁵³` or `k > 22`.
#[inline]
pub(crate) fn plain_decimal_prefix(b: &[u8]) -> Option<(f64, bool, usize)> {
    let (negative, mut i) = match b.first() {
        Some(b'-') => (true, 1),
        Some(b'+') => (false, 1),
        _ => (false, 0),
    };
    // Wrapping: a run of more than 19 digits is rejected below.
    let mut m: u64 = 0;
    let int_start = i;
    while let Some(d) = b.get(i).map(|c| c.wrapping_sub(b'0')).filter(|d| *d < 10) {
        m = m.wrapping_mul(10).wrapping_add(u64::from(d));
        i += 1;
    }
    let int_digits = i - int_start;
    let mut k = 0;
    let point = b.get(i) == Some(&b'.');
    if point {
        i += 1;
        let frac_start = i;
        while let Some(d) = b.get(i).map(|c| c.wrapping_sub(b'0')).filter(|d| *d < 10) {
            m = m.wrapping_mul(10).wrapping_add(u64::from(d));
            i += 1;
        }
        k = i - frac_start;
    }
    let digits = int_digits + k;
    if digits == 0 || digits > 19 || m >= 1 << 53 || k >= EXACT_POWERS_OF_TEN.len() {
        return None;
    }
    let v = m as f64 / EXACT_POWERS_OF_TEN[k];
    let integer = !point && digits <= 15;
    Some((if negative { -v } else { v }, integer, i))
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

    proptest::proptest! {
        /// The plain-decimal fast path gives the bits of the general parser
        /// for any digits, point position and sign it accepts.
        #[test]
        fn plain_decimals_read_as_the_general_parser(
            m in 0u64..(1u64 << 53),
            point in 0usize..25,
            negative: bool,
            zeros in 0usize..4,
        ) {
            let digits = format!("{}{m}", "0".repeat(zeros));
            let text = if point == 0 {
                digits.clone()
            } else if point >= digits.len() {
                format!(".{}{digits}", "0".repeat(point - digits.len()))
            } else {
                let (a, b) = digits.split_at(digits.len() - point);
                format!("{a}.{b}")
            };
            let text = if negative { format!("-{text}") } else { text };
            let want: f64 = text.parse().unwrap();
            match parse_cell(text.as_bytes()) {
                Ok(Cell::Value(x)) => proptest::prop_assert_eq!(x.to_bits(), want.to_bits(), "{}", text),
                other => proptest::prop_assert!(false, "{}: {:?}", text, other),
            }
        }
    }

    #[test]
    fn plain_decimal_edges() {
        for text in [
            "0",
            "-0",
            "5.",
            ".5",
            "-.5",
            "9007199254740991",
            "1234567.891",
        ] {
            let want: f64 = text.parse().unwrap();
            assert_eq!(
                plain_decimal(text.as_bytes()).map(f64::to_bits),
                Some(want.to_bits()),
                "{text}"
            );
        }
        // Left to the general parser: too many digits, exponents, odd forms.
        for text in [
            "9007199254740993",
            "12345678901234567890",
            "1e5",
            ".",
            "-",
            "",
            "1.2.3",
            "0x1",
            "1_000",
        ] {
            assert_eq!(plain_decimal(text.as_bytes()), None, "{text}");
        }
        assert_eq!(
            parse_cell(b"9007199254740993"),
            Ok(Cell::Value(9007199254740992.0))
        );
        assert_eq!(parse_cell(b"."), Err(CellError::NotNumber));
        assert_eq!(parse_cell(b"-"), Err(CellError::NotNumber));
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
