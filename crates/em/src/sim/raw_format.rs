//! Binary raw format of the ADC record (issue 6 item 1: "little-endian f32
//! interleaved plus a small JSON header").
//!
//! ```text
//! bytes 0..8     magic  "AEMRAW1\n"
//! bytes 8..12    u32 LE length L of the JSON header
//! bytes 12..12+L JSON RawHeader (UTF-8)
//! then           frames × channels f32 LE, interleaved: sample n, channel c at index n·channels + c
//! ```

use super::scenario::EmScenario;
use crate::{EmError, Result};
use std::io::Write;

/// The 8-byte magic at the start of a raw file.
pub const MAGIC: &[u8; 8] = b"AEMRAW1\n";

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
    /// The scenario that produced the record (truth and distortions). The
    /// drawn matrices are informational (JSON may round their last ulp);
    /// `EmScenario::new(scenario.config)` reproduces them exactly.
    pub scenario: EmScenario,
}

impl RawHeader {
    /// Header for `frames` frames of `channels` channels.
    pub fn new(
        sample_rate_hz: f64,
        channels: usize,
        frames: u64,
        start_index: u64,
        scenario: EmScenario,
    ) -> Self {
        Self {
            layout: "f32le-interleaved".into(),
            sample_rate_hz,
            channels,
            frames,
            start_index,
            scenario,
        }
    }
}

/// Write header and samples.
///
/// Errors: sample count not `frames × channels`, or an I/O failure.
pub fn write_raw<W: Write>(mut w: W, header: &RawHeader, samples: &[f32]) -> Result<()> {
    let expected = header.frames as usize * header.channels;
    if samples.len() != expected {
        return Err(EmError::InvalidArgument(format!(
            "{} samples, header says {expected}",
            samples.len()
        )));
    }
    let json = serde_json::to_vec(header).map_err(|e| EmError::InvalidData(e.to_string()))?;
    let len =
        u32::try_from(json.len()).map_err(|_| EmError::InvalidData("header too long".into()))?;
    let io = |e: std::io::Error| EmError::InvalidData(e.to_string());
    w.write_all(MAGIC).map_err(io)?;
    w.write_all(&len.to_le_bytes()).map_err(io)?;
    w.write_all(&json).map_err(io)?;
    let mut buf = Vec::with_capacity(samples.len() * 4);
    for v in samples {
        buf.extend_from_slice(&v.to_le_bytes());
    }
    w.write_all(&buf).map_err(io)
}

/// Parse a raw file's bytes into header and samples.
///
/// Errors ([`EmError::InvalidData`]) for a wrong magic, a malformed header or
/// a truncated body.
pub fn read_raw(bytes: &[u8]) -> Result<(RawHeader, Vec<f32>)> {
    let bad = |m: &str| EmError::InvalidData(m.into());
    if bytes.len() < 12 || &bytes[..8] != MAGIC {
        return Err(bad("not an aeromag EM raw file"));
    }
    let len = u32::from_le_bytes([bytes[8], bytes[9], bytes[10], bytes[11]]) as usize;
    let body_start = 12usize
        .checked_add(len)
        .filter(|&e| e <= bytes.len())
        .ok_or_else(|| bad("truncated header"))?;
    let header: RawHeader = serde_json::from_slice(&bytes[12..body_start])
        .map_err(|e| EmError::InvalidData(e.to_string()))?;
    let n = (header.frames as usize)
        .checked_mul(header.channels)
        .ok_or_else(|| bad("header sizes overflow"))?;
    let body = &bytes[body_start..];
    if body.len() != n * 4 {
        return Err(bad("body length does not match the header"));
    }
    let samples = body
        .chunks_exact(4)
        .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        .collect();
    Ok((header, samples))
}
