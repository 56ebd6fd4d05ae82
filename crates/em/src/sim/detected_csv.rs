//! CSV of detected field vectors, the output of `aeromag em detect` and the
//! input of `em calibrate` / `em locate` (issue 6 item 1: "CSV for the
//! detected vectors"; column conventions of spec `data-formats.md`: units in
//! the names).
//!
//! Columns, one row per detector block:
//!
//! | column | meaning |
//! |---|---|
//! | `time_s` | block centre, s (absolute sample index / rate) |
//! | `h{i}_{c}_re_t`, `h{i}_{c}_im_t` | complex field of dipole `i` = 1..3 on receiver axis `c` ∈ {x, y, z}, T, pilot-corrected (`χ⁻¹ ξ⁻¹ U0/(−iωg)`) |
//! | `xi{i}_{c}_re`, `xi{i}_{c}_im` | channel sensitivity `ξ_c(ω_i)` measured by the pilot tones (eq. 4; detected pilot / nominal pilot, 1 without pilot correction) |
//! | `pol_ratio_{i}` | polarisation ratio (minor/major axis) of dipole `i`'s field before calibration |
//!
//! Numbers use Rust's shortest round-trip formatting, so reading the file
//! back gives the detected values bit for bit. No truth is written here
//! (see [`super::truth_csv()`]).

use crate::detection::{Complex64, FieldEpoch, major_axis};
use crate::{EmError, Result};
use std::fmt::Write;

const AXES: [&str; 3] = ["x", "y", "z"];

/// Names of the 36 value columns in file order: the 18 `h…` columns, then
/// the 18 `xi…` columns (re, im per dipole and axis).
pub fn value_columns() -> Vec<String> {
    let mut v = Vec::with_capacity(36);
    for i in 1..=3 {
        for a in AXES {
            v.push(format!("h{i}_{a}_re_t"));
            v.push(format!("h{i}_{a}_im_t"));
        }
    }
    for i in 1..=3 {
        for a in AXES {
            v.push(format!("xi{i}_{a}_re"));
            v.push(format!("xi{i}_{a}_im"));
        }
    }
    v
}

/// The CSV text (header plus one row per epoch).
pub fn detected_csv(epochs: &[FieldEpoch]) -> String {
    let mut s = String::from("time_s");
    for c in value_columns() {
        s.push(',');
        s.push_str(&c);
    }
    s.push_str(",pol_ratio_1,pol_ratio_2,pol_ratio_3\n");
    for e in epochs {
        let _ = write!(s, "{}", e.time_s);
        for v in e.h.iter().flatten().chain(e.xi.iter().flatten()) {
            let _ = write!(s, ",{},{}", v.re, v.im);
        }
        for h in &e.h {
            let _ = write!(s, ",{}", major_axis(h).ratio);
        }
        s.push('\n');
    }
    s
}

/// Rebuild an epoch from its time (s) and the 36 values of
/// [`value_columns`] in that order.
///
/// Errors ([`EmError::InvalidData`]) for a wrong count; the caller checks
/// finiteness (it knows the file positions).
pub fn field_epoch_from_values(time_s: f64, values: &[f64]) -> Result<FieldEpoch> {
    if values.len() != 36 {
        return Err(EmError::InvalidData {
            reason: format!("{} detected values, expected 36", values.len()),
        });
    }
    let c = |k: usize| Complex64::new(values[2 * k], values[2 * k + 1]);
    let block = |o: usize| [0, 1, 2].map(|i| [0, 1, 2].map(|a| c(o + 3 * i + a)));
    Ok(FieldEpoch {
        time_s,
        h: block(0),
        xi: block(9),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip_of_values() {
        let e = FieldEpoch {
            time_s: 1.25,
            h: [0, 1, 2].map(|i| {
                [0, 1, 2].map(|a| Complex64::new(1e-9 * (i * 3 + a) as f64, -3e-12 * a as f64))
            }),
            xi: [0, 1, 2]
                .map(|i| [0, 1, 2].map(|a| Complex64::new(1.0 + 0.01 * (i + a) as f64, 0.02))),
        };
        let text = detected_csv(std::slice::from_ref(&e));
        let mut lines = text.lines();
        let header: Vec<&str> = lines.next().unwrap().split(',').collect();
        assert_eq!(header.len(), 1 + 36 + 3);
        assert_eq!(&header[1..37], value_columns().as_slice());
        let row: Vec<f64> = lines
            .next()
            .unwrap()
            .split(',')
            .map(|v| v.parse().unwrap())
            .collect();
        let back = field_epoch_from_values(row[0], &row[1..37]).unwrap();
        assert_eq!(back, e);
        assert!(field_epoch_from_values(0.0, &row[1..36]).is_err());
    }
}
