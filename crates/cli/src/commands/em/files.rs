//! Reading the files of the `aeromag em` commands with file, line, row and
//! column in every error (exit code 2): detected-vector CSV, KNOWN CSV
//! (through aeromag-io's reader), the system JSON and the raw record
//! (streamed in chunks).

use crate::exit::bad_input;
use aeromag_em::detection::{EmSystem, FieldEpoch};
use aeromag_em::sim::{RawReader, field_epoch_from_values, value_columns};
use aeromag_io::{FlightTable, ReadOptions, read_table};
use std::fs::File;
use std::io::BufReader;
use std::path::Path;

/// Read a CSV table with aeromag-io (no MagNav name preset: the EM files
/// have their own column names).
pub fn load_table(path: &Path) -> anyhow::Result<FlightTable> {
    let opts = ReadOptions {
        magnav_preset: false,
        ..ReadOptions::default()
    };
    Ok(read_table(path, &opts)?)
}

/// "'FILE' line L (data row R), column 'C'" for error messages.
pub fn at(t: &FlightTable, row: usize, column: &str) -> String {
    match t.line_of_row(row) {
        Some(l) => format!(
            "'{}' line {l} (data row {}), column '{column}'",
            t.file_label(),
            row + 1
        ),
        None => format!(
            "'{}' data row {}, column '{column}'",
            t.file_label(),
            row + 1
        ),
    }
}

/// A numeric column whose every value must be finite.
pub fn finite_column<'a>(t: &'a FlightTable, name: &str) -> anyhow::Result<&'a [f64]> {
    // aeromag-io keeps a column with any non-number as text: name the cell.
    if let Some(text) = t.get(name).and_then(|c| c.text())
        && let Some(row) = text.iter().position(|v| v.trim().parse::<f64>().is_err())
    {
        return Err(bad_input!(
            "{}: '{}' is not a number",
            at(t, row, name),
            text[row]
        ));
    }
    let v = t.require(name)?;
    if let Some(row) = v.iter().position(|x| !x.is_finite()) {
        return Err(bad_input!(
            "{}: value is missing, NaN or infinite",
            at(t, row, name)
        ));
    }
    Ok(v)
}

/// Check that `time_s` strictly increases.
pub fn increasing_time(t: &FlightTable, time: &[f64]) -> anyhow::Result<()> {
    if let Some(k) = time.windows(2).position(|w| w[1] <= w[0]) {
        return Err(bad_input!(
            "{}: time {} s does not increase (previous row {} s)",
            at(t, k + 1, "time_s"),
            time[k + 1],
            time[k]
        ));
    }
    Ok(())
}

/// The epochs of a detected-vector CSV (`aeromag em detect`'s output).
pub fn read_detected(path: &Path) -> anyhow::Result<Vec<FieldEpoch>> {
    let t = load_table(path)?;
    let time = finite_column(&t, "time_s")?;
    increasing_time(&t, time)?;
    let names = value_columns();
    let cols: Vec<&[f64]> = names
        .iter()
        .map(|n| finite_column(&t, n))
        .collect::<anyhow::Result<_>>()?;
    let mut row = vec![0.0; cols.len()];
    (0..t.n_rows())
        .map(|r| {
            for (v, c) in row.iter_mut().zip(&cols) {
                *v = c[r];
            }
            Ok(field_epoch_from_values(time[r], &row)?)
        })
        .collect()
}

/// Read and check a system description (JSON of [`EmSystem`]).
pub fn read_system(path: &Path) -> anyhow::Result<EmSystem> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| bad_input!("cannot read '{}': {e}", path.display()))?;
    let s: EmSystem = serde_json::from_str(&text)
        .map_err(|e| bad_input!("'{}': not an EM system description: {e}", path.display()))?;
    s.validate()
        .map_err(|e| bad_input!("'{}': {e}", path.display()))?;
    Ok(s)
}

/// Open a raw record for streaming: header read and checked (3 channels,
/// valid system).
pub fn open_raw(path: &Path) -> anyhow::Result<RawReader<BufReader<File>>> {
    let f = File::open(path).map_err(|e| bad_input!("cannot read '{}': {e}", path.display()))?;
    let r =
        RawReader::new(BufReader::new(f)).map_err(|e| bad_input!("'{}': {e}", path.display()))?;
    let h = r.header();
    if h.channels != 3 {
        return Err(bad_input!(
            "'{}': header field 'channels' is {}, the EM receiver has 3",
            path.display(),
            h.channels
        ));
    }
    h.system
        .validate()
        .map_err(|e| bad_input!("'{}': header field 'system': {e}", path.display()))?;
    Ok(r)
}

/// Read the next chunk of at most `frames` frames into `out`; every sample
/// must be finite. Returns the absolute frame index of the chunk's first
/// frame and the number of frames (0 at the end).
pub fn next_chunk(
    r: &mut RawReader<BufReader<File>>,
    path: &Path,
    frames: usize,
    out: &mut Vec<f32>,
) -> anyhow::Result<(u64, usize)> {
    let first = r.frames_read();
    let n = r
        .read_frames(frames, out)
        .map_err(|e| bad_input!("'{}': {e}", path.display()))?;
    if let Some(k) = out.iter().position(|v| !v.is_finite()) {
        let frame = first + (k / 3) as u64;
        return Err(bad_input!(
            "'{}': frame {frame} channel {} (byte offset {}) is {}",
            path.display(),
            k % 3,
            r.body_offset() + 4 * (3 * first + k as u64),
            out[k]
        ));
    }
    Ok((r.header().start_index + first, n))
}
