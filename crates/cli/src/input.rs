//! Reading flight files the same way in every command: read, map columns,
//! choose sensors and segments, check (the library's `Flight`), print the
//! warnings.

use aeromag::{ColumnMap, Flight, ReadOptions, RowSelection, Sensors};
use std::path::PathBuf;

/// Input-file arguments shared by the commands that read flight data.
#[derive(Debug, Clone, clap::Args)]
pub struct InputArgs {
    /// Flight data file: CSV (header row, `#` comments) or Geosoft XYZ (`.xyz`).
    #[arg(long, short = 'i', value_name = "FILE")]
    pub input: PathBuf,
    /// Map canonical column names onto the file's names, e.g.
    /// `mag=mag_1_uc,flux_x=flux_a_x,time=tt` (MagNav names are recognised
    /// automatically).
    #[arg(long, value_name = "MAP")]
    pub columns: Option<String>,
    /// The scalar magnetometer to use, e.g. `mag_3_uc` (SGL names also find
    /// the XYZ export's `UNCOMPMAG3`), or any column. Default: the first of
    /// mag_1_uc … mag_5_uc present.
    #[arg(long, value_name = "NAME")]
    pub mag: Option<String>,
    /// The vector magnetometer to use, by prefix: `flux_b` reads
    /// flux_b_x/y/z (or FLUXB_X/Y/Z). Default: the first complete of A–D.
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

/// Read and check a file of another kind than a flight (a gradiometer
/// pass) with the default options; its warnings go to stderr.
pub fn load(path: &std::path::Path) -> anyhow::Result<Flight> {
    let flight = Flight::read(path)?;
    for w in flight.warnings() {
        eprintln!("{w}");
    }
    Ok(flight)
}

impl InputArgs {
    /// The library's reading options for these arguments.
    pub fn read_options(&self) -> anyhow::Result<ReadOptions> {
        Ok(ReadOptions {
            columns: match &self.columns {
                Some(m) => ColumnMap::parse(m)?,
                None => ColumnMap::new(),
            },
            sensors: Sensors {
                mag: self.mag.clone(),
                vector: self.vector.clone(),
            },
            rows: RowSelection::parse(self.lines.as_deref(), self.time_range.as_deref())?,
            ..ReadOptions::default()
        })
    }

    /// Read and check the flight file; its warnings go to stderr.
    pub fn load(&self) -> anyhow::Result<Flight> {
        let flight = Flight::read_with(&self.input, &self.read_options()?)?;
        for w in flight.warnings() {
            eprintln!("{w}");
        }
        Ok(flight)
    }
}
