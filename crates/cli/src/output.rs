//! Writing a compensated flight and telling the user (`compensate`,
//! `rotor apply`, `pod apply`).

use crate::exit::bad_input;
use aeromag::io::atomic::{check_writable, check_writable_folder};
use aeromag::{Compensated, Flight, SensorsCompensated};
use aeromag_core::output_target::{OutputTarget, output_target, same_file};
use std::path::Path;

/// Add the compensation columns to the flight, write it to `out` and tell
/// the user: a warning for the rows that could not be compensated (kept
/// with the flag 1) and a summary naming the `model` file, with `detail` in
/// parentheses when not empty.
pub fn write_compensated(
    flight: Flight,
    out: Compensated,
    path: &Path,
    model: &Path,
    detail: &str,
) -> anyhow::Result<()> {
    let (missing, output) = (out.missing, out.output);
    let table = out.into_table(flight)?;
    aeromag::io::write_table(&table, path)?;
    let n = table.n_rows();
    if missing > 0 {
        eprintln!(
            "warning: {missing} of {n} rows could not be compensated ({}); they are kept with {} = 1",
            output.why_missing, output.flag
        );
    }
    let detail = if detail.is_empty() {
        String::new()
    } else {
        format!(" ({detail})")
    };
    println!(
        "compensated {} of {n} rows with {}{detail}; written to {}",
        n - missing,
        model.display(),
        path.display()
    );
    Ok(())
}

/// What `compensate` and `calibrate --compensated` say of a model: its
/// terms and method, and `how` it was applied (`, causal`; empty).
pub fn model_detail(model: &aeromag::TlModel, how: &str) -> String {
    format!("{} terms, method {}{how}", model.design.terms, model.method)
}

/// Writes `flight` with every sensor's compensated columns to `path` and
/// prints what was written (`compensate` and `calibrate --compensated` with
/// a multi-sensor model from `model`).
pub fn write_compensated_sensors(
    flight: Flight,
    out: SensorsCompensated,
    path: &Path,
    model: &Path,
    sensors: usize,
) -> anyhow::Result<()> {
    let missing = out.missing();
    let names: Vec<String> = out.columns().into_iter().map(|(n, _)| n).collect();
    let mut table = flight.into_table();
    out.add_to(&mut table)?;
    aeromag::io::write_table(&table, path)?;
    let n = table.n_rows();
    if missing > 0 {
        eprintln!(
            "warning: {missing} of {n} rows could not be compensated for every sensor (missing values); their columns are empty there"
        );
    }
    println!(
        "compensated {sensors} sensors on {n} rows with {}: {}; written to {}",
        model.display(),
        names.join(", "),
        path.display()
    );
    Ok(())
}

/// `aeromag em simulate` and `aeromag simulate em` (with the default number
/// of known positions): simulate, write, print the files.
pub fn simulate_em(
    config: Option<&Path>,
    seed: Option<u64>,
    out: Option<&Path>,
    print_config: bool,
    known_positions: usize,
) -> anyhow::Result<()> {
    if print_config {
        print!("{}", toml::to_string(&aeromag::em::command_default())?);
        return Ok(());
    }
    let text = config
        .map(aeromag::model_file::read_text_file)
        .transpose()?;
    let file = config.map_or_else(|| "defaults".to_string(), |p| p.display().to_string());
    let mut cfg = aeromag::em::parse_config(text.as_deref(), &file)?;
    if let Some(s) = seed {
        cfg.seed = s;
    }
    let out = out.ok_or_else(|| bad_input!("--out DIR is required"))?;
    // The five files checked before the synthesis (a folder in the place
    // of one failed with exit 1 after the first were replaced).
    let _created = simulation_folder(out, aeromag::em::SimulatedEm::FILE_NAMES, config)?;
    let spinner = crate::progress::spinner("simulating em");
    // A scenario file is named with the errors (with none, the message
    // named a file 'defaults' that does not exist).
    let files =
        aeromag::em::simulate_to_dir(&cfg, known_positions, out).map_err(|e| match config {
            Some(p) => anyhow::Error::new(e).context(format!("'{}'", p.display())),
            None => anyhow::Error::new(e),
        })?;
    spinner.finish_and_clear();
    println!(
        "simulated em (seed {}): {} frames × 3 channels at {} Hz ({} s, {} epochs of {} samples)",
        cfg.seed,
        files.frames,
        cfg.sample_rate_hz,
        cfg.duration_s,
        files.epochs,
        aeromag::em::study::STUDY_WINDOW_LEN
    );
    for (what, p) in [
        ("raw", &files.raw),
        ("system", &files.system),
        ("known", &files.known),
        ("truth", &files.truth),
        ("scenario", &files.scenario),
    ] {
        println!("  {what:<9} {}", p.display());
    }
    Ok(())
}

/// `aeromag dipole simulate` and `aeromag simulate gradiometer`.
pub fn simulate_gradiometer(
    config: Option<&Path>,
    seed: Option<u64>,
    out: Option<&Path>,
    print_config: bool,
) -> anyhow::Result<()> {
    let mut cfg = aeromag::gradiometry::read_config(config)?;
    if print_config {
        print!("{}", cfg.to_toml()?);
        return Ok(());
    }
    if let Some(s) = seed {
        cfg.seed = s;
        cfg.validate().map_err(|e| bad_input!("--seed: {e}"))?;
    }
    let out = out.ok_or_else(|| bad_input!("--out DIR is required"))?;
    let _created = simulation_folder(out, aeromag::gradiometry::SIMULATED_FILES, config)?;
    let files = aeromag::gradiometry::simulate_to_dir(&cfg, out)?;
    println!(
        "simulated gradiometer ({:?} system, {:?} gradiometer, {:?} {} m; seed {}): {} epochs × {} columns",
        cfg.system.motion,
        cfg.system.gradiometer,
        cfg.system.layout,
        cfg.system.baseline_m,
        cfg.seed,
        files.rows,
        files.columns
    );
    println!("  data      {}", files.csv.display());
    println!("  scenario  {}", files.scenario.display());
    Ok(())
}

/// Check, before any work, that a map picture (`--map`) is named `.png`
/// or `.svg`.
pub fn check_map(map: Option<&Path>) -> anyhow::Result<()> {
    if let Some(p) = map {
        aeromag::map::picture::PictureFormat::of_path(p)?;
    }
    Ok(())
}

/// The help of a command's `--out` flight table (the formats of
/// [`aeromag::io::TableFormat::of_path`]).
pub const TABLE_OUT_HELP: &str = "Output file: CSV, or Geosoft XYZ when it ends in `.xyz`, HDF5 \
     (one dataset per column, as MagNav/SGL files) in `.h5`, a MATLAB MAT-file in `.mat`";

/// Check, before any work, that a flight table can be written in the
/// format each of `tables` asks for (CSV, Geosoft XYZ for `.xyz`, HDF5 for
/// `.h5`, MATLAB for `.mat`; a grid or model name is bad input).
pub fn check_tables<'a>(tables: impl IntoIterator<Item = &'a Path>) -> anyhow::Result<()> {
    for p in tables {
        aeromag::io::TableFormat::of_path(p)?;
    }
    Ok(())
}

/// Check, before any work, that every output file can be written (its
/// folder is created if missing) and is neither one of the command's
/// `inputs` nor another of its outputs: bad input otherwise, so a long run
/// never ends on an unwritable path, and `--out` naming the input (which
/// the output replaced: 17 rows became 5 with `--time-range`) is refused.
/// A device or FIFO (`/dev/null`) is written as it is and may be named
/// twice.
pub fn check_files<'a>(
    outputs: impl IntoIterator<Item = &'a Path>,
    inputs: &[&Path],
) -> anyhow::Result<()> {
    let mut files: Vec<(&Path, std::path::PathBuf)> = Vec::new();
    for p in outputs {
        check_writable(p).map_err(|e| bad_input!("cannot write '{}': {e}", p.display()))?;
        let OutputTarget::File(target) =
            output_target(p).map_err(|e| bad_input!("cannot write '{}': {e}", p.display()))?
        else {
            continue;
        };
        if let Some(i) = inputs.iter().find(|i| same_file(&target, i)) {
            return Err(bad_input!(
                "'{}' is also an input of the command ('{}'): writing it would replace the input; \
                 name another output file",
                p.display(),
                i.display()
            ));
        }
        if let Some((q, _)) = files
            .iter()
            .find(|(_, t)| *t == target || same_file(t, &target))
        {
            return Err(bad_input!(
                "'{}' and '{}' name the same output file",
                q.display(),
                p.display()
            ));
        }
        files.push((p, target));
    }
    Ok(())
}

/// As [`check_files`] for an output folder.
pub fn check_folder(dir: &Path) -> anyhow::Result<()> {
    check_writable_folder(dir).map_err(|e| bad_input!("cannot write into '{}': {e}", dir.display()))
}

/// The files `names` a command writes into the folder `dir` as a set
/// ([`aeromag::model_file::write_files`]), checked before the command's
/// work as [`check_folder`] and [`check_files`] do (a folder in the place
/// of one is bad input at once, not an I/O error after the run).
pub fn check_folder_files<const N: usize>(
    dir: &Path,
    names: [&str; N],
    inputs: &[&Path],
) -> anyhow::Result<[std::path::PathBuf; N]> {
    check_folder(dir)?;
    let paths = names.map(|n| dir.join(n));
    check_files(paths.iter().map(|p| p.as_path()), inputs)?;
    Ok(paths)
}

/// A simulation's output folder `out` before the run: its files `names`
/// checked ([`check_folder_files`], the scenario file `config` not among
/// them), and the folder, if this run creates it, removed again if nothing
/// is written into it ([`NewFolder`]; also when the check fails).
pub fn simulation_folder<const N: usize>(
    out: &Path,
    names: [&str; N],
    config: Option<&Path>,
) -> anyhow::Result<NewFolder> {
    let created = NewFolder::before(out);
    let inputs: Vec<&Path> = config.into_iter().collect();
    check_folder_files(out, names, &inputs)?;
    Ok(created)
}

/// An output folder that a command is about to create (with the folders
/// above it that do not exist): removed again, when dropped, if the
/// command wrote nothing into it (a refused scenario left an empty folder
/// behind). Only empty folders are removed.
pub struct NewFolder(Vec<std::path::PathBuf>);

impl NewFolder {
    /// Notes which of `dir` and the folders above it do not exist yet.
    pub fn before(dir: &Path) -> Self {
        Self(
            dir.ancestors()
                .filter(|d| !d.as_os_str().is_empty())
                .take_while(|d| std::fs::symlink_metadata(d).is_err())
                .map(Path::to_path_buf)
                .collect(),
        )
    }
}

impl Drop for NewFolder {
    fn drop(&mut self) {
        for d in &self.0 {
            if std::fs::remove_dir(d).is_err() {
                break;
            }
        }
    }
}
