//! `aeromag em calibrate`: the three calibration stages from detected
//! vectors and a KNOWN file.

use super::HalfSpaceArg;
use super::files::{at, finite_column, load_table, read_detected, read_system};
use crate::exit::bad_input;
use aeromag_core::frames::Attitude;
use aeromag_em::calibration::{Calibration, CalibrationFile, FitCounts, KnownPoints};
use aeromag_em::detection::FieldEpoch;
use aeromag_em::positioning::Hemisphere;
use aeromag_em::study::rms;
use aeromag_io::FlightTable;
use nalgebra::Vector3;
use std::path::PathBuf;

/// Fit the three-stage calibration from detected vectors and known points.
///
/// The three calibration stages of seed 001:
///   1. polarisation: detection phases and imaginary couplings that make each
///      dipole's field linearly polarised, by least squares over ALL epochs
///      (no external information; needs ≥ 8 epochs at varied attitudes);
///   2. transmitter geometry: the 6 coefficients of the symmetric
///      transmitter distortion from the epochs whose position (range and
///      direction) KNOWN.csv gives (≥ 2);
///   3. attitude: the small rotation Q from the epoch(s) whose attitude
///      KNOWN.csv gives (one suffices).
///
/// `em locate` applies them in the same order.
///
/// KNOWN.csv (CSV, `#` comments allowed), one row per known point:
///   time_s                 time of the point, s; must fall within half an
///                          epoch spacing of a detected epoch's time_s
///   x_m, y_m, z_m          receiver position in the transmitter frame, m
///                          (all three, or all three empty)
///   roll_deg, pitch_deg,   receiver attitude relative to the transmitter
///   yaw_deg                frame, Z-Y-X Euler angles, deg (all three, or
///                          all three empty; the columns may be omitted)
/// A row gives a position, an attitude or both. Example:
///   time_s,x_m,y_m,z_m,roll_deg,pitch_deg,yaw_deg
///   0.07999,-52.1,1.9,39.2,12.5,-3.1,0.2
///   0.23999,-52.2,2.4,39.1,,,
///
/// The calibration file (JSON) holds "format": "aeromag-em-calibration",
/// "version": 1, the nominal moments, the three stages and the fit counts.
///
/// Example:
///   aeromag em calibrate --input em/detected.csv --known em/em.known.csv \
///       --system em/em.system.json --out em/cal.json
#[derive(Debug, clap::Args)]
#[command(verbatim_doc_comment)]
pub struct CalibrateArgs {
    /// Detected-vector CSV (`aeromag em detect`).
    #[arg(long, short = 'i', value_name = "DETECTED.csv")]
    input: PathBuf,
    /// Known positions and attitude (format above).
    #[arg(long, value_name = "KNOWN.csv")]
    known: PathBuf,
    /// Instrument constants (nominal moments): em.system.json.
    #[arg(long, value_name = "FILE.json")]
    system: PathBuf,
    /// Calibration file to write (JSON).
    #[arg(long, value_name = "CAL.json")]
    out: PathBuf,
    #[command(flatten)]
    half_space: HalfSpaceArg,
}

/// Parse KNOWN.csv against the detected epochs' times.
fn known_points(t: &FlightTable, epochs: &[FieldEpoch]) -> anyhow::Result<KnownPoints> {
    let time = finite_column(t, "time_s")?;
    let group = |names: [&str; 3], required: bool| -> anyhow::Result<Option<[&[f64]; 3]>> {
        let present = names.iter().filter(|n| t.get(n).is_some()).count();
        if present == 0 && !required {
            return Ok(None);
        }
        Ok(Some([
            t.require(names[0])?,
            t.require(names[1])?,
            t.require(names[2])?,
        ]))
    };
    let pos = group(["x_m", "y_m", "z_m"], true)?;
    let att = group(["roll_deg", "pitch_deg", "yaw_deg"], false)?;
    let names = |g: [&'static str; 3]| g;
    let spacing = if epochs.len() > 1 {
        let mut d: Vec<f64> = epochs
            .windows(2)
            .map(|w| w[1].time_s - w[0].time_s)
            .collect();
        d.sort_by(f64::total_cmp);
        d[d.len() / 2]
    } else {
        f64::INFINITY
    };
    let mut known = KnownPoints::default();
    for row in 0..t.n_rows() {
        let tk = time[row];
        let k = epochs.partition_point(|e| e.time_s < tk);
        let nearest = [k.checked_sub(1), Some(k)]
            .into_iter()
            .flatten()
            .filter(|&j| j < epochs.len())
            .min_by(|&a, &b| {
                (epochs[a].time_s - tk)
                    .abs()
                    .total_cmp(&(epochs[b].time_s - tk).abs())
            });
        let epoch = nearest
            .filter(|&j| (epochs[j].time_s - tk).abs() <= 0.5 * spacing)
            .ok_or_else(|| {
                bad_input!(
                    "{}: {tk} s is not within half an epoch ({:.4} s) of any detected epoch ({} … {} s)",
                    at(t, row, "time_s"),
                    0.5 * spacing,
                    epochs.first().map_or(f64::NAN, |e| e.time_s),
                    epochs.last().map_or(f64::NAN, |e| e.time_s)
                )
            })?;
        let mut any = false;
        for (cols, g) in [
            (pos, names(["x_m", "y_m", "z_m"])),
            (att, names(["roll_deg", "pitch_deg", "yaw_deg"])),
        ] {
            let Some(c) = cols else { continue };
            let v = [c[0][row], c[1][row], c[2][row]];
            let given = v.map(|x| !x.is_nan());
            if given.iter().all(|&g| !g) {
                continue;
            }
            if let Some(j) = (0..3).find(|&j| !given[j] || !v[j].is_finite()) {
                return Err(bad_input!(
                    "{}: value missing or not finite while {} are given (give all three or none)",
                    at(t, row, g[j]),
                    g.iter()
                        .filter(|&&n| n != g[j])
                        .copied()
                        .collect::<Vec<_>>()
                        .join(" and ")
                ));
            }
            any = true;
            if g[0] == "x_m" {
                known
                    .positions
                    .push((epoch, Vector3::new(v[0], v[1], v[2])));
            } else {
                let c_nb =
                    Attitude::new(v[0].to_radians(), v[1].to_radians(), v[2].to_radians()).c_nb();
                known.attitudes.push((epoch, c_nb.transpose()));
            }
        }
        if !any {
            return Err(bad_input!(
                "{}: the row gives neither a position (x_m, y_m, z_m) nor an attitude (roll_deg, pitch_deg, yaw_deg)",
                at(t, row, "x_m")
            ));
        }
    }
    let file = t.file_label();
    if known.positions.len() < 2 {
        return Err(bad_input!(
            "'{file}': {} known position(s); calibration stage 2 needs at least 2",
            known.positions.len()
        ));
    }
    if known.attitudes.is_empty() {
        return Err(bad_input!(
            "'{file}': no known attitude (roll_deg, pitch_deg, yaw_deg); calibration stage 3 needs one"
        ));
    }
    Ok(known)
}

pub fn run(a: CalibrateArgs) -> anyhow::Result<()> {
    let normal = a.half_space.normal()?;
    let system = read_system(&a.system)?;
    let epochs = read_detected(&a.input)?;
    if epochs.len() < 8 {
        return Err(bad_input!(
            "'{}': {} epochs; calibration stage 1 needs at least 8 at varied attitudes",
            a.input.display(),
            epochs.len()
        ));
    }
    let known = known_points(&load_table(&a.known)?, &epochs)?;
    let data: Vec<_> = epochs.iter().map(|e| e.h).collect();
    let m = system.moments_am2;
    let cal = Calibration::fit(&data, &known, &m, &Hemisphere::new(normal)).map_err(|e| {
        bad_input!(
            "calibration from '{}' and '{}' failed: {e}",
            a.input.display(),
            a.known.display()
        )
    })?;
    let file = CalibrationFile::new(
        cal,
        m,
        FitCounts {
            epochs: data.len(),
            known_positions: known.positions.len(),
            known_attitudes: known.attitudes.len(),
        },
    );
    std::fs::write(&a.out, file.to_json()?)?;
    let before: Vec<f64> = data
        .iter()
        .flat_map(|e| aeromag_em::calibration::uncalibrated(e, &cal.polarisation.phase_rad).1)
        .collect();
    let after: Vec<f64> = data
        .iter()
        .flat_map(|e| cal.polarisation.apply(e).1)
        .collect();
    let (rb, ra) = (rms(&before), rms(&after));
    println!(
        "calibrated from {} epochs, {} known positions, {} known attitude(s)",
        data.len(),
        known.positions.len(),
        known.attitudes.len()
    );
    println!(
        "  polarisation ratio RMS {rb:.3e} → {ra:.3e} ({:.0}×)",
        rb / ra.max(f64::MIN_POSITIVE)
    );
    println!(
        "  transmitter distortion |S| = {:.3e}, attitude correction {:.4} deg",
        cal.transmitter_s.norm(),
        aeromag_em::positioning::rotation_angle_between(
            &cal.attitude_q,
            &nalgebra::Matrix3::identity()
        )
        .to_degrees()
    );
    println!("  calibration {}", a.out.display());
    Ok(())
}
