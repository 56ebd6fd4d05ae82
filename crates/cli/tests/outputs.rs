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

/// Found by fuzzing: `--out` naming the input replaced it (17 rows became
/// 5 with `--time-range`), a device or FIFO was replaced by a regular file
/// (`--out /dev/full` reported success; as root `/dev/null` was lost), and
/// a symbolic link by the file instead of writing the file it names.
#[cfg(unix)]
#[test]
fn outputs_never_replace_inputs_devices_or_links() {
    use std::os::unix::fs::FileTypeExt;
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let flight = simulate(d, "calibration", "1");
    let model = d.join("m.json");
    let s = |p: &Path| p.to_str().unwrap().to_string();
    assert_code(
        &aeromag(&["calibrate", "-i", &s(&flight), "--model", &s(&model)]),
        0,
    );
    let before = std::fs::read(&flight).unwrap();
    let model_before = std::fs::read(&model).unwrap();
    // The input, or the model, as the output: refused before any work.
    for (out, named) in [(&flight, "calibration.csv"), (&model, "m.json")] {
        let o = compensate(&model, &flight, out);
        assert_code(&o, 2);
        assert!(
            stderr(&o).contains("also an input") && stderr(&o).contains(named),
            "{}",
            stderr(&o)
        );
    }
    // Also through a link to the input.
    let link_to_input = d.join("link.csv");
    std::os::unix::fs::symlink(&flight, &link_to_input).unwrap();
    assert_code(&compensate(&model, &flight, &link_to_input), 2);
    assert_eq!(std::fs::read(&flight).unwrap(), before);
    assert_eq!(std::fs::read(&model).unwrap(), model_before);
    // Two outputs naming one file.
    let o = aeromag(&[
        "level",
        "-i",
        &s(&flight),
        "--out",
        &s(&d.join("l.csv")),
        "--crossovers",
        &s(&d.join("l.csv")),
    ]);
    assert_code(&o, 2);
    assert!(
        stderr(&o).contains("name the same output file"),
        "{}",
        stderr(&o)
    );
    // A link to an output: the file it names is written, the link stays.
    let target = d.join("comp.csv");
    let link = d.join("comp-link.csv");
    std::os::unix::fs::symlink("comp.csv", &link).unwrap();
    assert_code(&compensate(&model, &flight, &link), 0);
    assert!(
        std::fs::symlink_metadata(&link)
            .unwrap()
            .file_type()
            .is_symlink()
    );
    let written = std::fs::read(&target).unwrap();
    assert!(written.starts_with(b"time,") || written.starts_with(b"#"));
    // comp_flag as the help documents it: 0 or 1, not 0.0.
    let text = String::from_utf8(written.clone()).unwrap();
    let row = text.lines().filter(|l| !l.starts_with('#')).nth(1).unwrap();
    assert!(row.ends_with(",0") || row.ends_with(",1"), "{row}");
    // A FIFO: written through, and still a FIFO afterwards.
    let fifo = d.join("fifo");
    let c = std::ffi::CString::new(s(&fifo)).unwrap();
    // SAFETY: a valid NUL-terminated path; mkfifo reads nothing else.
    assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0);
    let reader = {
        let fifo = fifo.clone();
        std::thread::spawn(move || std::fs::read(fifo).unwrap())
    };
    assert_code(&compensate(&model, &flight, &fifo), 0);
    assert_eq!(reader.join().unwrap(), written);
    assert!(std::fs::metadata(&fifo).unwrap().file_type().is_fifo());
}

/// `report` with a FIFO that no process reads in the place of
/// figures.json waited forever (killed at 10 s): a FIFO with no reader is
/// refused before the work by the shared output check (exit 2, naming
/// it), as a socket is; a FIFO with a reader is still written through
/// (`outputs_never_replace_inputs_devices_or_links`).
#[cfg(unix)]
#[test]
fn a_fifo_that_no_process_reads_is_bad_input() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let flight = simulate(d, "calibration", "1");
    let rep = d.join("rep");
    std::fs::create_dir(&rep).unwrap();
    mkfifo(&rep.join("figures.json"));
    let mut child = Command::new(env!("CARGO_BIN_EXE_aeromag"))
        .args(["report", "--input", flight.to_str().unwrap(), "--out"])
        .arg(&rep)
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let start = std::time::Instant::now();
    while child.try_wait().unwrap().is_none() {
        if start.elapsed() > Duration::from_secs(30) {
            child.kill().unwrap();
            panic!("report still waits on the FIFO after 30 s");
        }
        std::thread::sleep(Duration::from_millis(50));
    }
    let o = child.wait_with_output().unwrap();
    assert_code(&o, 2);
    assert!(
        stderr(&o).contains("figures.json") && stderr(&o).contains("FIFO"),
        "{}",
        stderr(&o)
    );
    assert!(!rep.join("index.html").exists());
}

/// `--out X.xyz` writes Geosoft XYZ and `--out X.h5` HDF5 (both were CSV
/// under that name), which read back to the table the CSV holds; a grid or
/// model name is refused before the work.
#[test]
fn xyz_hdf5_and_mat_outputs_hold_the_csv_table_and_other_formats_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let cal = simulate(dir.path(), "calibration", "3");
    let model = dir.path().join("m.json");
    assert_code(
        &aeromag(&[
            "calibrate",
            cal.to_str().unwrap(),
            "--model",
            model.to_str().unwrap(),
            "--eddy-lag",
            "none",
        ]),
        0,
    );
    let (csv, xyz, h5, mat) = (
        dir.path().join("c.csv"),
        dir.path().join("c.xyz"),
        dir.path().join("c.h5"),
        dir.path().join("c.mat"),
    );
    for out in [&csv, &xyz, &h5, &mat] {
        assert_code(&compensate(&model, &cal, out), 0);
    }
    let text = std::fs::read_to_string(&xyz).unwrap();
    assert!(
        text.starts_with("/ XYZ export of aeromag "),
        "{}",
        &text[..80]
    );
    let a = aeromag::Flight::read(&csv).unwrap();
    for other in [&xyz, &h5, &mat] {
        let b = aeromag::Flight::read(other).unwrap();
        let (ta, tb) = (a.table(), b.table());
        assert_eq!(ta.column_names(), tb.column_names());
        for name in ta.column_names() {
            let bits = |t: &aeromag::io::FlightTable| -> Vec<u64> {
                t.column(name)
                    .unwrap()
                    .iter()
                    .map(|v| v.to_bits())
                    .collect()
            };
            assert_eq!(bits(ta), bits(tb), "{name} in {}", other.display());
            let integer = |t: &aeromag::io::FlightTable| t.get(name).unwrap().integer_text();
            assert_eq!(integer(ta), integer(tb), "{name} in {}", other.display());
        }
    }
    for refused in ["c.he5", "c.tif", "c.json"] {
        let out = dir.path().join(refused);
        let o = aeromag(&[
            "compensate",
            "--model",
            "absent.json",
            "-i",
            "absent.csv",
            "--out",
            out.to_str().unwrap(),
        ]);
        assert_code(&o, 2);
        assert!(
            stderr(&o)
                .contains("CSV (.csv), Geosoft XYZ (.xyz), HDF5 (.h5) or a MATLAB MAT-file (.mat)"),
            "{}",
            stderr(&o)
        );
        assert!(!out.exists());
    }
}
