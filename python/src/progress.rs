//! Progress of long calls: the library's [`Observer`] calling a Python
//! callable `progress(stage, done, total)` (the Python layer adapts tqdm
//! bars to it). The callable runs with the GIL taken for the call only;
//! the work itself runs with the GIL released.

use aeromag::{Note, Observer};
use pyo3::prelude::*;

/// Calls `progress(stage, done, total)`; notes are kept for the result.
pub struct PyProgress {
    callback: Option<Py<PyAny>>,
    stage: String,
    /// The first error the callback raised (e.g. KeyboardInterrupt); the
    /// callback is not called again after it.
    pub error: Option<PyErr>,
    /// Notes and warnings raised, in order.
    pub notes: Vec<Note>,
}

impl PyProgress {
    pub fn new(callback: Option<Py<PyAny>>) -> Self {
        Self {
            callback,
            stage: String::new(),
            error: None,
            notes: Vec::new(),
        }
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

    /// The callback's error, if it raised one.
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
}
