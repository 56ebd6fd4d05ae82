//! Progress of long calls: the library's [`Observer`] calling a Python
//! callable `progress(stage, done, total)` (the Python layer adapts tqdm
//! bars to it). The callable runs with the GIL taken for the call only;
//! the work itself runs with the GIL released.
//!
//! Ctrl-C: the library asks the observer between steps whether to stop
//! ([`Observer::cancelled`]); [`PyProgress`] takes the GIL at most every
//! [`SIGNAL_CHECK_INTERVAL`] to run Python's signal handlers
//! (`PyErr_CheckSignals`). A `KeyboardInterrupt` (or any exception a
//! handler raises) is kept and stops the call, and [`PyProgress::finish`]
//! raises it instead of the library's "cancelled" error.

use aeromag::{Note, Observer};
use pyo3::prelude::*;
use std::time::{Duration, Instant};

/// Longest time between two checks for Python signals (Ctrl-C) while a
/// detached call runs: the GIL is taken for the check, so not every time
/// the library asks.
pub const SIGNAL_CHECK_INTERVAL: Duration = Duration::from_millis(50);

/// Calls `progress(stage, done, total)`; notes are kept for the result.
pub struct PyProgress {
    callback: Option<Py<PyAny>>,
    stage: String,
    /// The first error the callback or a signal handler raised (e.g.
    /// KeyboardInterrupt); the callback is not called again after it, and
    /// the library is told to stop.
    pub error: Option<PyErr>,
    /// When Python's signal handlers last ran.
    signals_checked: Instant,
    /// Notes and warnings raised, in order.
    pub notes: Vec<Note>,
}

impl PyProgress {
    pub fn new(callback: Option<Py<PyAny>>) -> Self {
        Self {
            callback,
            stage: String::new(),
            error: None,
            signals_checked: Instant::now(),
            notes: Vec::new(),
        }
    }

    /// Runs Python's signal handlers (with the GIL) when
    /// [`SIGNAL_CHECK_INTERVAL`] has passed since they last ran, keeping
    /// the exception one raises (KeyboardInterrupt on Ctrl-C). Whether an
    /// exception is kept.
    fn check_signals(&mut self) -> bool {
        if self.error.is_none() && self.signals_checked.elapsed() >= SIGNAL_CHECK_INTERVAL {
            if let Err(e) = Python::attach(|py| py.check_signals()) {
                self.error = Some(e);
            }
            self.signals_checked = Instant::now();
        }
        self.error.is_some()
    }

    fn call(&mut self, done: u64, total: u64) {
        if self.error.is_some() {
            return;
        }
        if let Some(cb) = &self.callback {
            let stage = self.stage.clone();
            if let Err(e) = Python::attach(|py| cb.call1(py, (stage, done, total)).map(|_| ())) {
                self.error = Some(e);
            }
        }
    }

    /// The error the callback or a signal handler raised, if any: raised
    /// before the call's own result is looked at, so that a call stopped by
    /// Ctrl-C raises KeyboardInterrupt, not the library's "cancelled".
    pub fn finish(&mut self) -> PyResult<()> {
        match self.error.take() {
            Some(e) => Err(e),
            None => Ok(()),
        }
    }
}

impl Observer for PyProgress {
    fn stage(&mut self, name: &str) {
        self.stage = name.to_string();
        self.call(0, 0);
    }

    fn progress(&mut self, done: u64, total: u64) {
        self.call(done, total);
    }

    fn note(&mut self, note: &Note) {
        self.notes.push(note.clone());
    }

    fn cancelled(&mut self) -> bool {
        self.check_signals()
    }
}
