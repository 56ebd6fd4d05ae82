//! Reading flight files the same way in every command: read, map columns,
//! choose sensors and segments, check (the library's `Flight`), print the
//! warnings.

use aeromag::{ColumnMap, Fields, Flight, ReadOptions, RowSelection, Sensors};
use std::path::{Path, PathBuf};

/// Input-file arguments shared by the commands that read flight data.
#[derive(Debug, Clone, clap::Args)]
#[group(skip)]
#[command(mut_arg("input", |a| a.help(
    "Flight data file: CSV (header row, `#` comments), Geosoft XYZ (`.xyz`), HDF5 in the \
     MagNav/SGL layout (`.h5`: one dataset per field) or a MATLAB MAT-file (`.mat`: vectors, \
     or a struct of them)"
)))]
#[command(mut_arg("file", |a| a.help(
    "The flight data file, as --input gives it (`aeromag inspect flight.xyz`)"
)))]
pub struct InputArgs {
    #[command(flatten)]
    file: InputFile,
    /// Map canonical column names onto the file's names, e.g.
    /// `mag=mag_1_uc,flux_x=flux_a_x,time=tt` (MagNav names are recognised
    /// automatically).
    #[arg(long, value_name = "MAP")]
    pub columns: Option<String>,
    /// The scalar magnetometer to use, e.g. `mag_3_uc` (SGL names also find
    /// the XYZ export's `UNCOMPMAG3` and back, as do the columns of a
    /// model, --extra and --reference-sensor), or any column. Default: the first of
    /// mag_1_uc … mag_5_uc present. `calibrate` takes several,
    /// comma-separated (one model per sensor).
    #[arg(long, value_name = "NAME")]
    pub mag: Option<String>,
    /// The vector magnetometer to use, by prefix: `flux_b` reads
    /// flux_b_x/y/z (or FLUXB_X/Y/Z). Default: the first complete of A–D.
    /// With several --mag sensors: one prefix for all, or one per sensor.
    #[arg(long, value_name = "PREFIX")]
    pub vector: Option<String>,
    /// Keep only the rows on these line labels, e.g. `1002.02` or
    /// `L1020,T901` (a whole flight's calibration box or survey lines).
    #[arg(long, value_name = "LABEL,LABEL")]
    pub lines: Option<String>,
    /// Keep only the rows with T0 ≤ time ≤ T1 (s).
    #[arg(long, value_name = "T0,T1", allow_hyphen_values = true)]
    pub time_range: Option<String>,
}

/// One input file of another kind than a flight (a grid, an EM record, a
/// gradiometer pass), given with --input or as the positional FILE, exactly
/// one of them. A command names its file with `mut_arg`, e.g.
/// `#[command(mut_arg("input", |a| a.value_name("GRID").help("Input grid file")))]`
/// and `#[command(mut_arg("file", |a| a.value_name("GRID")))]`.
#[derive(Debug, Clone, clap::Args)]
#[group(skip)]
#[command(group = clap::ArgGroup::new("input_file").required(true).multiple(false))]
pub struct InputFile {
    /// The input file.
    #[arg(long, short = 'i', value_name = "FILE", group = "input_file")]
    input: Option<PathBuf>,
    /// The same file as --input, given without the flag.
    #[arg(value_name = "FILE", group = "input_file")]
    file: Option<PathBuf>,
}

impl InputFile {
    /// The file, given with --input or as the positional FILE (clap asks
    /// for one of them).
    pub fn path(&self) -> &Path {
        self.input
            .as_deref()
            .or(self.file.as_deref())
            .unwrap_or(Path::new(""))
    }
}

/// Read and check a file of another kind than a flight (a gradiometer
/// pass), the fields `names` alone (the others are delimited but not
/// parsed: a truth column's text cell no longer stops a command that does
/// not read it), with the canonical names mapped by `columns` (a
/// `--columns` text, as for flights) and otherwise the default options; its
/// warnings go to stderr.
pub fn load_only(
    path: &std::path::Path,
    names: Vec<String>,
    columns: Option<&str>,
) -> anyhow::Result<Flight> {
    let columns = match columns {
        Some(m) => ColumnMap::parse_within(m, &names)?,
        None => ColumnMap::new(),
    };
    read_checked(
        path,
        &ReadOptions {
            fields: Fields::Only(names),
            columns,
            ..ReadOptions::default()
        },
    )
}

/// The column map of a `--columns` text (none: the empty map).
fn column_map(columns: Option<&str>) -> anyhow::Result<ColumnMap> {
    Ok(match columns {
        Some(m) => ColumnMap::parse(m)?,
        None => ColumnMap::new(),
    })
}

/// Read and check `path` with `opts`; its warnings go to stderr.
fn read_checked(path: &std::path::Path, opts: &ReadOptions) -> anyhow::Result<Flight> {
    let flight = Flight::read_with(path, opts)?;
    for w in flight.warnings() {
        eprintln!("{w}");
    }
    Ok(flight)
}

impl InputArgs {
    /// The flight file, given with --input or as the positional FILE.
    pub fn path(&self) -> &Path {
        self.file.path()
    }

    /// The library's reading options for these arguments.
    pub fn read_options(&self) -> anyhow::Result<ReadOptions> {
        Ok(ReadOptions {
            columns: column_map(self.columns.as_deref())?,
            // Several sensors are chosen per model, not at reading.
            sensors: if self.several_sensors() {
                Sensors::default()
            } else {
                Sensors {
                    mag: self.mag.clone(),
                    vector: self.vector.clone(),
                }
            },
            rows: RowSelection::parse(self.lines.as_deref(), self.time_range.as_deref())?,
            ..ReadOptions::default()
        })
    }

    /// Whether --mag or --vector names several sensors.
    pub fn several_sensors(&self) -> bool {
        [&self.mag, &self.vector]
            .iter()
            .any(|s| s.as_deref().is_some_and(|s| s.contains(',')))
    }

    /// The sensors of --mag and --vector in `flight` (one per --mag name;
    /// --vector gives one prefix for all or one per sensor).
    pub fn sensor_columns(&self, flight: &Flight) -> anyhow::Result<Vec<aeromag::SensorColumns>> {
        let split = |s: &Option<String>| -> Vec<String> {
            s.as_deref()
                .map(|s| {
                    s.split(',')
                        .map(|t| t.trim().to_string())
                        .filter(|t| !t.is_empty())
                        .collect()
                })
                .unwrap_or_default()
        };
        Ok(aeromag::SensorColumns::list(
            flight,
            &split(&self.mag),
            &split(&self.vector),
        )?)
    }

    /// Read and check the flight file (every field); its warnings go to stderr.
    pub fn load(&self) -> anyhow::Result<Flight> {
        self.load_fields(Fields::All)
    }

    /// Read and check only the canonical columns and `extra` (an HDF5
    /// flight of 100 fields then reads about 20 datasets; a CSV or XYZ file
    /// parses about 20 fields of each row), for the commands that do not
    /// write the input's columns back.
    pub fn load_canonical(&self, extra: &[&str]) -> anyhow::Result<Flight> {
        self.load_fields(Fields::canonical_and(extra))
    }

    fn load_fields(&self, fields: Fields) -> anyhow::Result<Flight> {
        let opts = ReadOptions {
            fields,
            ..self.read_options()?
        };
        read_checked(self.path(), &opts)
    }
}
