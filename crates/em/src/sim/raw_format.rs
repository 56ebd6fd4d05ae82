//! Binary raw format of the ADC record (issue 6 item 1: "little-endian f32
//! interleaved plus a small JSON header").
//!
//! ```text
//! bytes 0..8     magic  "AEMRAW1\n"
//! bytes 8..12    u32 LE length L of the JSON header
//! bytes 12..12+L JSON RawHeader (UTF-8)
//! then           frames × channels f32 LE, interleaved: sample n, channel c at index n·channels + c
//! ```
//!
//! [`write_raw`] pads the JSON with spaces so that the samples start at a
//! multiple of 4 bytes (readers accept any `L`; an aligned body can be read
//! in place from a memory map).

use crate::detection::EmSystem;
use crate::{EmError, Result};
use std::io::{Read, Write};

/// The 8-byte magic at the start of a raw file.
pub const MAGIC: &[u8; 8] = b"AEMRAW1\n";

/// Most channels a raw file may declare (the receiver has 3): a header
/// claiming more is an error, so that a hostile header cannot make a
/// reader allocate frames × channels buffers out of proportion to the file.
pub const MAX_CHANNELS: usize = 1024;

/// JSON header of a raw record.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct RawHeader {
    /// Always `"f32le-interleaved"`.
    pub layout: String,
    /// ADC rate, Hz.
    pub sample_rate_hz: f64,
    /// Number of channels.
    pub channels: usize,
    /// Number of frames (samples per channel).
    pub frames: u64,
    /// Absolute index of the first frame (flight time × rate).
    pub start_index: u64,
    /// The instrument constants (frequency plan, coil gain, pilot field,
    /// bench cross-coupling, nominal moments): what the detector needs. No
    /// truth of the flight is stored in a raw file.
    pub system: EmSystem,
}

impl RawHeader {
    /// Header for `frames` frames of `channels` channels.
    pub fn new(
        sample_rate_hz: f64,
        channels: usize,
        frames: u64,
        start_index: u64,
        system: EmSystem,
    ) -> Self {
        Self {
            layout: "f32le-interleaved".into(),
            sample_rate_hz,
            channels,
            frames,
            start_index,
            system,
        }
    }
}

/// Write header and samples.
///
/// Errors: sample count not `frames × channels`, or an I/O failure.
pub fn write_raw<W: Write>(mut w: W, header: &RawHeader, samples: &[f32]) -> Result<()> {
    let expected = header.frames as usize * header.channels;
    if samples.len() != expected {
        return Err(EmError::InvalidArgument {
            reason: format!("{} samples, header says {expected}", samples.len()),
        });
    }
    let mut json = serde_json::to_vec(header).map_err(|e| EmError::InvalidData {
        reason: e.to_string(),
    })?;
    // Spaces after the JSON (valid JSON whitespace) so that the samples
    // start at a multiple of 4 bytes and can be read in place.
    json.resize(json.len() + (4 - (12 + json.len()) % 4) % 4, b' ');
    let len = u32::try_from(json.len()).map_err(|_| EmError::InvalidData {
        reason: "header too long".into(),
    })?;
    let io = |e: std::io::Error| EmError::InvalidData {
        reason: e.to_string(),
    };
    w.write_all(MAGIC).map_err(io)?;
    w.write_all(&len.to_le_bytes()).map_err(io)?;
    w.write_all(&json).map_err(io)?;
    let mut buf = Vec::with_capacity(samples.len() * 4);
    for v in samples {
        buf.extend_from_slice(&v.to_le_bytes());
    }
    w.write_all(&buf).map_err(io)
}

/// Streaming reader of a raw record: the header first, then the body in
/// chunks of frames, so that a long record is detected in constant memory.
#[derive(Debug)]
pub struct RawReader<R: Read> {
    inner: R,
    header: RawHeader,
    body_offset: u64,
    frames_read: u64,
}

fn bad(m: String) -> EmError {
    EmError::InvalidData { reason: m }
}

/// Read exactly `buf.len()` bytes or report how many were there.
fn read_full<R: Read>(r: &mut R, buf: &mut [u8]) -> Result<usize> {
    let mut got = 0;
    while got < buf.len() {
        match r.read(&mut buf[got..]) {
            Ok(0) => break,
            Ok(n) => got += n,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
            Err(e) => return Err(bad(format!("read error: {e}"))),
        }
    }
    Ok(got)
}

impl<R: Read> RawReader<R> {
    /// Read and check magic and header.
    ///
    /// Errors ([`EmError::InvalidData`]): wrong magic, truncated or malformed
    /// JSON header, a layout other than `f32le-interleaved`, zero channels or
    /// a non-positive rate.
    pub fn new(mut inner: R) -> Result<Self> {
        let mut pre = [0u8; 12];
        let n = read_full(&mut inner, &mut pre)?;
        if n < 12 || &pre[..8] != MAGIC {
            return Err(bad(
                "not an aeromag EM raw file (the first 8 bytes are not \"AEMRAW1\\n\")".into(),
            ));
        }
        let len = u32::from_le_bytes([pre[8], pre[9], pre[10], pre[11]]) as usize;
        // Read what is there (not a buffer of the announced length: bytes
        // 8..12 may claim 4 GiB in a file of a few bytes).
        let mut json = Vec::new();
        let got = (&mut inner)
            .take(len as u64)
            .read_to_end(&mut json)
            .map_err(|e| bad(format!("read error: {e}")))?;
        if got < len {
            return Err(bad(format!(
                "truncated header: bytes 8..12 announce {len} header bytes, the file has {got} after them"
            )));
        }
        let body_offset = 12 + len as u64;
        let header: RawHeader = serde_json::from_slice(&json)
            .map_err(|e| bad(format!("JSON header (bytes 12..{body_offset}): {e}")))?;
        if header.layout != "f32le-interleaved" {
            return Err(bad(format!(
                "header field 'layout' is \"{}\", expected \"f32le-interleaved\"",
                header.layout
            )));
        }
        if header.channels > MAX_CHANNELS {
            return Err(bad(format!(
                "header field 'channels' = {} is more than {MAX_CHANNELS}",
                header.channels
            )));
        }
        if header.channels == 0 || !crate::positive_finite(header.sample_rate_hz) {
            return Err(bad(format!(
                "header fields 'channels' = {} and 'sample_rate_hz' = {} must be positive",
                header.channels, header.sample_rate_hz
            )));
        }
        Ok(Self {
            inner,
            header,
            body_offset,
            frames_read: 0,
        })
    }

    /// The header.
    pub fn header(&self) -> &RawHeader {
        &self.header
    }

    /// Byte offset of the first sample in the file.
    pub fn body_offset(&self) -> u64 {
        self.body_offset
    }

    /// Frames read so far.
    pub fn frames_read(&self) -> u64 {
        self.frames_read
    }

    /// Read up to `max_frames` frames into `out` (replacing its contents;
    /// unspecified after an error); returns the number read, 0 at the end.
    /// After the last frame the stream must end.
    ///
    /// Errors ([`EmError::InvalidData`]): the body ends before the header's
    /// frame count (truncated file) or continues after it (trailing bytes).
    pub fn read_frames(&mut self, max_frames: usize, out: &mut Vec<f32>) -> Result<usize> {
        let left = self.header.frames - self.frames_read;
        let frames = (max_frames as u64).min(left) as usize;
        let ch = self.header.channels;
        if frames == 0 {
            out.clear();
            if read_full(&mut self.inner, &mut [0u8; 1])? != 0 {
                return Err(bad(format!(
                    "trailing bytes after the header's {} frames (from byte {})",
                    self.header.frames,
                    self.body_offset + self.header.frames * ch as u64 * 4
                )));
            }
            return Ok(0);
        }
        // Straight into the samples' memory, in steps of at most 1 MiB
        // beyond what was read: a header claiming 10^12 frames meets a short
        // body without a huge allocation first. A buffer passed back in is
        // overwritten as it is (not zeroed first).
        let samples = frames.saturating_mul(ch);
        out.truncate(samples);
        let mut got = 0;
        while got < samples {
            let end = samples.min(got + (1 << 18));
            if out.len() < end {
                out.resize(end, 0.0);
            }
            let bytes: &mut [u8] = bytemuck::cast_slice_mut(&mut out[got..end]);
            let n = read_full(&mut self.inner, bytes)?;
            got += n / 4;
            if n < bytes.len() {
                let read = 4 * got as u64 + (n % 4) as u64;
                let at = self.frames_read + (read / (4 * ch as u64));
                return Err(bad(format!(
                    "truncated body: the header says {} frames × {ch} channels, the file ends in frame {at} (byte {})",
                    self.header.frames,
                    self.body_offset + self.frames_read * ch as u64 * 4 + read
                )));
            }
        }
        if cfg!(target_endian = "big") {
            for v in out.iter_mut() {
                *v = f32::from_bits(u32::from_le(v.to_bits()));
            }
        }
        self.frames_read += frames as u64;
        Ok(frames)
    }
}

/// Parse a raw file's bytes into header and samples ([`RawReader`] over the
/// whole body).
///
/// Errors as [`RawReader::new`] and [`RawReader::read_frames`].
pub fn read_raw(bytes: &[u8]) -> Result<(RawHeader, Vec<f32>)> {
    let mut r = RawReader::new(bytes)?;
    let frames = usize::try_from(r.header().frames)
        .map_err(|_| bad("header field 'frames' too large".into()))?;
    if frames.checked_mul(r.header().channels * 4) != Some(bytes.len() - r.body_offset() as usize) {
        // Same errors as streaming, without allocating a wrong-sized buffer
        // (chunks of at most 1 MiB).
        let chunk = ((1 << 20) / (4 * r.header().channels)).max(1);
        let mut out = Vec::new();
        while r.read_frames(chunk, &mut out)? > 0 {}
    }
    let mut samples = Vec::new();
    r.read_frames(frames, &mut samples)?;
    r.read_frames(1, &mut Vec::new())?;
    Ok((r.header.clone(), samples))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A raw record of 0 frames written by `aeromag em simulate` (cut).
    const RAW0: &[u8] = include_bytes!("../../tests/data/raw_0_frames.raw");

    /// RAW0 with header fields replaced and `body` appended.
    fn with(fields: &[(&str, serde_json::Value)], body: &[u8]) -> Vec<u8> {
        let len = u32::from_le_bytes(RAW0[8..12].try_into().unwrap()) as usize;
        let mut h: serde_json::Value = serde_json::from_slice(&RAW0[12..12 + len]).unwrap();
        for (k, v) in fields {
            h[*k] = v.clone();
        }
        let json = serde_json::to_vec(&h).unwrap();
        let mut out = MAGIC.to_vec();
        out.extend((json.len() as u32).to_le_bytes());
        out.extend(json);
        out.extend(body);
        out
    }

    #[test]
    fn seed_reads() {
        let (h, s) = read_raw(RAW0).unwrap();
        assert_eq!((h.channels, h.frames, s.len()), (3, 0, 0));
    }

    #[test]
    fn header_length_claiming_4_gib_is_an_error_without_allocating_it() {
        let mut b = RAW0[..40].to_vec();
        b[8..12].copy_from_slice(&u32::MAX.to_le_bytes());
        let e = read_raw(&b).unwrap_err().to_string();
        assert!(
            e.contains("announce 4294967295 header bytes, the file has 28"),
            "{e}"
        );
    }

    #[test]
    fn header_claiming_1e12_frames_is_streamed_in_bounded_chunks() {
        let b = with(&[("frames", 1_000_000_000_000u64.into())], &[0u8; 120]);
        let e = read_raw(&b).unwrap_err().to_string();
        assert!(
            e.contains("truncated body") && e.contains("frame 10"),
            "{e}"
        );
        let mut r = RawReader::new(&b[..]).unwrap();
        let mut out = Vec::new();
        assert_eq!(r.read_frames(4, &mut out).unwrap(), 4);
        assert!(r.read_frames(1 << 16, &mut out).is_err());
    }

    #[test]
    fn absurd_channel_counts_are_errors() {
        for ch in [1_000_000_000_000_000u64, u64::MAX, MAX_CHANNELS as u64 + 1] {
            let b = with(&[("channels", ch.into()), ("frames", 1u64.into())], &[]);
            let e = read_raw(&b).unwrap_err().to_string();
            assert!(e.contains("'channels'"), "{ch}: {e}");
        }
        // At the limit: 10^12 frames of 1024 channels in a 4 KiB body.
        let b = with(
            &[
                ("channels", MAX_CHANNELS.into()),
                ("frames", 1_000_000_000_000u64.into()),
            ],
            &[0u8; 4096],
        );
        let e = read_raw(&b).unwrap_err().to_string();
        assert!(e.contains("truncated body"), "{e}");
        let mut r = RawReader::new(&b[..]).unwrap();
        assert!(r.read_frames(usize::MAX, &mut Vec::new()).is_err());
    }
}
