//! Reading the files of the EM chain with file, line, row and column in
//! every error: detected-vector CSV, KNOWN CSV (through aeromag-io's
//! reader), the system JSON and the raw record (streamed in chunks).

use crate::error::{Error, Result};
use crate::flight::Flight;
use aeromag_em::detection::{EmSystem, FieldEpoch};
use aeromag_em::sim::{RawReader, field_epoch_from_values, value_columns};
use aeromag_io::{ReadOptions, read_table};
use std::fs::File;
use std::io::BufReader;
use std::path::Path;

/// A CSV table of the EM chain (no MagNav name preset: the EM files have
/// their own column names), unchecked (no `time` column).
pub fn load_table(path: &Path) -> Result<Flight> {
    let opts = ReadOptions {
        magnav_preset: false,
        ..ReadOptions::default()
    };
    Ok(Flight::unchecked(read_table(path, &opts)?))
}

/// Check that `time` (column `name`) strictly increases.
fn increasing_time(t: &Flight, name: &str, time: &[f64]) -> Result<()> {
    if let Some(k) = time.windows(2).position(|w| w[1] <= w[0]) {
        return Err(t.bad_value(
            k + 1,
            name,
            format!(
                "time {} s does not increase (previous row {} s)",
                time[k + 1],
                time[k]
            ),
        ));
    }
    Ok(())
}

/// The epochs of a detected-vector CSV ([`super::detect`]'s output,
/// `aeromag em detect`): every value a finite number, time increasing.
pub fn read_detected(path: &Path) -> Result<Vec<FieldEpoch>> {
    let t = load_table(path)?;
    let time = t.finite("time_s")?;
    increasing_time(&t, "time_s", time)?;
    let names = value_columns();
    let cols: Vec<&[f64]> = names.iter().map(|n| t.finite(n)).collect::<Result<_>>()?;
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

/// Read and check a system description (JSON of [`EmSystem`]: the
/// instrument constants).
pub fn read_system(path: &Path) -> Result<EmSystem> {
    let file = path.display().to_string();
    let text = std::fs::read_to_string(path).map_err(|e| Error::read(path, e))?;
    let s: EmSystem = serde_json::from_str(&text)
        .map_err(|e| Error::bad_file(&file, format!("not an EM system description: {e}")))?;
    s.validate()
        .map_err(|e| Error::bad_file(&file, e.to_string()))?;
    Ok(s)
}

/// Open a raw record for streaming: header read and checked (3 channels,
/// valid system).
pub fn open_raw(path: &Path) -> Result<RawReader<BufReader<File>>> {
    let file = path.display().to_string();
    let f = File::open(path).map_err(|e| Error::read(path, e))?;
    let r = RawReader::new(BufReader::new(f)).map_err(|e| Error::bad_file(&file, e.to_string()))?;
    let h = r.header();
    if h.channels != 3 {
        return Err(Error::bad_file(
            &file,
            format!(
                "header field 'channels' is {}, the EM receiver has 3",
                h.channels
            ),
        ));
    }
    h.system
        .validate()
        .map_err(|e| Error::bad_file(&file, format!("header field 'system': {e}")))?;
    Ok(r)
}

/// Read the next chunk of at most `frames` frames into `out`; every sample
/// must be finite. Returns the absolute frame index of the chunk's first
/// frame and the number of frames (0 at the end).
pub(super) fn next_chunk(
    r: &mut RawReader<BufReader<File>>,
    path: &Path,
    frames: usize,
    out: &mut Vec<f32>,
) -> Result<(u64, usize)> {
    let file = path.display().to_string();
    let first = r.frames_read();
    let n = r
        .read_frames(frames, out)
        .map_err(|e| Error::bad_file(&file, e.to_string()))?;
    // Runs without an early exit vectorise; the position is looked for
    // only when a run has a bad value.
    let all_finite = out
        .chunks(4096)
        .all(|c| c.iter().fold(true, |ok, v| ok & v.is_finite()));
    if let Some(k) = (!all_finite)
        .then(|| out.iter().position(|v| !v.is_finite()))
        .flatten()
    {
        let frame = first + (k / 3) as u64;
        return Err(Error::bad_file(
            &file,
            format!(
                "frame {frame} channel {} (byte offset {}) is {}",
                k % 3,
                r.body_offset() + 4 * (3 * first + k as u64),
                out[k]
            ),
        ));
    }
    Ok((r.header().start_index + first, n))
}
