//! Reading flight files the same way in every command: parse, map columns,
//! validate time and units, print warnings.

use aeromag_io::{ColumnMap, FlightTable, ReadOptions, check_time, check_units, read_table};
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

/// Read, map and validate a flight file; warnings go to stderr.
pub fn load(path: &Path, columns: Option<&str>) -> anyhow::Result<FlightTable> {
    let mut opts = ReadOptions::default();
    if let Some(map) = columns {
        opts.columns = ColumnMap::parse(map)?;
    }
    let table = read_table(path, &opts)?;
    if table.column("time").is_some() {
        check_time(&table)?;
    }
    for w in check_units(&table)? {
        eprintln!("warning: {w}");
    }
    Ok(table)
}

impl InputArgs {
    /// [`load`] with these arguments.
    pub fn load(&self) -> anyhow::Result<FlightTable> {
        load(&self.input, self.columns.as_deref())
    }
}
