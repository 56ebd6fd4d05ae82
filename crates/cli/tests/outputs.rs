//! Outputs that never lie: an interrupted command leaves no temporary and
//! no partial file and exits 130 (SIGINT) / 143 (SIGTERM); output paths
//! are checked before the work starts.

mod common;
use common::*;
use std::path::Path;
use std::process::Command;
use std::time::Duration;

/// Every file under `dir`, relative names.
fn files(dir: &Path) -> Vec<String> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        let Ok(rd) = std::fs::read_dir(&d) else {
            continue;
        };
        for e in rd.flatten() {
            let p = e.path();
            if p.is_dir() {
                stack.push(p);
            } else {
                out.push(p.strip_prefix(dir).unwrap().display().to_string());
            }
        }
    }
    out
}

#[cfg(unix)]
#[test]
fn interrupted_demo_leaves_no_temporary_and_exits_128_plus_signal() {
    let dir = tempfile::tempdir().unwrap();
    for (k, (signal, code, delay_ms)) in [
        (libc::SIGINT, 130, 200),
        (libc::SIGTERM, 143, 900),
        (libc::SIGINT, 130, 1600),
    ]
    .into_iter()
    .enumerate()
    {
        let out = dir.path().join(format!("demo{k}"));
        let child = Command::new(env!("CARGO_BIN_EXE_aeromag"))
            .args(["demo", "--quick", "--out", out.to_str().unwrap()])
            .stdout(std::process::Stdio::null())
            .stderr(std::process::Stdio::piped())
            .spawn()
            .unwrap();
        std::thread::sleep(Duration::from_millis(delay_ms));
        // SAFETY: sending a signal to our own child process.
        unsafe { libc::kill(child.id() as libc::pid_t, signal) };
        let o = child.wait_with_output().unwrap();
        let written = files(&out);
        if o.status.code() == Some(0) {
            // Finished before the signal: nothing to check but completeness.
            assert!(
                written.iter().any(|f| f.ends_with("summary.json")),
                "{written:?}"
            );
            continue;
        }
        assert_eq!(o.status.code(), Some(code), "{}", stderr(&o));
        assert!(stderr(&o).contains("interrupted"), "{}", stderr(&o));
        assert!(
            written.iter().all(|f| !f.ends_with(".tmp")),
            "temporaries left: {written:?}"
        );
    }
}

#[test]
fn output_paths_are_checked_before_the_work() {
    let dir = tempfile::tempdir().unwrap();
    let blocker = dir.path().join("file");
    std::fs::write(&blocker, "x").unwrap();
    // A folder where a file is expected, and a file where a folder is
    // expected: exit 2 at once, naming the path (the input does not even
    // need to exist: the check comes first).
    let o = aeromag(&[
        "compensate",
        "--model",
        "absent.json",
        "-i",
        "absent.csv",
        "--out",
        dir.path().to_str().unwrap(),
    ]);
    assert_code(&o, 2);
    assert!(
        stderr(&o).contains("cannot write") && stderr(&o).contains("folder"),
        "{}",
        stderr(&o)
    );
    let inside_file = blocker.join("out.csv");
    let o = aeromag(&[
        "level",
        "-i",
        "absent.csv",
        "--out",
        inside_file.to_str().unwrap(),
    ]);
    assert_code(&o, 2);
    assert!(stderr(&o).contains("cannot write"), "{}", stderr(&o));
    // A missing output folder is created.
    let nested = dir.path().join("a/b/model.json");
    let o = aeromag(&[
        "calibrate",
        "-i",
        "absent.csv",
        "--model",
        nested.to_str().unwrap(),
    ]);
    assert_code(&o, 2); // the input is missing …
    assert!(stderr(&o).contains("absent.csv"), "{}", stderr(&o));
    assert!(
        dir.path().join("a/b").is_dir(),
        "… but the folder was made first"
    );
    assert!(files(&dir.path().join("a")).is_empty());
}
