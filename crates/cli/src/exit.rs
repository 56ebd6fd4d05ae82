//! Exit codes: 2 for bad input, 1 for other failures.

/// Marks an error as caused by the user's input (exit code 2).
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub struct BadInput(pub String);

/// Exit code of an error chain: 2 if any cause is a bad-input error of ours or
/// of a library crate, 1 otherwise.
pub fn classify(e: &anyhow::Error) -> i32 {
    for cause in e.chain() {
        if cause.downcast_ref::<BadInput>().is_some()
            || cause
                .downcast_ref::<aeromag_io::IoError>()
                .is_some_and(|e| e.is_bad_input())
            || cause.downcast_ref::<aeromag_core::CoreError>().is_some()
            || cause
                .downcast_ref::<aeromag_sim::SimError>()
                .is_some_and(sim_bad_input)
        {
            return 2;
        }
    }
    1
}

/// Shorthand: a bad-input error with a message.
macro_rules! bad_input {
    ($($t:tt)*) => { anyhow::Error::new($crate::exit::BadInput(format!($($t)*))) };
}
pub(crate) use bad_input;

/// Scenario-file problems are the user's input; failures to run or write are not.
fn sim_bad_input(e: &aeromag_sim::SimError) -> bool {
    use aeromag_sim::SimError as E;
    matches!(
        e,
        E::ConfigParse(_) | E::InvalidConfig { .. } | E::Core(_) | E::Trajectory(_)
    )
}
