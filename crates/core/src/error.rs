//! The error type of `aeromag-core`.

/// Everything that can go wrong in `aeromag-core`.
///
/// Functions return an error instead of panicking on bad input (NaN,
/// empty series, impossible filter specifications, out-of-range dates).
#[derive(Debug, thiserror::Error, Clone, PartialEq)]
#[non_exhaustive]
pub enum CoreError {
    /// An argument is outside its valid domain.
    #[error("invalid argument `{name}`: {reason}")]
    InvalidArgument { name: &'static str, reason: String },
    /// A series contains a non-finite value where none is allowed.
    #[error("non-finite value in `{name}` at index {index}")]
    NonFinite { name: &'static str, index: usize },
    /// A series is too short for the requested operation.
    #[error("`{name}` has {len} samples; at least {min} are needed")]
    TooShort {
        name: &'static str,
        len: usize,
        min: usize,
    },
    /// A date lies outside the validity of a model.
    #[error("date {year:.3} is outside the model's validity {first:.1}–{last:.1}")]
    DateOutOfRange { year: f64, first: f64, last: f64 },
    /// A coefficient or data file could not be parsed.
    #[error("cannot parse {what}: {reason}")]
    Parse { what: &'static str, reason: String },
}

impl CoreError {
    /// Whether the caller's input caused the error. Every variant here
    /// says what was wrong with an argument, a series, a date or a file to
    /// parse, so all are bad input; a caller that passes computed values
    /// (not the user's) and gets one has a bug to report.
    pub fn is_bad_input(&self) -> bool {
        match self {
            CoreError::InvalidArgument { .. }
            | CoreError::NonFinite { .. }
            | CoreError::TooShort { .. }
            | CoreError::DateOutOfRange { .. }
            | CoreError::Parse { .. } => true,
        }
    }
}

/// Result alias of this crate.
pub type Result<T> = std::result::Result<T, CoreError>;

/// A value in a message: as Rust writes it (`-100.5`, `500000`), or in
/// exponent form when that would be long (`1e300`, not 301 digits).
pub fn shown(v: f64) -> String {
    let plain = v.to_string();
    if plain.len() > 24 {
        format!("{v:e}")
    } else {
        plain
    }
}

/// `x` with `decimals` decimals, as a printed figure, or in exponent form
/// ([`shown`]) from 10¹⁵ on, where fixed decimals would be long: a time of
/// 1e300 s in a hostile file is printed `1e300`, not as 301 digits.
pub fn fixed(x: f64, decimals: usize) -> String {
    if x.abs() < 1e15 {
        format!("{x:.decimals$}")
    } else {
        shown(x)
    }
}

/// A figure in a message: four decimals, or three significant digits in
/// exponent form below 10⁻³ and from 10⁶ (a phase in radians turns at
/// 4.8·10⁻⁵ Hz, which [`shown`] wrote with 20 digits; a time step of
/// 10⁻⁹ s was `9.999999717180685e-10`).
pub fn figure(x: f64) -> String {
    if x != 0.0 && !(1e-3..1e6).contains(&x.abs()) {
        format!("{x:.2e}")
    } else {
        fixed(x, 4)
    }
}

/// Characters of a text [`shown_text`] keeps.
pub const SHOWN_TEXT_CHARS: usize = 40;

/// A text from a file in a message: quoted and escaped as Rust's `{:?}`
/// writes it (control characters and NULs as `\0`, `\u{1}`, …), cut to
/// its first [`SHOWN_TEXT_CHARS`] characters with `…` after the quote, so
/// that binary garbage is never echoed raw nor by the kilobyte.
pub fn shown_text(s: &str) -> String {
    match s.char_indices().nth(SHOWN_TEXT_CHARS) {
        Some((end, _)) => format!("{:?}…", &s[..end]),
        None => format!("{s:?}"),
    }
}

/// The 1-based line of byte `offset` of `text` (a parser's error span →
/// the line a caller reports in a structured error; offsets past the end
/// give the last line).
pub fn line_of(text: &str, offset: usize) -> u64 {
    let end = offset.min(text.len());
    1 + text.as_bytes()[..end]
        .iter()
        .filter(|&&b| b == b'\n')
        .count() as u64
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn line_of_counts_the_lines_before_an_offset() {
        let text = "a = 1\nb = [\nc";
        assert_eq!(line_of(text, 0), 1);
        assert_eq!(line_of(text, 5), 1);
        assert_eq!(line_of(text, 6), 2);
        assert_eq!(line_of(text, 12), 3);
        assert_eq!(line_of(text, 999), 3);
    }

    #[test]
    fn texts_are_escaped_and_cut() {
        assert_eq!(shown_text("long_name"), "\"long_name\"");
        assert_eq!(shown_text("y\0\u{1}é"), "\"y\\0\\u{1}é\"");
        let garbage = "\0".repeat(500);
        let s = shown_text(&garbage);
        assert_eq!(s, format!("\"{}\"…", "\\0".repeat(SHOWN_TEXT_CHARS)));
    }

    #[test]
    fn figures_have_fixed_decimals_until_they_would_be_long() {
        assert_eq!(fixed(53064.0631, 1), "53064.1");
        assert_eq!(fixed(-0.5, 3), "-0.500");
        assert_eq!(fixed(1e300, 3), "1e300");
        assert_eq!(fixed(f64::NAN, 2), "NaN");
    }

    #[test]
    fn long_values_are_shown_in_exponent_form() {
        assert_eq!(shown(-100.5), "-100.5");
        assert_eq!(shown(500000.0), "500000");
        assert_eq!(shown(1e300), "1e300");
        assert_eq!(shown(1e-308), "1e-308");
        assert_eq!(shown(f64::NAN), "NaN");
    }

    #[test]
    fn every_core_error_is_bad_input() {
        assert!(
            CoreError::TooShort {
                name: "x",
                len: 1,
                min: 3
            }
            .is_bad_input()
        );
        assert!(
            CoreError::DateOutOfRange {
                year: 1800.0,
                first: 1900.0,
                last: 2030.0
            }
            .is_bad_input()
        );
    }
}
