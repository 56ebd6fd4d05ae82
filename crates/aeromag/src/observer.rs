//! What a long workflow tells while it runs, and the notes it leaves.
//!
//! Library code prints nothing. A workflow reports its stages and progress
//! to an [`Observer`] (the `aeromag` command draws them as progress bars on a
//! terminal; a notebook could draw them with tqdm), and every note or
//! warning it raises is both sent to the observer as it happens and kept in
//! the result ([`Note`]), so that a caller that ignores the observer loses
//! nothing. The design follows argmin's observers: the workflow calls the
//! observer; the observer never changes the result — except to stop it:
//! [`Observer::cancelled`] is asked between steps, and a workflow told to
//! stop returns [`crate::Error::Cancelled`].
//!
//! ```
//! use aeromag::{Note, Observer};
//!
//! /// Collects the stage names.
//! #[derive(Default)]
//! struct Stages(Vec<String>);
//!
//! impl Observer for Stages {
//!     fn stage(&mut self, name: &str) {
//!         self.0.push(name.to_string());
//!     }
//! }
//!
//! let mut seen = Stages::default();
//! seen.stage("fitting");
//! seen.note(&Note::warning("3 of 100 rows have missing values"));
//! assert_eq!(seen.0, ["fitting"]);
//! ```

use serde::{Deserialize, Serialize};
use std::fmt;

/// Whether a [`Note`] is information or a warning.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum NoteLevel {
    /// What a workflow chose or did (a lag kept, an altitude cleaned).
    Note,
    /// Something the user should look at (rows left out, a term not
    /// determined by the flight, a column that does not look right).
    Warning,
}

/// A note or warning raised by a workflow, kept in its result.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct Note {
    /// Note or warning.
    pub level: NoteLevel,
    /// The text, one sentence or a few, without a `note:` prefix.
    pub message: String,
}

impl Note {
    /// An informational note.
    #[allow(clippy::self_named_constructors)]
    pub fn note(message: impl Into<String>) -> Self {
        Self {
            level: NoteLevel::Note,
            message: message.into(),
        }
    }

    /// A warning.
    pub fn warning(message: impl Into<String>) -> Self {
        Self {
            level: NoteLevel::Warning,
            message: message.into(),
        }
    }

    /// Whether this is a warning.
    pub fn is_warning(&self) -> bool {
        self.level == NoteLevel::Warning
    }
}

impl fmt::Display for Note {
    /// `note: …` or `warning: …`, as the command prints it.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.level {
            NoteLevel::Note => write!(f, "note: {}", self.message),
            NoteLevel::Warning => write!(f, "warning: {}", self.message),
        }
    }
}

/// Receives a workflow's stages, progress and notes as they happen. Every
/// method has a default that does nothing; implement the ones you need.
pub trait Observer {
    /// A stage begins (for example "choosing eddy-current lags"); it lasts
    /// until the next stage begins or the workflow returns.
    fn stage(&mut self, _name: &str) {}
    /// `done` of `total` steps of the current stage are complete.
    fn progress(&mut self, _done: u64, _total: u64) {}
    /// A note or warning was raised (it is also kept in the result).
    fn note(&mut self, _note: &Note) {}
    /// Whether the workflow should stop (default: never). Asked on the
    /// calling thread at every stage and between the steps of the long
    /// loops (the Kalman fit's noise-tuning evaluations and filter rounds,
    /// minimum curvature's sweeps): a few milliseconds to a few tens of
    /// milliseconds apart, so it must be cheap. Once it returns `true`, the
    /// workflow returns [`crate::Error::Cancelled`] at its next check
    /// (usually at once); it should keep returning `true`. Python's
    /// observer checks for Ctrl-C here.
    fn cancelled(&mut self) -> bool {
        false
    }
}

/// An observer that ignores everything.
#[derive(Debug, Clone, Copy, Default)]
pub struct Silent;

impl Observer for Silent {}

/// Notes of one workflow run: kept for the result and forwarded to the
/// observer as they are raised.
pub(crate) struct Notes<'o> {
    observer: &'o mut dyn Observer,
    kept: Vec<Note>,
}

impl<'o> Notes<'o> {
    pub(crate) fn new(observer: &'o mut dyn Observer) -> Self {
        Self {
            observer,
            kept: Vec::new(),
        }
    }

    /// Raise a note.
    pub(crate) fn note(&mut self, message: impl Into<String>) {
        self.push(Note::note(message));
    }

    /// Raise a warning.
    pub(crate) fn warn(&mut self, message: impl Into<String>) {
        self.push(Note::warning(message));
    }

    /// Raise a note or warning already built.
    pub(crate) fn push(&mut self, note: Note) {
        self.observer.note(&note);
        self.kept.push(note);
    }

    /// Begin a stage.
    pub(crate) fn stage(&mut self, name: &str) {
        self.observer.stage(name);
    }

    /// Whether the observer asks to stop ([`Observer::cancelled`]).
    pub(crate) fn cancelled(&mut self) -> bool {
        self.observer.cancelled()
    }

    /// [`crate::Error::Cancelled`] when the observer asks to stop: for
    /// workflows' stages and loops (`notes.check_cancelled()?`).
    pub(crate) fn check_cancelled(&mut self) -> crate::Result<()> {
        if self.cancelled() {
            Err(crate::Error::Cancelled)
        } else {
            Ok(())
        }
    }

    /// The notes raised so far.
    pub(crate) fn into_notes(self) -> Vec<Note> {
        self.kept
    }

    /// Number of notes raised so far.
    pub(crate) fn len(&self) -> usize {
        self.kept.len()
    }

    /// Copies of the notes raised after the first `start`.
    pub(crate) fn since(&self, start: usize) -> Vec<Note> {
        self.kept[start.min(self.kept.len())..].to_vec()
    }
}

/// A [`Notes`] collector is itself an observer: a nested workflow's notes
/// are kept by the outer one and forwarded to its observer.
impl Observer for Notes<'_> {
    fn stage(&mut self, name: &str) {
        self.observer.stage(name);
    }
    fn progress(&mut self, done: u64, total: u64) {
        self.observer.progress(done, total);
    }
    fn note(&mut self, note: &Note) {
        self.push(note.clone());
    }
    fn cancelled(&mut self) -> bool {
        self.observer.cancelled()
    }
}
