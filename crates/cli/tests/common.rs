//! Helpers shared by the CLI integration tests.
#![allow(dead_code)]

use std::path::Path;
use std::process::{Command, Output};

/// Run `aeromag COMMAND -i INPUT --out OUT EXTRA…`.
pub fn run_on(command: &str, input: &Path, out: &Path, extra: &[&str]) -> Output {
    let mut args = vec![
        command,
        "-i",
        input.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ];
    args.extend(extra);
    aeromag(&args)
}

/// Run the `aeromag` binary with arguments.
pub fn aeromag(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_aeromag"))
        .args(args)
        .output()
        .expect("spawn aeromag")
}

/// Run in a working directory.
pub fn aeromag_in(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_aeromag"))
        .current_dir(dir)
        .args(args)
        .output()
        .expect("spawn aeromag")
}

pub fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

pub fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// Assert the exit code, showing the output on failure.
pub fn assert_code(o: &Output, code: i32) {
    assert_eq!(
        o.status.code(),
        Some(code),
        "expected exit code {code}\nstdout:\n{}\nstderr:\n{}",
        stdout(o),
        stderr(o)
    );
}

/// `aeromag <family> apply --model MODEL --input INPUT --out OUT` (rotor,
/// pod).
pub fn apply(family: &str, model: &Path, input: &Path, out: &Path) -> Output {
    with_model(&[family, "apply"], model, input, out)
}

/// `aeromag compensate --model MODEL --input INPUT --out OUT`.
#[allow(dead_code)] // not every test binary compensates
pub fn compensate(model: &Path, input: &Path, out: &Path) -> Output {
    with_model(&["compensate"], model, input, out)
}

/// `aeromag <command…> --model MODEL --input INPUT --out OUT`.
fn with_model(command: &[&str], model: &Path, input: &Path, out: &Path) -> Output {
    let mut args = command.to_vec();
    args.extend([
        "--model",
        model.to_str().unwrap(),
        "--input",
        input.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    aeromag(&args)
}

/// `aeromag simulate SCENARIO --seed SEED --out DIR/SCENARIO`; the CSV written.
pub fn simulate(dir: &Path, scenario: &str, seed: &str) -> std::path::PathBuf {
    simulate_with(dir, scenario, seed, None)
}

/// [`simulate`] with a scenario file (`--config`).
pub fn simulate_with(
    dir: &Path,
    scenario: &str,
    seed: &str,
    config: Option<&Path>,
) -> std::path::PathBuf {
    let out = dir.join(scenario);
    let mut args = vec![
        "simulate",
        scenario,
        "--seed",
        seed,
        "--out",
        out.to_str().unwrap(),
    ];
    if let Some(c) = config {
        args.extend(["--config", c.to_str().unwrap()]);
    }
    assert_code(&aeromag(&args), 0);
    out.join(format!("{}.csv", scenario.replace('-', "_")))
}

/// The installation of the simulated towed pod (`pod fit` arguments).
pub const POD_SETUP: [&str; 10] = [
    "--cable-length-m",
    "40",
    "--attach-m",
    "0,0,1.2",
    "--inclination-deg",
    "45",
    "--grad-north-nt-per-km",
    "5.91",
    "--grad-up-nt-per-km",
    "-25.91",
];

/// Every file under `dir` (hidden ones too), by relative name, with its
/// bytes: for checking that a refused or interrupted run left a folder as
/// it was (no file replaced, no temporary or staging folder left).
pub fn tree(dir: &Path) -> std::collections::BTreeMap<String, Vec<u8>> {
    let mut files = std::collections::BTreeMap::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                stack.push(p);
            } else {
                let name = p.strip_prefix(dir).unwrap().display().to_string();
                // A FIFO is not read (that would wait for a writer).
                let bytes = if p.is_file() {
                    std::fs::read(&p).unwrap()
                } else {
                    b"(not a file)".to_vec()
                };
                files.insert(name, bytes);
            }
        }
    }
    files
}

/// Make a FIFO at `path`.
#[cfg(unix)]
pub fn mkfifo(path: &Path) {
    let c = std::ffi::CString::new(path.to_str().unwrap()).unwrap();
    // SAFETY: a valid NUL-terminated path; mkfifo reads nothing else.
    assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0);
}
