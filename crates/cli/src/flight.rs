//! Glue between flight tables (aeromag-io) and the compensation library:
//! required columns, segmentation, and writing results back as columns.

use crate::exit::bad_input;
use aeromag_compensation::reference_field::{LeverArm, lever_arm_correction_nt};
use aeromag_compensation::tolles_lawson::segments::split_segments;
use aeromag_io::FlightTable;
use std::ops::Range;

/// The columns a Tolles-Lawson fit or compensation needs.
pub struct TlColumns<'a> {
    pub time: &'a [f64],
    pub flux: [&'a [f64]; 3],
    pub mag: &'a [f64],
    pub line: Option<&'a [f64]>,
}

/// Which known external-field channels are subtracted from `mag` before a
/// fit and before scoring (FOM, IR): `auto` takes `diurnal` (base station)
/// and `igrf` (main field at the recorded position) when the file has them —
/// the usual reduction to the anomaly field, which keeps external variations
/// out of the band-pass fit; `none` uses `mag` as it is (MagNav.jl's way);
/// or a comma-separated list of column names.
pub fn reference_columns(table: &FlightTable, spec: &str) -> anyhow::Result<Vec<String>> {
    match spec.trim() {
        "auto" => Ok(["diurnal", "igrf"]
            .iter()
            .filter(|c| table.column(c).is_some())
            .map(|c| c.to_string())
            .collect()),
        "none" | "" => Ok(Vec::new()),
        list => {
            let cols: Vec<String> = list
                .split(',')
                .map(|c| c.trim().to_string())
                .filter(|c| !c.is_empty())
                .collect();
            for c in &cols {
                table.require(c)?;
            }
            Ok(cols)
        }
    }
}

/// The sum of the named reference channels (zeros if none). With a lever
/// arm, the `igrf` channel is moved from the navigation point to the sensor
/// (needs `lat`, `lon`, `alt`, `roll`, `pitch`, `yaw`).
pub fn reference_sum(
    table: &FlightTable,
    cols: &[String],
    lever: Option<&LeverArm>,
) -> anyhow::Result<Vec<f64>> {
    let mut r = vec![0.0; table.n_rows()];
    for c in cols {
        for (a, b) in r.iter_mut().zip(table.require(c)?) {
            *a += b;
        }
    }
    if let (Some(lever), true) = (lever, cols.iter().any(|c| c == "igrf")) {
        let [lat, lon, alt, roll, pitch, yaw] = nav_and_attitude(table)?;
        let corr = lever_arm_correction_nt(lever, lat, lon, alt, roll, pitch, yaw)
            .map_err(|e| bad_input!("{}: {e}", table.file_label()))?;
        for (a, c) in r.iter_mut().zip(corr) {
            *a += c;
        }
    }
    Ok(r)
}

/// `n` comma-separated finite numbers given to option `flag`.
pub fn parse_numbers(flag: &str, s: &str, n: usize) -> anyhow::Result<Vec<f64>> {
    let bad = || bad_input!("{flag} `{s}`: expected {n} comma-separated finite numbers");
    let v: Vec<f64> = s
        .split(',')
        .map(|p| p.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .map_err(|_| bad())?;
    if v.len() != n || v.iter().any(|x| !x.is_finite()) {
        return Err(bad());
    }
    Ok(v)
}

/// The sensor's track `[lat (deg), lon (deg), alt (m)]` from the
/// navigation point's (`lat`, `lon`, `alt`) moved by the lever arm
/// `arm_m` (body frame, m) with the attitude (`roll`, `pitch`, `yaw`).
pub fn sensor_track(table: &FlightTable, arm_m: [f64; 3]) -> anyhow::Result<[Vec<f64>; 3]> {
    sensor_track_at(table, table.require("alt")?, arm_m)
}

/// [`sensor_track`] with the navigation altitude `alt` (m) given instead of
/// the table's `alt` column (e.g. a cleaned copy of it).
pub fn sensor_track_at(
    table: &FlightTable,
    alt: &[f64],
    arm_m: [f64; 3],
) -> anyhow::Result<[Vec<f64>; 3]> {
    let [lat, lon, _, roll, pitch, yaw] = nav_and_attitude(table)?;
    aeromag_compensation::levelling::sensor_positions(lat, lon, alt, roll, pitch, yaw, arm_m)
        .map_err(|e| bad_input!("{}: {e}", table.file_label()))
}

/// The navigation point's `lat`, `lon` (deg), `alt` (m) and the attitude
/// `roll`, `pitch`, `yaw` (deg) of `table`: what moving a lever arm needs.
fn nav_and_attitude(table: &FlightTable) -> anyhow::Result<[&[f64]; 6]> {
    Ok([
        table.require("lat")?,
        table.require("lon")?,
        table.require("alt")?,
        table.require("roll")?,
        table.require("pitch")?,
        table.require("yaw")?,
    ])
}

/// A parsed `X,Y,Z` lever arm in metres (body frame: x forward, y right,
/// z down).
pub fn parse_lever_arm(s: &str) -> anyhow::Result<[f64; 3]> {
    let v = parse_numbers("--lever-arm", s, 3)?;
    Ok([v[0], v[1], v[2]])
}

impl<'a> TlColumns<'a> {
    /// Take `time`, `flux_x/y/z`, `mag` (and `line` if numeric) from a table;
    /// a missing column is a bad-input error naming the file.
    pub fn from_table(t: &'a FlightTable) -> anyhow::Result<Self> {
        Ok(Self {
            time: t.require("time")?,
            flux: [
                t.require("flux_x")?,
                t.require("flux_y")?,
                t.require("flux_z")?,
            ],
            mag: t.require("mag")?,
            line: t.column("line"),
        })
    }

    /// Rows where every needed value is finite.
    pub fn usable(&self) -> Vec<bool> {
        (0..self.time.len())
            .map(|i| {
                self.time[i].is_finite()
                    && self.mag[i].is_finite()
                    && self.flux.iter().all(|f| f[i].is_finite())
                    && (self.flux[0][i] != 0.0 || self.flux[1][i] != 0.0 || self.flux[2][i] != 0.0)
            })
            .collect()
    }

    /// Contiguous segments (split at line changes if `by_line`, gaps and
    /// unusable rows) of at least `min_len` rows, and the rows left out.
    pub fn segments(
        &self,
        by_line: bool,
        min_len: usize,
    ) -> (Vec<Range<usize>>, Vec<Range<usize>>) {
        split_segments(
            self.time,
            if by_line { self.line } else { None },
            &self.usable(),
            1.5,
            min_len,
        )
    }
}

/// A parsed `LO,HI` pass band in Hz.
pub fn parse_band(s: &str) -> anyhow::Result<(f64, f64)> {
    let v = parse_numbers("--band", s, 2)?;
    let (lo, hi) = (v[0], v[1]);
    if !(lo > 0.0 && hi > lo) {
        return Err(bad_input!("--band {lo},{hi}: need 0 < LO < HI"));
    }
    Ok((lo, hi))
}

/// Add the modelled interference `interf` (nT; NaN = not compensated) as
/// column `interf_col`, `mag_comp = mag − interf`, and `flag_col` (0
/// compensated, 1 not) to `table`; returns the number of rows not
/// compensated. Bad input if one of the columns exists already. Used by
/// `compensate`, `rotor apply` and `pod apply`.
pub fn add_compensation(
    table: &mut FlightTable,
    interf_col: &str,
    flag_col: &str,
    interf: Vec<f64>,
) -> anyhow::Result<usize> {
    for name in [interf_col, "mag_comp", flag_col] {
        if table.get(name).is_some() {
            return Err(bad_input!(
                "{}: already has a column `{name}`; rename it first",
                table.file_label()
            ));
        }
    }
    let mag = table.require("mag")?;
    let comp: Vec<f64> = mag.iter().zip(&interf).map(|(m, i)| m - i).collect();
    let flag: Vec<f64> = interf
        .iter()
        .map(|v| if v.is_finite() { 0.0 } else { 1.0 })
        .collect();
    let missing = flag.iter().filter(|f| **f > 0.0).count();
    table.add_column(interf_col, interf)?;
    table.add_column("mag_comp", comp)?;
    table.add_column(flag_col, flag)?;
    Ok(missing)
}

/// Write a compensated `table` to `out` and tell the user: a warning for
/// the `missing` rows (`why` they could not be compensated; kept with
/// `flag_col` = 1) and a summary naming the `model` file, with `detail` in
/// parentheses when not empty. Used by `compensate`, `rotor apply` and
/// `pod apply`.
pub fn write_compensated(
    table: &FlightTable,
    out: &std::path::Path,
    model: &std::path::Path,
    detail: &str,
    missing: usize,
    flag_col: &str,
    why: &str,
) -> anyhow::Result<()> {
    aeromag_io::write_csv(table, out)?;
    let n = table.n_rows();
    if missing > 0 {
        eprintln!(
            "warning: {missing} of {n} rows could not be compensated ({why}); they are kept with {flag_col} = 1"
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
        out.display()
    );
    Ok(())
}

/// Read a model file and parse it with `parse` (a `from_json(text, origin)`
/// of the library's model types); any failure is bad input naming the file.
pub fn load_model_file<T>(
    path: &std::path::Path,
    parse: impl FnOnce(&str, &str) -> Result<T, aeromag_compensation::CompError>,
) -> anyhow::Result<T> {
    let origin = path.display().to_string();
    let text = std::fs::read_to_string(path)
        .map_err(|e| bad_input!("cannot read model file '{origin}': {e}"))?;
    parse(&text, &origin).map_err(|e| bad_input!("{e}"))
}
