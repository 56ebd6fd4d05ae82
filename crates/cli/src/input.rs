//! Reading flight files the same way in every command: read, map columns,
//! check (the library's `Flight`), print the warnings.

use aeromag::{ColumnMap, Flight};
use std::path::{Path, PathBuf};

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
}

/// Read and check a flight file; its warnings go to stderr.
pub fn load(path: &Path, columns: Option<&str>) -> anyhow::Result<Flight> {
    let map = match columns {
        Some(m) => ColumnMap::parse(m)?,
        None => ColumnMap::new(),
    };
    let flight = Flight::read_mapped(path, &map)?;
    for w in flight.warnings() {
        eprintln!("{w}");
    }
    Ok(flight)
}

impl InputArgs {
    /// [`load`] with these arguments.
    pub fn load(&self) -> anyhow::Result<Flight> {
        load(&self.input, self.columns.as_deref())
    }
}
