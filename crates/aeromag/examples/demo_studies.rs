//! The demo's studies as a library: run one (or the whole demo) and print
//! its typed summary and the rows the `aeromag demo` table shows.
//!
//! ```sh
//! cargo run --release -p aeromag --example demo_studies -- rotor
//! cargo run --release -p aeromag --example demo_studies -- demo OUT_DIR
//! ```

use aeromag::studies::{
    Demo, EmStudy, GradiometryStudy, PodStudy, PrintedSummary, RotorStudyRun, Study, StudyOutcome,
    StudySize,
};
use aeromag::{Error, Silent};

/// Run `study` quickly and print its summary and table rows.
fn show<S: Study>(study: S) -> Result<(), Error>
where
    <S::Outcome as StudyOutcome>::Summary: PrintedSummary,
{
    let out = study.run(StudySize::Quick, &mut Silent)?;
    let summary = out.summary();
    println!("{summary:#?}");
    for row in summary.printed() {
        println!("{:<56} {:>12}", row.key, row.value);
    }
    Ok(())
}

fn main() -> Result<(), Error> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    match args.first().map(String::as_str) {
        Some("rotor") | None => show(RotorStudyRun::default()),
        Some("pod") => show(PodStudy),
        Some("em") => show(EmStudy::default()),
        Some("gradiometry") => show(GradiometryStudy),
        Some("demo") => show(Demo {
            seed: 1,
            out: args.get(1).map_or_else(|| "demo-out".into(), Into::into),
        }),
        Some(other) => {
            eprintln!("unknown study `{other}`: rotor, pod, em, gradiometry or demo");
            std::process::exit(2);
        }
    }
}
