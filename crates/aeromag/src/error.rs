//! The error type of the `aeromag` library.
//!
//! Every workflow returns [`Error`]. Its `Display` text is the message a
//! user sees: it names the file (and the row and column where they are
//! known). [`Error::is_bad_input`] tells the two kinds of failure apart:
//!
//! - **bad input** — the user's file, columns, values, options or scenario
//!   file: fixing the input fixes the run (the `aeromag` command exits
//!   with code 2);
//! - **failure** — the input is valid but the method could not produce a
//!   result (a singular or diverging fit, a numerical failure), or an output
//!   could not be written (exit code 1).
//!
//! A workflow its observer cancelled ([`crate::Observer::cancelled`])
//! returns [`Error::Cancelled`], which is neither (not bad input).
//!
//! Errors of the sub-crates are kept as they are (with their own
//! classification) and, where they do not know it, given the file they
//! concern ([`Error::InFile`]).

use aeromag_io::Location;
use std::path::PathBuf;

/// Everything that can go wrong in a workflow of this crate.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// Reading, mapping, checking or writing a flight table (aeromag-io;
    /// its messages name file, line, row and column).
    #[error(transparent)]
    Io(Box<aeromag_io::IoError>),
    /// A value, column or setting this workflow cannot use.
    #[error("{}", bad_input_message(file.as_deref(), *line, *row, column.as_deref(), reason))]
    BadInput {
        /// The file (or table) concerned, when there is one.
        file: Option<String>,
        /// 1-based line in the file, when known (printed with the data row;
        /// a parser's message names the line of a syntax error itself).
        line: Option<u64>,
        /// 0-based data row (printed 1-based as "data row N").
        row: Option<usize>,
        /// Column name as the file spells it.
        column: Option<String>,
        /// What is wrong and what is expected.
        reason: String,
    },
    /// An error of a sub-crate raised on the data of `file`.
    #[error("{file}: {error}")]
    InFile {
        /// The file (label of the table) whose data raised it.
        file: String,
        /// The error.
        error: Box<Error>,
    },
    /// Tolles-Lawson fits, levelling, rotor and pod models.
    #[error(transparent)]
    Compensation(aeromag_compensation::CompError),
    /// The physical simulator (scenario files, running, writing).
    #[error(transparent)]
    Simulation(Box<aeromag_sim::SimError>),
    /// EM detection, calibration and positioning.
    #[error(transparent)]
    Em(#[from] aeromag_em::EmError),
    /// Gradiometer dipole estimation.
    #[error(transparent)]
    Gradiometry(#[from] aeromag_gradiometry::GradiometryError),
    /// Projection, gridding and grid files.
    #[error(transparent)]
    Grid(aeromag_grid::GridError),
    /// Plots and reports.
    #[error(transparent)]
    Report(#[from] aeromag_report::ReportError),
    /// Frames, fields, filters, dates.
    #[error(transparent)]
    Core(#[from] aeromag_core::CoreError),
    /// Estimation machinery (least squares, Kalman filters).
    #[error(transparent)]
    Estimation(#[from] aeromag_estimation::EstError),
    /// Reading an input file other than a flight table (model file,
    /// scenario file, raw record) failed at the operating-system level.
    #[error("cannot read '{}': {source}", path.display())]
    Read {
        /// The file.
        path: PathBuf,
        /// The operating system's reason.
        source: std::io::Error,
    },
    /// Writing an output file (or creating its folder) failed.
    #[error("cannot write '{}': {source}", path.display())]
    Write {
        /// The file or folder.
        path: PathBuf,
        /// The operating system's reason.
        source: std::io::Error,
    },
    /// The observer cancelled the workflow ([`crate::Observer::cancelled`]):
    /// the user asked it to stop (not bad input). A sub-crate's cancelled
    /// error becomes this one.
    #[error("cancelled")]
    Cancelled,
    /// Serialising a result (JSON, TOML) failed: a bug, reported instead of
    /// a panic.
    #[error("cannot serialise {what}: {reason}")]
    Serialize {
        /// What was being serialised.
        what: &'static str,
        /// The serialiser's message.
        reason: String,
    },
}

/// Result alias of this crate.
pub type Result<T> = std::result::Result<T, Error>;

fn bad_input_message(
    file: Option<&str>,
    line: Option<u64>,
    row: Option<usize>,
    column: Option<&str>,
    reason: &str,
) -> String {
    let mut at = Vec::new();
    match (file, line, row) {
        (Some(f), Some(l), Some(r)) => at.push(format!("'{f}' line {l} (data row {})", r + 1)),
        (f, _, r) => {
            if let Some(f) = f {
                at.push(format!("'{f}'"));
            }
            if let Some(r) = r {
                at.push(format!("data row {}", r + 1));
            }
        }
    }
    if let Some(c) = column {
        at.push(format!("column '{c}'"));
    }
    if at.is_empty() {
        reason.to_string()
    } else {
        format!("{}: {reason}", at.join(", "))
    }
}

impl Error {
    /// Whether the user's input caused this error (see the module docs):
    /// `true` for files, columns, values, options and scenario files that
    /// cannot be used; `false` for valid input on which a method failed,
    /// and for failures to write.
    pub fn is_bad_input(&self) -> bool {
        match self {
            Error::Io(e) => e.is_bad_input(),
            Error::BadInput { .. } => true,
            Error::InFile { error, .. } => error.is_bad_input(),
            Error::Compensation(e) => e.is_bad_input(),
            Error::Simulation(e) => e.is_bad_input(),
            Error::Em(e) => e.is_bad_input(),
            Error::Gradiometry(e) => e.is_bad_input(),
            Error::Report(e) => e.is_bad_input(),
            Error::Grid(e) => e.is_bad_input(),
            Error::Core(e) => e.is_bad_input(),
            Error::Estimation(e) => e.is_bad_input(),
            Error::Read { .. } => true,
            Error::Write { .. } | Error::Serialize { .. } | Error::Cancelled => false,
        }
    }

    /// Whether the workflow was cancelled ([`Error::Cancelled`], also when
    /// given a file).
    pub fn is_cancelled(&self) -> bool {
        match self {
            Error::Cancelled => true,
            Error::InFile { error, .. } => error.is_cancelled(),
            _ => false,
        }
    }

    /// Whether writing an output (a file or its folder) failed: Python
    /// raises these as `OSError`, whichever part of the library wrote.
    pub fn is_write_failure(&self) -> bool {
        match self {
            Error::Write { .. } | Error::Grid(aeromag_grid::GridError::Write { .. }) => true,
            Error::Io(e) => matches!(**e, aeromag_io::IoError::Write { .. }),
            Error::InFile { error, .. } => error.is_write_failure(),
            _ => false,
        }
    }

    /// The operating system's error of a file that could not be opened,
    /// read or written (a missing input, a folder in the place of an
    /// output, no permission, a full disk): Python raises the matching
    /// `OSError` subclass (`FileNotFoundError`, …) with its `errno` and
    /// `filename`.
    pub fn os_error(&self) -> Option<&std::io::Error> {
        use aeromag_io::IoError;
        match self {
            Error::Read { source, .. } | Error::Write { source, .. } => Some(source),
            Error::Io(e) => match &**e {
                IoError::Open { source, .. } | IoError::Write { source, .. } => Some(source),
                _ => None,
            },
            Error::Grid(
                aeromag_grid::GridError::Open { source, .. }
                | aeromag_grid::GridError::Write { source, .. },
            ) => Some(source),
            Error::InFile { error, .. } => error.os_error(),
            _ => None,
        }
    }

    /// Where the error is (file, line, data row, column), as far as it
    /// says; Python's `BadInputError` carries these.
    pub fn location(&self) -> Location {
        match self {
            Error::Io(e) => e.location(),
            Error::BadInput {
                file,
                line,
                row,
                column,
                ..
            } => Location {
                file: file.clone(),
                line: *line,
                row: *row,
                column: column.clone(),
            },
            Error::InFile { file, error } => {
                let mut at = error.location();
                at.file.get_or_insert_with(|| file.clone());
                at
            }
            Error::Read { path, .. }
            | Error::Write { path, .. }
            | Error::Report(aeromag_report::ReportError::Io { path, .. }) => {
                Location::in_file(path.display().to_string())
            }
            Error::Compensation(aeromag_compensation::CompError::ModelFile {
                origin,
                line,
                ..
            }) => Location {
                line: *line,
                ..Location::in_file(origin.clone())
            },
            Error::Grid(
                aeromag_grid::GridError::Read { path, .. }
                | aeromag_grid::GridError::Open { path, .. }
                | aeromag_grid::GridError::BadValue { path, .. }
                | aeromag_grid::GridError::Write { path, .. }
                | aeromag_grid::GridError::UnknownFormat(path),
            ) => Location::in_file(path.clone()),
            // Scenario files: the file is the caller's (`Error::InFile`),
            // the line the parser's.
            Error::Simulation(e) => match &**e {
                aeromag_sim::SimError::ConfigParse { line, .. } => Location {
                    line: *line,
                    ..Location::default()
                },
                aeromag_sim::SimError::Write { path, .. } => {
                    Location::in_file(path.display().to_string())
                }
                _ => Location::default(),
            },
            Error::Gradiometry(aeromag_gradiometry::GradiometryError::Config { line, .. }) => {
                Location {
                    line: *line,
                    ..Location::default()
                }
            }
            _ => Location::default(),
        }
    }

    /// A bad-input error with only a reason (an option or setting).
    pub fn bad_input(reason: impl Into<String>) -> Self {
        Error::BadInput {
            file: None,
            line: None,
            row: None,
            column: None,
            reason: reason.into(),
        }
    }

    /// Bad input in the text of `file` (a scenario, settings, model or EM
    /// file): the error's message after the file's name, and the line its
    /// parser placed it on (TOML and JSON syntax and type errors; their
    /// messages name the line and column themselves, so it is kept for
    /// [`Error::location`] and printed only through the message).
    pub fn in_text(file: impl Into<String>, e: impl Into<Error>) -> Self {
        let e = e.into();
        Error::BadInput {
            file: Some(file.into()),
            line: e.location().line,
            row: None,
            column: None,
            reason: e.to_string(),
        }
    }

    /// [`Error::in_text`] of a TOML parser's error on `text`.
    pub fn toml(file: impl Into<String>, text: &str, e: &toml::de::Error) -> Self {
        Error::BadInput {
            file: Some(file.into()),
            line: e
                .span()
                .map(|s| aeromag_core::error::line_of(text, s.start)),
            row: None,
            column: None,
            reason: e.to_string(),
        }
    }

    /// [`Error::in_text`] of a JSON parser's error, after `what` ("not a
    /// JSON model file").
    pub fn json(file: impl Into<String>, what: &str, e: &serde_json::Error) -> Self {
        Error::BadInput {
            file: Some(file.into()),
            line: aeromag_compensation::model_file::json_error_line(e),
            row: None,
            column: None,
            reason: format!("{what} ({e})"),
        }
    }

    /// A bad-input error about the data of `file`.
    pub fn bad_file(file: impl Into<String>, reason: impl Into<String>) -> Self {
        Error::BadInput {
            file: Some(file.into()),
            line: None,
            row: None,
            column: None,
            reason: reason.into(),
        }
    }

    /// A bad-input error at a row and column of `file`.
    pub fn bad_value(
        file: impl Into<String>,
        row: usize,
        column: impl Into<String>,
        reason: impl Into<String>,
    ) -> Self {
        Error::BadInput {
            file: Some(file.into()),
            line: None,
            row: Some(row),
            column: Some(column.into()),
            reason: reason.into(),
        }
    }

    /// [`Error::Write`] for `path`.
    pub fn write(path: impl Into<PathBuf>, source: std::io::Error) -> Self {
        Error::Write {
            path: path.into(),
            source,
        }
    }

    /// [`Error::Read`] for `path`.
    pub fn read(path: impl Into<PathBuf>, source: std::io::Error) -> Self {
        Error::Read {
            path: path.into(),
            source,
        }
    }
}

/// The classification of any error of this library or its sub-crates
/// (`None` for an error type none of them defines): for callers that hold
/// errors type-erased, such as `anyhow` in the `aeromag` command.
pub fn classify(e: &(dyn std::error::Error + 'static)) -> Option<bool> {
    macro_rules! first_known {
        ($($t:ty),*) => {
            $(if let Some(e) = e.downcast_ref::<$t>() {
                return Some(e.is_bad_input());
            })*
        };
    }
    first_known!(
        Error,
        aeromag_io::IoError,
        aeromag_compensation::CompError,
        aeromag_sim::SimError,
        aeromag_em::EmError,
        aeromag_gradiometry::GradiometryError,
        aeromag_report::ReportError,
        aeromag_core::CoreError,
        aeromag_estimation::EstError,
        aeromag_grid::GridError
    );
    None
}

/// Attach the file a sub-crate error concerns ([`Error::InFile`]).
pub trait InFile<T> {
    /// The error, if any, as raised on the data of `file`.
    fn in_file(self, file: &str) -> Result<T>;
}

impl<T, E: Into<Error>> InFile<T> for std::result::Result<T, E> {
    /// An error that already names a file is kept as it is (it was
    /// printed with the file twice: "f.csv: 'f.csv': …").
    fn in_file(self, file: &str) -> Result<T> {
        self.map_err(|e| match e.into() {
            e @ (Error::BadInput { file: Some(_), .. }
            | Error::InFile { .. }
            | Error::Cancelled) => e,
            e => Error::InFile {
                file: file.to_string(),
                error: Box::new(e),
            },
        })
    }
}

impl From<aeromag_io::IoError> for Error {
    fn from(e: aeromag_io::IoError) -> Self {
        Error::Io(Box::new(e))
    }
}

/// A cancelled fit is [`Error::Cancelled`].
impl From<aeromag_compensation::CompError> for Error {
    fn from(e: aeromag_compensation::CompError) -> Self {
        match e {
            aeromag_compensation::CompError::Cancelled(_) => Error::Cancelled,
            e => Error::Compensation(e),
        }
    }
}

/// A cancelled grid is [`Error::Cancelled`].
impl From<aeromag_grid::GridError> for Error {
    fn from(e: aeromag_grid::GridError) -> Self {
        match e {
            aeromag_grid::GridError::Cancelled(_) => Error::Cancelled,
            e => Error::Grid(e),
        }
    }
}

impl From<aeromag_sim::SimError> for Error {
    fn from(e: aeromag_sim::SimError) -> Self {
        Error::Simulation(Box::new(e))
    }
}

impl From<serde_json::Error> for Error {
    fn from(e: serde_json::Error) -> Self {
        Error::Serialize {
            what: "JSON",
            reason: e.to_string(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bad_input_names_file_row_and_column() {
        let e = Error::bad_value("cal.csv", 14, "mag", "is not a total field");
        assert_eq!(
            e.to_string(),
            "'cal.csv', data row 15, column 'mag': is not a total field"
        );
        assert!(e.is_bad_input());
        assert_eq!(Error::bad_input("--band 1,0").to_string(), "--band 1,0");
    }

    /// Files other than flights say where in their errors as well
    /// (`location`: what Python's exceptions carry), and a missing or
    /// unwritable file gives the system's error.
    #[test]
    fn settings_model_and_grid_files_are_located() {
        use crate::ModelFile;
        let tmp = tempfile::tempdir().unwrap();
        let dir = tmp.path();
        let file = |name: &str, text: &str| {
            let p = dir.join(name);
            std::fs::write(&p, text).unwrap();
            p
        };
        let at = |e: &Error| (e.location().file, e.location().line);
        let shown = |p: &std::path::Path| Some(p.display().to_string());

        let model = file(
            "m.json",
            "{\n  \"format\": \"aeromag-model/2\",\n  \"kind\" ,\n}\n",
        );
        let e = crate::TlModel::read(&model).unwrap_err();
        assert_eq!(at(&e), (shown(&model), Some(3)), "{e}");
        assert!(e.is_bad_input());
        let e = crate::model_file::kind_of(&model).unwrap_err();
        assert_eq!(at(&e), (shown(&model), Some(3)), "{e}");

        let scenario = file("s.toml", "seed = 1\n\n[scalar]\nlag_s = \"x\"\n");
        let kind = crate::simulate::ScenarioKind::Calibration;
        let e = crate::simulate::simulate_scenario(kind, Some(&scenario), None).unwrap_err();
        assert_eq!(at(&e), (shown(&scenario), Some(4)), "{e}");
        let text = e.to_string();
        assert!(
            text.starts_with(&format!(
                "'{}': scenario file: TOML parse error at line 4",
                scenario.display()
            )),
            "{text}"
        );
        // A value wrong after merging over the defaults: the file, no line.
        let negative = file("n.toml", "[scalar]\nlag_s = -1.0\n");
        let e = crate::simulate::simulate_scenario(kind, Some(&negative), None).unwrap_err();
        assert_eq!(at(&e), (shown(&negative), None), "{e}");

        let grad = file("g.toml", "seed = 3\n[system]\nbaseline_m = [1\n");
        let e = crate::gradiometry::read_config(Some(&grad)).unwrap_err();
        assert_eq!(at(&e), (shown(&grad), Some(3)), "{e}");

        let read_grid = |p: &std::path::Path| -> Error {
            crate::grid::format::read_grid(p).unwrap_err().into()
        };
        let grid = file("g.asc", "ncols 2\nnrows x\n");
        let e = read_grid(&grid);
        assert_eq!(at(&e).0, shown(&grid), "{e}");
        assert!(e.os_error().is_none());

        for missing in [
            dir.join("none.asc"),
            dir.join("none.tif"),
            dir.join("none.nc"),
        ] {
            let e = read_grid(&missing);
            assert_eq!(at(&e).0, shown(&missing), "{e}");
            assert_eq!(
                e.os_error().map(|o| o.kind()),
                Some(std::io::ErrorKind::NotFound)
            );
        }
        let missing = dir.join("none.json");
        let e = crate::TlModel::read(&missing).unwrap_err();
        assert_eq!(
            e.os_error().map(|o| o.kind()),
            Some(std::io::ErrorKind::NotFound)
        );
        let missing = dir.join("none.csv");
        let e = crate::Flight::read(&missing).unwrap_err();
        assert_eq!(at(&e).0, shown(&missing), "{e}");
        assert_eq!(
            e.os_error().map(|o| o.kind()),
            Some(std::io::ErrorKind::NotFound)
        );
    }

    #[test]
    fn the_error_stays_small() {
        // Returned by every workflow: boxed sub-errors keep it cheap to move.
        assert!(
            std::mem::size_of::<Error>() <= 112,
            "{}",
            std::mem::size_of::<Error>()
        );
    }

    #[test]
    fn context_keeps_the_classification() {
        let failed: std::result::Result<(), Error> = Err(Error::Serialize {
            what: "x",
            reason: "y".into(),
        });
        let e = failed.in_file("f.csv").unwrap_err();
        assert!(!e.is_bad_input());
        assert!(e.to_string().starts_with("f.csv: "), "{e}");
        let bad: std::result::Result<(), Error> = Err(Error::bad_input("no"));
        assert!(bad.in_file("f.csv").unwrap_err().is_bad_input());
        let w = Error::write("/x", std::io::Error::other("disk full"));
        assert!(!w.is_bad_input());
    }

    #[test]
    fn a_cancelled_sub_crate_error_is_cancelled_not_bad_input() {
        use aeromag_core::cancel::Cancelled;
        let comp: Error = aeromag_compensation::CompError::from(Cancelled).into();
        let grid: Error = aeromag_grid::GridError::from(Cancelled).into();
        for e in [comp, grid] {
            assert!(matches!(e, Error::Cancelled), "{e:?}");
            assert!(!e.is_bad_input());
            assert_eq!(e.to_string(), "cancelled");
        }
        let failed: std::result::Result<(), Error> = Err(Error::Cancelled);
        let e = failed.in_file("f.csv").unwrap_err();
        assert!(e.is_cancelled() && !e.is_bad_input());
        assert_eq!(e.to_string(), "cancelled");
        assert!(!Error::bad_input("no").is_cancelled());
    }
}
