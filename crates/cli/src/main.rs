//! `aeromag`: the command-line program.
//!
//! Each command parses its arguments, calls one function of the `aeromag`
//! library, writes the files and prints. Every command returns
//! `anyhow::Result`; [`exit::classify`] maps errors to exit codes: 2 for bad
//! input (files, columns, arguments, scenario files), 1 for everything else.
//! Nothing panics on user input.

mod args;
mod commands;
mod exit;
mod input;
mod output;
mod progress;

use clap::{Parser, Subcommand};

/// Processing of magnetic and low-frequency EM measurements from moving
/// platforms: simulation, inspection, IGRF, interference compensation.
///
/// Files use nT for magnetic induction, metres, seconds and degrees; frames are
/// NED (x north, y east, z down) and body (x forward, y right wing, z down).
/// Exit codes: 0 success, 2 bad input (the message names file, row, column),
/// 1 other failures.
#[derive(Debug, Parser)]
#[command(name = "aeromag", version, about, long_about, propagate_version = true)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    Demo(commands::demo::Args),
    Simulate(commands::simulate::Args),
    Inspect(commands::inspect::Args),
    Igrf(commands::igrf::Args),
    Calibrate(commands::calibrate::Args),
    Compensate(commands::compensate::Args),
    Stream(commands::stream::Args),
    Report(commands::report::Args),
    Level(commands::level::Args),
    Grid(commands::grid::Args),
    Microlevel(commands::microlevel::Args),
    Derive(commands::derive::Args),
    Dipole(commands::dipole::Args),
    Em(commands::em::Args),
    Rotor(commands::rotor::Args),
    Pod(commands::pod::Args),
    Observability(commands::observability::Args),
}

/// Let a closed pipe (`aeromag … | head`) end the program quietly, as Unix
/// tools do, instead of failing on the next `println!`.
fn restore_sigpipe() {
    #[cfg(unix)]
    // SAFETY: setting a signal's disposition to its default at start-up,
    // before any thread exists, has no memory-safety implications.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
}

/// Ctrl-C and SIGTERM: remove the output files being written (their
/// temporaries; complete outputs are renamed into place atomically, see
/// `aeromag::io::atomic`) and exit with 130 (SIGINT) or 143 (SIGTERM).
///
/// The two signals are blocked in every thread (threads inherit the mask of
/// the main thread, which sets it first) and taken by one thread with
/// `sigwait`, so the clean-up runs as ordinary code, not in a signal handler.
fn handle_interrupts() {
    #[cfg(unix)]
    // SAFETY: sigset_t is plain data initialised by sigemptyset; the mask is
    // set at start-up before any other thread exists; the waiting thread
    // only reads its own copy of the set.
    unsafe {
        let mut set: libc::sigset_t = std::mem::zeroed();
        libc::sigemptyset(&mut set);
        libc::sigaddset(&mut set, libc::SIGINT);
        libc::sigaddset(&mut set, libc::SIGTERM);
        if libc::pthread_sigmask(libc::SIG_BLOCK, &set, std::ptr::null_mut()) != 0 {
            return;
        }
        std::thread::spawn(move || {
            let mut sig: libc::c_int = 0;
            if libc::sigwait(&set, &mut sig) == 0 {
                let removed = aeromag::io::atomic::remove_temporaries();
                let name = if sig == libc::SIGINT {
                    "SIGINT"
                } else {
                    "SIGTERM"
                };
                eprintln!(
                    "interrupted ({name}); {removed} unfinished output file(s) removed, complete outputs kept"
                );
                std::process::exit(128 + sig);
            }
        });
    }
}

fn main() {
    restore_sigpipe();
    handle_interrupts();
    let cli = Cli::try_parse().unwrap_or_else(|e| e.exit());
    let result = check_environment().and_then(|()| match cli.command {
        Command::Demo(a) => commands::demo::run(a),
        Command::Simulate(a) => commands::simulate::run(a),
        Command::Inspect(a) => commands::inspect::run(a),
        Command::Igrf(a) => commands::igrf::run(a),
        Command::Calibrate(a) => commands::calibrate::run(a),
        Command::Compensate(a) => commands::compensate::run(a),
        Command::Stream(a) => commands::stream::run(a),
        Command::Report(a) => commands::report::run(a),
        Command::Level(a) => commands::level::run(a),
        Command::Grid(a) => commands::grid::run(a),
        Command::Microlevel(a) => commands::microlevel::run(a),
        Command::Derive(a) => commands::derive::run(a),
        Command::Dipole(a) => commands::dipole::run(a),
        Command::Em(a) => commands::em::run(a),
        Command::Rotor(a) => commands::rotor::run(a),
        Command::Pod(a) => commands::pod::run(a),
        Command::Observability(a) => commands::observability::run(a),
    });
    if let Err(e) = result {
        let Some(code) = exit::code(&e, aeromag::io::atomic::interrupted()) else {
            // The interruption's error: the signal's thread removes the
            // temporaries and exits with 130/143.
            loop {
                std::thread::park();
            }
        };
        eprintln!("error: {}", exit::message(&e));
        std::process::exit(code);
    }
}

/// The environment variables that set how aeromag runs, checked before any
/// work: `AEROMAG_THREADS` (the number of threads; the library would ignore
/// a value it refuses) must be a whole number from 1 to 64.
fn check_environment() -> anyhow::Result<()> {
    use aeromag::core::parallel::{THREADS_VAR, threads_setting};
    if let Some(v) = std::env::var_os(THREADS_VAR) {
        let v = v.to_string_lossy();
        threads_setting(&v).map_err(|e| exit::bad_input!("{e}"))?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::CommandFactory;

    /// Every command, and every command under it, says what it does: none
    /// shows the shared input arguments' description as its own (a command
    /// without a doc comment of its own inherits it from the flattened
    /// `InputArgs`, as `level` did in `aeromag --help`).
    #[test]
    fn every_command_describes_itself() {
        fn check(cmd: &clap::Command, path: &str) {
            for sub in cmd.get_subcommands() {
                let path = format!("{path} {}", sub.get_name());
                let about = sub.get_about().map(|a| a.to_string()).unwrap_or_default();
                assert!(!about.trim().is_empty(), "`{path}` has no description");
                assert!(
                    !about.starts_with("Input-file arguments"),
                    "`{path}` shows the input arguments' description: {about}"
                );
                check(sub, &path);
            }
        }
        check(&Cli::command(), "aeromag");
    }
}
