//! The command's observer: stages as spinners on stderr (only when both
//! stdout and stderr are a terminal), notes and warnings printed as they
//! come.

use aeromag::{Note, Observer};
use indicatif::ProgressBar;
use std::io::IsTerminal;

fn on_terminal() -> bool {
    std::io::stdout().is_terminal() && std::io::stderr().is_terminal()
}

/// A spinner for a step of unknown length; hidden when not on a terminal.
pub fn spinner(msg: &str) -> ProgressBar {
    if !on_terminal() {
        return ProgressBar::hidden();
    }
    let pb = ProgressBar::new_spinner();
    pb.set_message(msg.to_string());
    pb.enable_steady_tick(std::time::Duration::from_millis(120));
    pb
}

/// Renders a library workflow's stages as spinners and prints its notes.
#[derive(Default)]
pub struct Bars {
    current: Option<ProgressBar>,
}

impl Bars {
    /// An observer with nothing shown yet.
    pub fn new() -> Self {
        Self::default()
    }
}

impl Observer for Bars {
    fn stage(&mut self, name: &str) {
        if let Some(pb) = self.current.take() {
            pb.finish_and_clear();
        }
        self.current = Some(spinner(name));
    }

    fn progress(&mut self, done: u64, total: u64) {
        if let Some(pb) = &self.current {
            pb.set_length(total);
            pb.set_position(done);
        }
    }

    fn note(&mut self, note: &Note) {
        match &self.current {
            Some(pb) => pb.suspend(|| eprintln!("{note}")),
            None => eprintln!("{note}"),
        }
    }
}

impl Drop for Bars {
    fn drop(&mut self) {
        if let Some(pb) = self.current.take() {
            pb.finish_and_clear();
        }
    }
}
