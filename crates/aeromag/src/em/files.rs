//! Reading the files of the EM chain with file, line, row and column in
//! every error: detected-vector CSV, KNOWN CSV (through aeromag-io's
//! reader), the system and calibration JSON (a leading UTF-8 BOM is
//! skipped, as in the CSV files) and the raw record (read in place from a
//! memory map when its samples are aligned and complete, else streamed in
//! chunks).

use crate::error::{Error, Result};
use crate::flight::Flight;
use aeromag_core::error::shown;
use aeromag_em::calibration::CalibrationFile;
use aeromag_em::detection::{EmSystem, FieldEpoch};
use aeromag_em::sim::{RawHeader, RawReader, field_epoch_from_values, value_columns};
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

/// The largest detected field component read, T: the 2·10⁴ A·m² dipoles
/// of the simulated transmitter give 4 mT at 1 m (the default record's
/// fields are ~10⁻⁸ T); 1e300 T gave a "singular matrix" failure.
pub const MAX_FIELD_T: f64 = 1.0;

/// The epochs of a detected-vector CSV ([`super::detect`]'s output,
/// `aeromag em detect`): every value a finite number, field components
/// within ±[`MAX_FIELD_T`], time increasing.
pub fn read_detected(path: &Path) -> Result<Vec<FieldEpoch>> {
    let t = load_table(path)?;
    let time = t.finite("time_s")?;
    increasing_time(&t, "time_s", time)?;
    let names = value_columns();
    let cols: Vec<&[f64]> = names.iter().map(|n| t.finite(n)).collect::<Result<_>>()?;
    for (n, c) in names.iter().zip(&cols) {
        if !(n.starts_with('h') && n.ends_with("_t")) {
            continue;
        }
        if let Some(r) = c.iter().position(|v| v.abs() > MAX_FIELD_T) {
            return Err(t.bad_value(
                r,
                n,
                format!(
                    "{} T is not a field the transmitter induces at the bird (|h| ≤ {MAX_FIELD_T} T)",
                    shown(c[r])
                ),
            ));
        }
    }
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
    let text = crate::model_file::read_text_file(path)?;
    let s: EmSystem = serde_json::from_str(&text)
        .map_err(|e| Error::json(&file, "not an EM system description", &e))?;
    s.validate()
        .map_err(|e| Error::bad_file(&file, e.to_string()))?;
    Ok(s)
}

/// Read and check a calibration file (`em calibrate`'s JSON,
/// [`CalibrationFile::from_json`]), naming the file in its errors.
pub fn read_calibration(path: &Path) -> Result<CalibrationFile> {
    let text = crate::model_file::read_text_file(path)?;
    CalibrationFile::from_json(&text)
        .map_err(|e| Error::bad_file(path.display().to_string(), e.to_string()))
}

/// ADC rates a raw record may have, Hz: 1 Hz to 100 MHz (the working
/// frequencies are kHz; no receiver digitises faster).
pub const RAW_SAMPLE_RATE_RANGE_HZ: (f64, f64) = (1.0, 1e8);

/// Largest absolute frame index of a raw record (`start_index + frames`):
/// 2⁵³, beyond which the time `index / rate` is not exact (and `u64`
/// wraps); at 100 kHz it is 2800 years.
pub const MAX_FRAME_INDEX: u64 = 1 << 53;

/// Open a raw record for streaming: header read and checked (3 channels,
/// sample rate within [`RAW_SAMPLE_RATE_RANGE_HZ`], frame indices up to
/// [`MAX_FRAME_INDEX`], valid system).
pub fn open_raw(path: &Path) -> Result<RawReader<BufReader<File>>> {
    let f = File::open(path).map_err(|e| Error::read(path, e))?;
    raw_reader(path, BufReader::new(f))
}

/// [`open_raw`] over any byte source.
fn raw_reader<R: std::io::Read>(path: &Path, source: R) -> Result<RawReader<R>> {
    let file = path.display().to_string();
    let r = RawReader::new(source).map_err(|e| Error::bad_file(&file, e.to_string()))?;
    check_raw_header(r.header()).map_err(|m| Error::bad_file(&file, m))?;
    Ok(r)
}

/// The checks every raw header passes, as a message naming the header
/// field: 3 channels, sample rate within [`RAW_SAMPLE_RATE_RANGE_HZ`],
/// frame indices up to [`MAX_FRAME_INDEX`], a valid system
/// ([`EmSystem::validate`]). [`open_raw`] applies them to the records it
/// reads and `em simulate` to the header it is about to write, so that it
/// never writes a record `em detect` refuses.
pub fn check_raw_header(h: &RawHeader) -> std::result::Result<(), String> {
    if h.channels != 3 {
        return Err(format!(
            "header field 'channels' is {}, the EM receiver has 3",
            h.channels
        ));
    }
    let (lo, hi) = RAW_SAMPLE_RATE_RANGE_HZ;
    if !(lo..=hi).contains(&h.sample_rate_hz) {
        return Err(format!(
            "header field 'sample_rate_hz' is {}, expected {}…{} Hz",
            shown(h.sample_rate_hz),
            shown(lo),
            shown(hi)
        ));
    }
    if h.start_index
        .checked_add(h.frames)
        .is_none_or(|end| end > MAX_FRAME_INDEX)
    {
        return Err(format!(
            "header fields 'start_index' {} + 'frames' {} exceed 2^53 = {MAX_FRAME_INDEX} \
             (frame indices beyond it have no exact time)",
            h.start_index, h.frames
        ));
    }
    h.system
        .validate()
        .map_err(|e| format!("header field 'system': {e}"))
}

/// Read the next chunk of at most `frames` frames into `out`; every sample
/// must be finite. Returns the absolute frame index of the chunk's first
/// frame and the number of frames (0 at the end).
fn next_chunk(
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
    check_finite(path, r.body_offset(), first, out)?;
    Ok((r.header().start_index + first, n))
}

/// Every sample of `samples` (interleaved frames from frame `first`, the
/// body starting at byte `body_offset`) finite, or an error naming the
/// first bad frame, channel and byte offset.
fn check_finite(path: &Path, body_offset: u64, first: u64, samples: &[f32]) -> Result<()> {
    // Runs without an early exit vectorise; the position is looked for
    // only when a run has a bad value. A whole mapped record (12 MB for
    // the default 10 s) is checked in parts on the cores.
    let finite = |part: &[f32]| {
        part.chunks(4096)
            .all(|c| c.iter().fold(true, |ok, v| ok & v.is_finite()))
    };
    let threads = aeromag_core::parallel::threads();
    let all_finite = if threads > 1 && samples.len() >= 1 << 20 {
        let parts: Vec<&[f32]> = samples.chunks(samples.len().div_ceil(threads)).collect();
        aeromag_core::parallel::parallel_map(parts.len(), threads, |t| finite(parts[t]))
            .into_iter()
            .all(|ok| ok)
    } else {
        finite(samples)
    };
    if let Some(k) = (!all_finite)
        .then(|| samples.iter().position(|v| !v.is_finite()))
        .flatten()
    {
        let frame = first + (k / 3) as u64;
        return Err(Error::bad_file(
            path.display().to_string(),
            format!(
                "frame {frame} channel {} (byte offset {}) is {}",
                k % 3,
                body_offset + 4 * (3 * first + k as u64),
                samples[k]
            ),
        ));
    }
    Ok(())
}

/// A raw record mapped into memory whose samples can be read in place:
/// a body of exactly the header's frames (so a truncated record or trailing
/// bytes go the streaming way, [`open_raw`], with its messages), starting
/// at a multiple of 4 bytes, on a little-endian machine. No copy of the
/// samples and no sample buffer (`em detect` on a 12 MB record had spent a
/// sixth of its processor time copying the file through `read`, and the
/// buffer's pages cost more).
pub(super) struct MappedRaw {
    map: memmap2::Mmap,
    header: aeromag_em::sim::RawHeader,
    body_offset: usize,
    /// The samples have been checked finite ([`RawSource::check_in_advance`]).
    checked: bool,
}

impl MappedRaw {
    /// The record at `path` mapped, `None` when it cannot be read in place
    /// (then stream it). Header errors are those of [`open_raw`].
    fn open(path: &Path) -> Result<Option<Self>> {
        if cfg!(target_endian = "big") {
            return Ok(None);
        }
        let f = File::open(path).map_err(|e| Error::read(path, e))?;
        // SAFETY: the map is read-only and private to this process; its
        // contents are only read as bytes or, once checked to lie inside
        // the file and be aligned, as f32 (every bit pattern is an f32).
        // Another process shrinking the file while it is mapped would make
        // reads beyond the new end fault, as for any memory-mapped reader.
        let Ok(map) = (unsafe { memmap2::MmapOptions::new().map(&f) }) else {
            return Ok(None);
        };
        let r = raw_reader(path, &map[..])?;
        let (header, body_offset) = (r.header().clone(), r.body_offset() as usize);
        let body = map.len() - body_offset.min(map.len());
        let exact = usize::try_from(header.frames)
            .ok()
            .and_then(|f| f.checked_mul(4 * header.channels))
            == Some(body);
        let aligned = bytemuck::try_cast_slice::<u8, f32>(&map[body_offset..]).is_ok();
        Ok((exact && aligned).then_some(Self {
            map,
            header,
            body_offset,
            checked: false,
        }))
    }

    /// The whole body, checked finite (unless it has been already): the
    /// absolute index of its first frame and its samples (no buffer to
    /// bound, so one piece).
    fn samples(&self, path: &Path) -> Result<(u64, &[f32])> {
        let samples: &[f32] = bytemuck::cast_slice(&self.map[self.body_offset..]);
        if !self.checked {
            check_finite(path, self.body_offset as u64, 0, samples)?;
        }
        Ok((self.header.start_index, samples))
    }
}

/// A raw record to detect: mapped and read in place ([`MappedRaw`]) when
/// it can be, else streamed in chunks ([`open_raw`]).
pub(super) enum RawSource {
    /// Read in place.
    Mapped(MappedRaw),
    /// Read in chunks.
    Streamed(RawReader<BufReader<File>>),
}

impl RawSource {
    /// Open the record at `path` (header checked as by [`open_raw`]).
    pub(super) fn open(path: &Path) -> Result<Self> {
        Ok(match MappedRaw::open(path)? {
            Some(m) => Self::Mapped(m),
            None => Self::Streamed(open_raw(path)?),
        })
    }

    /// The header.
    pub(super) fn header(&self) -> &aeromag_em::sim::RawHeader {
        match self {
            Self::Mapped(m) => &m.header,
            Self::Streamed(r) => r.header(),
        }
    }

    /// Check a mapped record's samples finite now rather than in
    /// [`Self::for_each_chunk`], so that the check (a pass over the whole
    /// record, which also brings its pages in) can run alongside other
    /// work: `em detect` builds its detector meanwhile. A streamed record
    /// is checked chunk by chunk as it is read.
    pub(super) fn check_in_advance(&mut self, path: &Path) -> Result<()> {
        if let Self::Mapped(m) = self {
            m.samples(path)?;
            m.checked = true;
        }
        Ok(())
    }

    /// `f(first, samples)` for the record's samples in order, every one
    /// checked finite first (an error names frame, channel and byte
    /// offset): in chunks of at most `frames` frames when streamed, in one
    /// piece when mapped. `first` is the absolute index of the first frame.
    pub(super) fn for_each_chunk(
        self,
        path: &Path,
        frames: usize,
        mut f: impl FnMut(u64, &[f32]) -> Result<()>,
    ) -> Result<()> {
        match self {
            Self::Mapped(m) => {
                let (first, samples) = m.samples(path)?;
                f(first, samples)
            }
            Self::Streamed(mut r) => {
                let mut samples = Vec::new();
                loop {
                    let (first, got) = next_chunk(&mut r, path, frames, &mut samples)?;
                    if got == 0 {
                        return Ok(());
                    }
                    f(first, &samples)?;
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A record long enough to be checked in parts on the cores names its
    /// first non-finite sample, whichever part holds it, and a finite one
    /// passes.
    #[test]
    fn the_first_non_finite_sample_is_named_in_a_long_record() {
        let path = Path::new("rec.raw");
        let n = 3 << 20;
        let mut samples = vec![0.25f32; n];
        assert!(check_finite(path, 100, 0, &samples).is_ok());
        samples[n - 2] = f32::INFINITY;
        let msg = check_finite(path, 100, 7, &samples)
            .unwrap_err()
            .to_string();
        let k = n - 2;
        assert!(
            msg.contains(&format!(
                "frame {} channel {} (byte offset {}) is inf",
                7 + k / 3,
                k % 3,
                100 + 4 * (3 * 7 + k)
            )),
            "{msg}"
        );
        samples[5] = f32::NAN;
        let msg = check_finite(path, 100, 0, &samples)
            .unwrap_err()
            .to_string();
        assert!(
            msg.contains("frame 1 channel 2 (byte offset 120) is NaN"),
            "{msg}"
        );
    }
}
