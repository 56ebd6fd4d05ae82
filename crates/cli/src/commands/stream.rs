//! `aeromag stream`: compensate samples as they arrive (library:
//! [`aeromag::online::LineStream`]).

use aeromag::online::{Adapt, AdaptOptions, LineStream, StreamOptions};
use aeromag::{ColumnMap, ModelFile, TlModel};
use std::io::{BufReader, Write};
use std::path::PathBuf;

/// Compensate samples as they arrive, one CSV line at a time, with a model
/// fitted by `aeromag calibrate` (applied causally: the values of
/// `aeromag compensate --causal`, value for value).
///
/// Reads lines from standard input (default), a TCP connection
/// (--listen HOST:PORT: the compensated lines go back on the same
/// connection; when the peer disconnects the next connection is served,
/// the state kept when its header is the same) or UDP datagrams
/// (--udp HOST:PORT: each datagram's lines answered to its sender).
/// The first line is the header (the column names) unless --columns-in
/// names the columns. Each line is written back, flushed, with
/// `mag_interf` and `mag_comp` (nT) and `comp_flag`: 0 compensated,
/// 1 missing value (or a `mag` or vector magnitude below 1000 nT, no
/// reading of Earth's field: a dropout value or another unit; or an
/// interference beyond any magnetic field, 10⁶ nT),
/// 2 compensated after a gap (run restarted), 3 time going back (ignored;
/// after 10 such lines in a row that advance together, the stream runs on
/// their clock), 4 malformed line (or a `mag`/`flux_*` value beyond 10⁶
/// nT). Bad lines never stop the stream; the counts go to standard error
/// when a stream ends, with the first line of each kind not compensated
/// and why. Comment lines (`#` first, as in a CSV file: a simulated
/// file's `# units:` lines) and blank lines are written back as they are,
/// in their place.
///
/// With --adapt the coefficients start at the model's and are updated by
/// every compensated sample, after it is compensated: `kalman`, the
/// thesis' forward filter with the field states (the permanent terms
/// drifting as random walks, the field model without a base station; it
/// needs the ground speed: `vn`, `ve` columns or --speed), or `rls`,
/// recursive least squares with forgetting, for comparison. The final
/// coefficients and their standard deviations go to standard error.
///
/// Examples:
///   aeromag stream --model model.json < survey.csv > survey_comp.csv
///   aeromag stream --model model.json --adapt kalman < flight.csv > comp.csv
///   aeromag stream --model model.json --listen 127.0.0.1:5555
#[derive(Debug, clap::Args)]
#[command(verbatim_doc_comment)]
pub struct Args {
    /// Model file written by `aeromag calibrate` (one sensor).
    #[arg(long, value_name = "MODEL.json")]
    model: PathBuf,
    /// The input's column names, comma-separated, when the stream has no
    /// header line.
    #[arg(long, value_name = "NAMES")]
    columns_in: Option<String>,
    /// Map canonical names onto the stream's columns,
    /// e.g. `mag=mag_1_uc,flux_x=flux_a_x`.
    #[arg(long, value_name = "MAP")]
    columns: Option<String>,
    /// The sample rate whose interval × 1.5 breaks a run (default: the
    /// calibration's, recorded in the model file).
    #[arg(long, value_name = "HZ")]
    sample_rate: Option<f64>,
    /// Serve TCP connections on HOST:PORT instead of standard input.
    #[arg(long, value_name = "HOST:PORT", conflicts_with = "udp")]
    listen: Option<String>,
    /// Serve UDP datagrams on HOST:PORT instead of standard input.
    #[arg(long, value_name = "HOST:PORT")]
    udp: Option<String>,
    /// Adapt the coefficients as samples arrive: kalman or rls.
    #[arg(long, value_name = "METHOD")]
    adapt: Option<Adapt>,
    /// Ground speed, m/s, when the stream has no vn, ve columns (--adapt
    /// kalman; at most 1000). With lat, lon in the stream, 10 s stretches
    /// whose path gives a speed far from it are warned of.
    #[arg(long, value_name = "M/S", requires = "adapt")]
    speed: Option<f64>,
    /// Random-walk intensity of the permanent coefficients, nT/√h
    /// (--adapt kalman; default 0.5, at most 50).
    #[arg(long, value_name = "NT_PER_SQRT_H", requires = "adapt")]
    permanent_drift: Option<f64>,
    /// q₁ of the field model, nT²/m^(2n−1) (--adapt kalman; default: the
    /// on-board value of the model's order).
    #[arg(long, value_name = "Q1", requires = "adapt")]
    field_q1: Option<f64>,
    /// Memory of the recursive least squares, s (--adapt rls; default 1800,
    /// at least 300).
    #[arg(long, value_name = "S", requires = "adapt")]
    memory: Option<f64>,
}

pub fn run(a: Args) -> anyhow::Result<()> {
    // The estimators' own flags with the other estimator were ignored
    // without a word (`--adapt rls --permanent-drift 5`).
    let given = |flag: &'static str, set: bool| set.then_some(flag);
    let misplaced = match a.adapt {
        Some(Adapt::Rls) => [
            given("--speed", a.speed.is_some()),
            given("--permanent-drift", a.permanent_drift.is_some()),
            given("--field-q1", a.field_q1.is_some()),
        ]
        .into_iter()
        .flatten()
        .next()
        .map(|f| (f, "kalman")),
        Some(Adapt::Kalman) => given("--memory", a.memory.is_some()).map(|f| (f, "rls")),
        None => None,
    };
    if let Some((flag, method)) = misplaced {
        anyhow::bail!(aeromag::Error::bad_input(format!(
            "{flag} applies to --adapt {method} only"
        )));
    }
    // A multi-sensor model was refused as "not a `tolles-lawson` model
    // (written by `aeromag calibrate`)", which it was.
    if aeromag::model_file::kind_of(&a.model)? == aeromag::compensation::model_file::TL_SENSORS_KIND
    {
        anyhow::bail!(aeromag::Error::bad_file(
            a.model.display().to_string(),
            "a model of several sensors (`calibrate --mag A,B`): stream compensates one sensor; \
             fit its model alone (`calibrate --mag A`), or compensate the recorded flight with \
             `aeromag compensate --causal`"
        ));
    }
    let model = TlModel::read(&a.model)?;
    let opts = StreamOptions {
        columns: match &a.columns {
            Some(m) => ColumnMap::parse(m)?,
            None => ColumnMap::new(),
        },
        sample_rate_hz: a.sample_rate,
        adapt: a.adapt,
        adapt_options: adapt_options(&a),
        speed_m_s: a.speed,
    };
    let mut stream = LineStream::new(&model, &opts, a.columns_in.as_deref())?;
    if let Some(addr) = &a.listen {
        return serve_tcp(&mut stream, addr);
    }
    if let Some(addr) = &a.udp {
        return serve_udp(&mut stream, addr);
    }
    let stdin = std::io::stdin().lock();
    let stdout = std::io::stdout().lock();
    // The connection is named for its input; a failed write is on the
    // output ("cannot write 'standard input'" said otherwise).
    let result = stream
        .serve(stdin, stdout, "standard input")
        .map_err(|e| match e {
            aeromag::Error::Write { source, .. } => aeromag::Error::Write {
                path: "standard output".into(),
                source,
            },
            e => e,
        });
    eprintln!("{}", stream.counts());
    print_issues(&stream);
    print_coefficients(&stream);
    Ok(result?)
}

/// The adaptive estimators' settings from the flags.
fn adapt_options(a: &Args) -> AdaptOptions {
    let mut o = AdaptOptions {
        field_q1: a.field_q1,
        ..AdaptOptions::default()
    };
    if let Some(d) = a.permanent_drift {
        o.kalman.permanent_drift_nt_per_sqrt_h = d;
    }
    if let Some(m) = a.memory {
        o.rls.memory_s = m;
    }
    o
}

/// Why lines were not compensated, on standard error (each kind's count
/// and first line).
fn print_issues(stream: &LineStream) {
    for w in stream.issues().warnings() {
        eprintln!("{w}");
    }
}

/// The adapted coefficients on standard error (nothing without --adapt).
fn print_coefficients(stream: &LineStream) {
    let c = stream.coefficients();
    if !c.is_empty() {
        eprintln!("coefficients now (value ± standard deviation):");
        for (name, v, s) in c {
            // Far values (a hand-edited model) in exponent form.
            let v = if v.abs() < 1e9 {
                format!("{v:>12.6}")
            } else {
                format!("{v:>12.5e}")
            };
            eprintln!("  {name:<8} {v} ± {s:.3e}");
        }
    }
    if let Some(n) = stream.outliers().filter(|&n| n > 0) {
        eprintln!(
            "warning: {n} sample(s) not learnt from: their innovation was beyond 100 standard deviations \
             (an outlying reading; they were compensated with the coefficients of the time)"
        );
    }
}

/// Serve one TCP connection after another, for ever (Ctrl-C ends it).
fn serve_tcp(stream: &mut LineStream, addr: &str) -> anyhow::Result<()> {
    let listener = std::net::TcpListener::bind(addr)
        .map_err(|e| anyhow::anyhow!("cannot listen on {addr}: {e}"))?;
    eprintln!("listening on {}", listener.local_addr()?);
    for conn in listener.incoming() {
        let conn = match conn {
            Ok(c) => c,
            Err(e) => {
                eprintln!("warning: a connection failed: {e}");
                continue;
            }
        };
        let peer = conn
            .peer_addr()
            .map_or_else(|_| "a peer".to_string(), |p| p.to_string());
        let result = conn
            .try_clone()
            .map_err(|e| aeromag::Error::read(&peer, e))
            .and_then(|r| stream.serve(BufReader::new(r), &conn, &peer));
        if let Err(e) = result {
            eprintln!("warning: connection from {peer} ended: {e}");
            let _ = (&conn).write_all(format!("# error: {e}\n").as_bytes());
        }
        eprintln!("{peer} disconnected; so far {}", stream.counts());
        print_issues(stream);
        print_coefficients(stream);
    }
    Ok(())
}

/// Serve datagrams for ever: each datagram's lines answered to its sender
/// in one datagram (the first line of the first datagram is the header
/// unless --columns-in named the columns).
fn serve_udp(stream: &mut LineStream, addr: &str) -> anyhow::Result<()> {
    let socket = std::net::UdpSocket::bind(addr)
        .map_err(|e| anyhow::anyhow!("cannot listen on {addr}: {e}"))?;
    eprintln!("listening on {} (UDP)", socket.local_addr()?);
    let mut buf = vec![0u8; 65_536];
    let mut started = false;
    loop {
        let (n, from) = socket.recv_from(&mut buf)?;
        let peer = from.to_string();
        let mut input = &buf[..n];
        let mut out = Vec::new();
        let result = (|| {
            if !started {
                started = stream.start(&mut input, &mut out, &peer)?;
            }
            stream.lines(input, &mut out, &peer)
        })();
        if let Err(e) = result {
            eprintln!("warning: datagram from {peer}: {e}");
            out.extend_from_slice(format!("# error: {e}\n").as_bytes());
        }
        for chunk in out.chunks(65_000) {
            if let Err(e) = socket.send_to(chunk, from) {
                eprintln!("warning: cannot answer {peer}: {e}");
            }
        }
    }
}
