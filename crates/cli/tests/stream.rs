//! `aeromag stream` and `compensate --causal` as commands: a simulated
//! survey replayed through a pipe, through TCP and through UDP on the
//! loopback (127.0.0.1 only), with corrupted lines injected, against the
//! batch file of `compensate --causal`.

mod common;
use common::*;
use std::io::{BufRead, BufReader, Read, Write};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};

/// A model (4-cycle box, seed 5), the survey's lines (header first, no
/// comments) and `compensate --causal`'s output lines.
fn setup(dir: &Path) -> (PathBuf, Vec<String>, Vec<String>) {
    let cal = simulate(dir, "calibration", "5");
    let model = dir.join("m.json");
    let o = aeromag(&[
        "calibrate",
        "-i",
        cal.to_str().unwrap(),
        "--model",
        model.to_str().unwrap(),
    ]);
    assert_code(&o, 0);
    let survey = simulate(dir, "survey", "6");
    let lines: Vec<String> = std::fs::read_to_string(&survey)
        .unwrap()
        .lines()
        .filter(|l| !l.starts_with('#'))
        .take(6001)
        .map(str::to_string)
        .collect();
    let input = dir.join("in.csv");
    std::fs::write(&input, lines.join("\n") + "\n").unwrap();
    let out = dir.join("causal.csv");
    let o = aeromag(&[
        "compensate",
        "--causal",
        "--model",
        model.to_str().unwrap(),
        "-i",
        input.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_code(&o, 0);
    assert!(stdout(&o).contains("causal"), "{}", stdout(&o));
    let want = std::fs::read_to_string(&out)
        .unwrap()
        .lines()
        .map(str::to_string)
        .collect();
    (model, lines, want)
}

/// `aeromag stream --model MODEL` with its standard streams piped.
fn piped_stream(model: &Path) -> Child {
    piped_stream_with(model, &[])
}

/// `aeromag stream --model MODEL ARGS…` with its standard streams piped.
fn piped_stream_with(model: &Path, args: &[&str]) -> Child {
    Command::new(env!("CARGO_BIN_EXE_aeromag"))
        .args(["stream", "--model", model.to_str().unwrap()])
        .args(args)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap()
}

/// `mag_interf`, `mag_comp` of an output line.
fn values(line: &str) -> (String, String) {
    let v: Vec<&str> = line.rsplitn(4, ',').collect();
    (v[2].to_string(), v[1].to_string())
}

/// The flag of an output line.
fn flag(line: &str) -> &str {
    line.rsplit(',').next().unwrap()
}

/// Every output line of an input data line carries the batch file's values.
fn assert_same(got: &[String], want: &[String]) {
    assert_eq!(got.len(), want.len());
    for (k, (g, w)) in got.iter().zip(want).enumerate() {
        assert_eq!(values(g), values(w), "data row {k}");
    }
}

#[test]
fn a_pipe_gives_the_causal_batch_values_and_flags_bad_lines() {
    let d = tempfile::tempdir().unwrap();
    let (model, lines, want) = setup(d.path());
    // Inject a malformed line, a time going back and a line with a text
    // cell after data rows 100, 200 and 300.
    let mut input = vec![lines[0].clone()];
    for (k, l) in lines[1..].iter().enumerate() {
        input.push(l.clone());
        match k {
            100 => input.push("garbage".into()),
            200 => input.push(lines[1].clone()),
            300 => input.push(format!("x{l}")),
            _ => {}
        }
    }
    let (out, err) = through_pipe(&model, &[], &input);
    assert_eq!(
        out[0],
        format!("{},mag_interf,mag_comp,comp_flag", lines[0])
    );
    assert_eq!(out.len(), input.len());
    let (mut kept, mut flags) = (Vec::new(), Vec::new());
    for (i, l) in out[1..].iter().enumerate() {
        match i {
            101 | 202 | 303 => flags.push(flag(l).to_string()),
            _ => kept.push(l.clone()),
        }
    }
    assert_eq!(flags, ["4", "3", "4"]);
    assert_same(&kept, &want[1..]);
    assert!(
        err.contains("6003 lines: 6000 compensated (0 runs restarted), 0 with missing values, 1 with time going back, 2 malformed"),
        "{err}"
    );
    // Why, with the first line of each kind (no reason was given).
    assert!(
        err.contains("warning: 2 lines malformed (the first: data line 102: column \"time\": \"garbage\" is not a number)"),
        "{err}"
    );
}

/// A stream whose `mag` is in tesla was compensated to tens of nT and
/// flagged 0: every line flagged 1, and standard error says why.
#[test]
fn a_stream_in_tesla_is_not_compensated_and_says_why() {
    let d = tempfile::tempdir().unwrap();
    let (model, lines, _) = setup(d.path());
    let mag = lines[0].split(',').position(|n| n == "mag").unwrap();
    let mut input = vec![lines[0].clone()];
    for l in &lines[1..101] {
        let mut cells: Vec<String> = l.split(',').map(str::to_string).collect();
        cells[mag] = format!("{:e}", cells[mag].parse::<f64>().unwrap() * 1e-9);
        input.push(cells.join(","));
    }
    let (out, err) = through_pipe(&model, &[], &input);
    assert!(out[1..].iter().all(|l| flag(l) == "1"), "{}", out[1]);
    assert!(
        err.contains("100 lines: 0 compensated (0 runs restarted), 100 with missing values"),
        "{err}"
    );
    assert!(
        err.contains("warning: 100 lines with a reading below 1000 nT, no reading of Earth's field (the first: data line 1: mag = ")
            && err.contains("not tesla"),
        "{err}"
    );
}

/// A file as `aeromag simulate` writes it, its `#` lines first, streams as
/// the same lines without them do: the comment lines come back as they
/// are, in their place, and are not counted as data lines.
#[test]
fn a_simulated_file_streams_with_its_comment_lines() {
    let d = tempfile::tempdir().unwrap();
    let (model, lines, want) = setup(d.path());
    let file = std::fs::read_to_string(d.path().join("survey").join("survey.csv")).unwrap();
    let comments: Vec<String> = file
        .lines()
        .take_while(|l| l.starts_with('#'))
        .map(str::to_string)
        .collect();
    assert!(comments.len() >= 2, "{comments:?}");
    let mut input = comments.clone();
    input.extend(lines[..3001].iter().cloned());
    input.push("# a note among the data".into());
    input.extend(lines[3001..].iter().cloned());
    let (out, err) = through_pipe(&model, &[], &input);
    assert_eq!(out[..comments.len()], comments[..]);
    let rest = &out[comments.len()..];
    assert_eq!(
        rest[0],
        format!("{},mag_interf,mag_comp,comp_flag", lines[0])
    );
    assert_eq!(rest[3001], "# a note among the data");
    let data: Vec<String> = rest[1..3001].iter().chain(&rest[3002..]).cloned().collect();
    assert_same(&data, &want[1..]);
    assert!(
        err.contains("6000 lines: 6000 compensated (0 runs restarted), 0 with missing values, 0 with time going back, 0 malformed"),
        "{err}"
    );
}

/// A running `aeromag stream` server and the address it listens on.
struct Server(Child, String);

impl Drop for Server {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

fn server(model: &Path, flag: &str) -> Server {
    server_with(model, flag, &[])
}

fn server_with(model: &Path, flag: &str, args: &[&str]) -> Server {
    let mut child = Command::new(env!("CARGO_BIN_EXE_aeromag"))
        .args([
            "stream",
            "--model",
            model.to_str().unwrap(),
            flag,
            "127.0.0.1:0",
        ])
        .args(args)
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut err = BufReader::new(child.stderr.take().unwrap());
    let mut first = String::new();
    err.read_line(&mut first).unwrap();
    let addr = first
        .trim()
        .strip_prefix("listening on ")
        .unwrap_or_else(|| panic!("{first}"))
        .trim_end_matches(" (UDP)")
        .to_string();
    // Keep draining stderr so the server never blocks on it.
    std::thread::spawn(move || {
        let _ = std::io::copy(&mut err, &mut std::io::sink());
    });
    Server(child, addr)
}

/// The data lines sent to a TCP server in two connections (rows 1–3000,
/// then the rest), each with the header: the data lines that come back.
fn over_two_connections(addr: &str, lines: &[String]) -> Vec<String> {
    let mut got = Vec::new();
    for part in [&lines[1..3001], &lines[3001..]] {
        let mut conn = std::net::TcpStream::connect(addr).unwrap();
        let text = format!("{}\n{}\n", lines[0], part.join("\n"));
        let mut w = conn.try_clone().unwrap();
        let writer = std::thread::spawn(move || {
            w.write_all(text.as_bytes()).unwrap();
            w.shutdown(std::net::Shutdown::Write).unwrap();
        });
        let mut back = String::new();
        conn.read_to_string(&mut back).unwrap();
        writer.join().unwrap();
        let back: Vec<String> = back.lines().map(str::to_string).collect();
        assert!(back[0].ends_with("mag_interf,mag_comp,comp_flag"));
        got.extend(back[1..].iter().cloned());
    }
    got
}

#[test]
fn tcp_on_the_loopback_survives_the_peer_reconnecting() {
    let d = tempfile::tempdir().unwrap();
    let (model, lines, want) = setup(d.path());
    let srv = server(&model, "--listen");
    let got = over_two_connections(&srv.1, &lines);
    // The second connection carries on where the first stopped (same
    // header, time step within the run): the batch values throughout.
    assert_same(&got, &want[1..]);
    assert_eq!(flag(&got[3000]), "0");
}

#[test]
fn udp_datagrams_are_answered_to_their_sender() {
    let d = tempfile::tempdir().unwrap();
    let (model, lines, want) = setup(d.path());
    let srv = server(&model, "--udp");
    let sock = std::net::UdpSocket::bind("127.0.0.1:0").unwrap();
    sock.set_read_timeout(Some(std::time::Duration::from_secs(20)))
        .unwrap();
    sock.connect(&srv.1).unwrap();
    let mut got = Vec::new();
    let mut buf = vec![0u8; 65_536];
    // The header with the first 20 lines, then 20 lines per datagram.
    for (k, chunk) in lines[1..201].chunks(20).enumerate() {
        let mut text = chunk.join("\n") + "\n";
        if k == 0 {
            text = format!("{}\n{text}", lines[0]);
        }
        sock.send(text.as_bytes()).unwrap();
        let n = sock.recv(&mut buf).unwrap();
        let back = String::from_utf8_lossy(&buf[..n]).to_string();
        let mut back: Vec<String> = back.lines().map(str::to_string).collect();
        if k == 0 {
            assert!(back.remove(0).ends_with("mag_interf,mag_comp,comp_flag"));
        }
        assert_eq!(back.len(), chunk.len());
        got.extend(back);
    }
    assert_same(&got, &want[1..201]);
}

#[test]
fn stream_and_causal_errors_exit_2() {
    let d = tempfile::tempdir().unwrap();
    let (model, _, _) = setup(d.path());
    let mut child = piped_stream(&model);
    child
        .stdin
        .take()
        .unwrap()
        .write_all(b"time,flux_x,flux_y,mag\n1,2,3,4\n")
        .unwrap();
    let o = child.wait_with_output().unwrap();
    assert_code(&o, 2);
    assert!(
        stderr(&o).contains("no column for `flux_z`"),
        "{}",
        stderr(&o)
    );
    let o = aeromag(&[
        "compensate",
        "--sample-rate",
        "10",
        "--model",
        "m.json",
        "-i",
        "x.csv",
        "--out",
        "o.csv",
    ]);
    assert_code(&o, 2);
    assert!(stderr(&o).contains("--causal"), "{}", stderr(&o));
    // An estimator's flag with the other estimator was ignored silently.
    let m = model.to_str().unwrap();
    for (args, says) in [
        (
            ["--adapt", "rls", "--permanent-drift", "5"],
            "--permanent-drift applies to --adapt kalman only",
        ),
        (
            ["--adapt", "kalman", "--memory", "900"],
            "--memory applies to --adapt rls only",
        ),
    ] {
        let mut all = vec!["stream", "--model", m];
        all.extend(args);
        let o = aeromag(&all);
        assert_code(&o, 2);
        assert!(stderr(&o).contains(says), "{}", stderr(&o));
    }
}

/// At real-time pace (one line, then its answer, then the next), every
/// line comes back before the next is sent: nothing waits for later input.
#[test]
fn each_line_comes_back_before_the_next_is_sent() {
    let d = tempfile::tempdir().unwrap();
    let (model, lines, want) = setup(d.path());
    let srv = server(&model, "--listen");
    let mut conn = std::net::TcpStream::connect(&srv.1).unwrap();
    conn.set_read_timeout(Some(std::time::Duration::from_secs(20)))
        .unwrap();
    let mut reader = BufReader::new(conn.try_clone().unwrap());
    let mut answer = String::new();
    conn.write_all(format!("{}\n", lines[0]).as_bytes())
        .unwrap();
    reader.read_line(&mut answer).unwrap();
    assert!(answer.trim_end().ends_with("comp_flag"), "{answer}");
    let mut got = Vec::new();
    for l in &lines[1..51] {
        conn.write_all(format!("{l}\n").as_bytes()).unwrap();
        answer.clear();
        reader
            .read_line(&mut answer)
            .expect("the answer to the line just sent");
        got.push(answer.trim_end().to_string());
    }
    assert_same(&got, &want[1..51]);
}

/// Lines in, lines out through a piped `aeromag stream ARGS…`: stdout's
/// lines and stderr.
fn through_pipe(model: &Path, args: &[&str], input: &[String]) -> (Vec<String>, String) {
    let mut child = piped_stream_with(model, args);
    let mut stdin = child.stdin.take().unwrap();
    let text = input.join("\n") + "\n";
    let writer = std::thread::spawn(move || stdin.write_all(text.as_bytes()).unwrap());
    let o = child.wait_with_output().unwrap();
    writer.join().unwrap();
    assert_code(&o, 0);
    (stdout(&o).lines().map(str::to_string).collect(), stderr(&o))
}

/// `--adapt kalman`: the same values through a pipe and through TCP with
/// the peer reconnecting (the state goes on), the coefficients with their
/// standard deviations on stderr, a stream without the ground speed bad
/// input unless --speed gives it; `--adapt rls` needs no speed.
#[test]
fn adaptive_streams_agree_through_pipe_and_tcp() {
    let d = tempfile::tempdir().unwrap();
    let (model, lines, want) = setup(d.path());
    let (piped, err) = through_pipe(&model, &["--adapt", "kalman"], &lines);
    assert_eq!(piped.len(), lines.len());
    assert!(err.contains("coefficients now"), "{err}");
    assert!(err.contains("p_x") && err.contains(" ± "), "{err}");
    // The coefficients moved: the values are not the fixed model's.
    let moved = piped[1..]
        .iter()
        .zip(&want[1..])
        .filter(|(g, w)| values(g) != values(w))
        .count();
    assert!(
        moved > 5000,
        "{moved} of 6000 lines differ from the fixed model"
    );

    let srv = server_with(&model, "--listen", &["--adapt", "kalman"]);
    let mut got = vec![piped[0].clone()];
    got.extend(over_two_connections(&srv.1, &lines));
    assert_eq!(got, piped);

    // Without vn, ve: bad input, unless --speed; rls needs none.
    let cols = "time,flux_x,flux_y,flux_z,mag";
    let short = ["1,20000,1000,45000,49300".to_string()];
    let mut child = piped_stream_with(&model, &["--adapt", "kalman", "--columns-in", cols]);
    drop(child.stdin.take());
    let o = child.wait_with_output().unwrap();
    assert_code(&o, 2);
    assert!(stderr(&o).contains("--speed"), "{}", stderr(&o));
    for args in [
        &["--adapt", "kalman", "--speed", "70", "--columns-in", cols][..],
        &["--adapt", "rls", "--columns-in", cols][..],
    ] {
        let (out, _) = through_pipe(&model, args, &short);
        assert_eq!(out.len(), 2, "{args:?}");
        assert!(out[1].ends_with(",2"), "{args:?}: {}", out[1]);
    }
}
