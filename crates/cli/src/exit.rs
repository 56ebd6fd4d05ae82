//! Exit codes: 2 for bad input, 1 for other failures; and the message.

/// Marks an error found by the command itself (an option combination) as
/// caused by the user's input (exit code 2).
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub struct BadInput(pub String);

/// Exit code of an error chain: 2 if the first error that knows its cause
/// says bad input, 1 otherwise (clap's own usage errors exit 2 before).
pub fn classify(e: &anyhow::Error) -> i32 {
    for cause in e.chain() {
        if cause.downcast_ref::<BadInput>().is_some() {
            return 2;
        }
        if let Some(bad) = aeromag::error::classify(cause) {
            return if bad { 2 } else { 1 };
        }
    }
    1
}

/// The exit code of a failed command, `None` when the failure is an
/// interruption's (`interrupted`: a write refused after SIGINT/SIGTERM,
/// "cannot write 'st/index.html': interrupted"): the signal's thread exits
/// with 130/143 and the caller waits for it (it exited 1 first, 2 of 180
/// runs of `em study` interrupted during its final write).
pub fn code(e: &anyhow::Error, interrupted: bool) -> Option<i32> {
    (!interrupted).then(|| classify(e))
}

/// The message of an error chain: each cause whose text the message does
/// not already hold, joined by ": " (library errors that quote their
/// source are not repeated).
pub fn message(e: &anyhow::Error) -> String {
    let mut msg = String::new();
    for cause in e.chain() {
        let text = cause.to_string();
        if msg.contains(&text) {
            continue;
        }
        if !msg.is_empty() {
            msg.push_str(": ");
        }
        msg.push_str(&text);
    }
    msg
}

/// Shorthand: a bad-input error with a message.
macro_rules! bad_input {
    ($($t:tt)*) => { anyhow::Error::new($crate::exit::BadInput(format!($($t)*))) };
}
pub(crate) use bad_input;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn causes_are_classified_and_not_repeated() {
        let io = std::io::Error::other("disk full");
        let e = anyhow::Error::new(aeromag::Error::write("/x/o.csv", io)).context("writing");
        assert_eq!(classify(&e), 1);
        assert_eq!(message(&e), "writing: cannot write '/x/o.csv': disk full");
        assert_eq!(classify(&bad_input!("--x")), 2);
        let bad = anyhow::Error::new(aeromag::Error::bad_input("no"));
        assert_eq!(classify(&bad), 2);
    }

    /// A write refused after an interruption is no failure of its own:
    /// the command exits as interrupted (130/143), not with 1.
    #[test]
    fn an_interrupted_write_leaves_the_exit_to_the_signal() {
        let io = std::io::Error::new(std::io::ErrorKind::Interrupted, "interrupted");
        let e = anyhow::Error::new(aeromag::Error::write("st/index.html", io));
        assert_eq!(code(&e, false), Some(1));
        assert_eq!(code(&e, true), None);
    }
}
