//! `aeromag observability`: what a calibration flight determines (library:
//! [`aeromag::observability`]).

use crate::input::InputArgs;
use crate::progress::Bars;
use aeromag::compensation::tolles_lawson::{Design, ExtraRequest, ExtraTerm, TermSet};

/// Observability and estimability of the interference coefficients on a
/// calibration flight (thesis sections 10 and 12).
///
/// Runs the Kalman filter of `calibrate --method kalman` (the external field
/// is a random process along the track, so it is marginalised, not filtered
/// away) and prints: the rank and condition number of the flight's
/// information about the coefficients (scaled by their prior), the
/// combinations of coefficients the flight cannot separate, in words, and
/// the estimability measure μ = sqrt(P_post/P_prior) of every coefficient
/// (near 0: determined by this flight; near 1: not; it depends on the prior,
/// σ = 1000 per coefficient here), and — easier to judge — each term's
/// effect uncertainty in nT: its standard deviation times the size of its
/// design column over a full calibration (1 for permanent terms, |B|/50000
/// for induced, |B|·(0.1 rad/s)/50000 for eddy terms: a 6°/s manoeuvre). A term whose effect is
/// uncertain by 1 nT or more is reported as not determined.
///
/// Use it to check a calibration flight, or a simulated pattern before
/// flying it (`aeromag simulate calibration --config pattern.toml`).
///
/// With `--extra cur_strb,cur_flap` the current terms (each channel times
/// the direction cosines, as in `calibrate --extra`; their effect is rated
/// with the channel's RMS on the flight) are assessed too:
/// a flight determines them only when each current changes at several
/// headings.
///
/// Example: `aeromag observability --input cal.csv --terms p3,i5,e8`
#[derive(Debug, clap::Args)]
#[command(verbatim_doc_comment)]
pub struct Args {
    #[command(flatten)]
    input: InputArgs,
    /// Term groups: p3, i6 or i5, e9 or e8, bias.
    #[arg(long, value_parser = |s: &str| TermSet::parse(s).map_err(|e| e.to_string()),
          default_value_t = Design::default().terms)]
    terms: TermSet,
    /// Extra regressors: recorded channels times the direction cosines,
    /// comma-separated (`calibrate --extra`, without `:lag`: lags are not
    /// assessed).
    #[arg(long, value_name = "NAME,…")]
    extra: Option<String>,
    /// Print JSON.
    #[arg(long)]
    json: bool,
}

pub fn run(a: Args) -> anyhow::Result<()> {
    let extras = match &a.extra {
        None => Vec::new(),
        Some(list) => {
            let requests = ExtraRequest::parse_list(list)
                .map_err(|e| aeromag::Error::bad_input(format!("--extra: {e}")))?;
            if let Some(r) = requests.iter().find(|r| r.lag) {
                return Err(aeromag::Error::bad_input(format!(
                    "--extra {}:lag: lags are not assessed here; give the channel alone",
                    r.channel
                ))
                .into());
            }
            requests
                .into_iter()
                .map(|r| ExtraTerm::new(r.channel))
                .collect()
        }
    };
    let names: Vec<&str> = extras.iter().map(|x| x.channel.as_str()).collect();
    let flight = a.input.load_canonical(&names)?;
    let terms = a
        .terms
        .with_extras(&extras)
        .map_err(|e| aeromag::Error::bad_input(format!("--extra: {e}")))?;
    let obs = aeromag::observability(&flight, &terms, None, &mut Bars::new())?;
    let o = &obs.observability;
    if a.json {
        println!("{}", serde_json::to_string_pretty(o)?);
        return Ok(());
    }
    let n = o.names.len();
    println!(
        "{}: {} coefficients ({}), {} rows",
        flight.file_label(),
        n,
        terms,
        obs.rows
    );
    println!(
        "information rank {} of {n}, condition number {:.2e}{}",
        o.rank,
        o.condition,
        if o.rank < n {
            " — some combinations are not observable"
        } else {
            ""
        }
    );
    if o.weak_combinations.is_empty() {
        println!("every combination of coefficients is determined by this flight");
    }
    for w in &o.weak_combinations {
        println!("  {w}");
    }
    // The term column as wide as the longest name (`cur_strb:e_x`).
    let w = obs
        .coefficients
        .iter()
        .map(|c| c.name.chars().count())
        .fold(8, usize::max);
    println!(
        "\n{:<w$} {:>10} {:>12} {:>16}  verdict",
        "term", "μ", "std", "effect σ (nT)"
    );
    for c in &obs.coefficients {
        println!(
            "{:<w$} {:>10.4} {:>12.3e} {:>16.4}  {}",
            c.name,
            c.mu,
            c.std,
            c.effect_std_nt,
            c.verdict.words()
        );
    }
    let undetermined = obs.undetermined();
    if !undetermined.is_empty() {
        println!(
            "\nthis flight cannot determine: {} — fly all four headings with roll, pitch and yaw manoeuvres, or drop these terms",
            undetermined.join(", ")
        );
    }
    Ok(())
}
