//! A rotor model applied to a flight: per stretch between gaps, the phase
//! from its channel (or estimated and aligned with the model over a whole
//! revolution) and the slowly varying angles tracked with the parameters
//! fixed.

use super::columns::{RotorColumns, check_rotor_speed, mean_rotor_hz};
use crate::compensate::{Compensator, OutputColumns};
use crate::error::{InFile, Result};
use crate::flight::Flight;
use crate::observer::{Note, Observer};
use aeromag_compensation::rotor::model_file::RotorModelFile;
use aeromag_compensation::rotor::{
    FlapAngles, RotorInput, SlowAngleOptions, TailRotor, align_phase_offset, estimate_phase,
    regressors, rotor_speed, track_slow_angles, unwrap_deg,
};
use aeromag_core::error::{figure, shown};
use nalgebra::Vector3;
use std::ops::Range;

/// The columns `rotor apply` adds: `rotor_interf`, `mag_comp`, `rotor_flag`.
pub const ROTOR_OUTPUT: OutputColumns = OutputColumns {
    interference: "rotor_interf",
    flag: "rotor_flag",
    why_missing: "missing values or stretches under 10 s",
    why_beyond: "an edited or corrupted parameter, another helicopter's model, or a sensor \
                 beside a magnetised part, where the fluxgate's field direction is not the \
                 sensor's?",
};

/// Phase (rad, unwrapped) and rotor speed (rad/s) of one segment: from the
/// channel, or estimated from `mag` (steps 1–2 of the library's `phase`)
/// in the rotor band `band` (Hz), an error naming the band's option and
/// `file` when the data show no rotor there.
pub(super) fn segment_phase(
    cols: &RotorColumns,
    r: &Range<usize>,
    fs: f64,
    blades: usize,
    band: [f64; 2],
    file: &str,
) -> Result<(Vec<f64>, Vec<f64>)> {
    let phase = match cols.phase {
        Some(p) => unwrap_deg(&p[r.clone()]),
        None => {
            estimate_phase(&cols.mag[r.clone()], fs, blades, band[0], band[1])
                .map_err(|e| {
                    e.at(format!(
                        "the rotor phase estimated from `mag` in the rotor band {},{} Hz \
                         (--rotor-hz of `rotor fit`, kept in the model as phase.rotor_hz_range)",
                        shown(band[0]),
                        shown(band[1])
                    ))
                })
                .in_file(file)?
                .phase_rad
        }
    };
    let omega = rotor_speed(&phase, fs, 1.0)?;
    Ok((phase, omega))
}

/// Options of the tracking on new data with a phase estimated from it: the
/// final options plus a slowly varying phase correction.
fn tracking_with_phase(o: &SlowAngleOptions) -> SlowAngleOptions {
    SlowAngleOptions {
        estimate_phase: true,
        iterations: o.iterations.max(6),
        ..*o
    }
}

/// One stretch of a record with the rotor phase, speed and slowly varying
/// angles found for it with a fitted model.
pub(super) struct TrackedSegment {
    b: Vec<Vector3<f64>>,
    omega: Vec<f64>,
    phase: Vec<f64>,
    angles: Vec<FlapAngles>,
    /// The recorded main phase (rad, unwrapped), which the tail rotor's is
    /// geared from.
    recorded_phase: Vec<f64>,
}

impl TrackedSegment {
    /// The regressor columns of `model` on this stretch: the main rotor's,
    /// then the tail rotor's when modelled.
    pub fn columns(&self, model: &RotorModelFile, fs: f64) -> Result<Vec<Vec<f64>>> {
        let mut cols = regressors(&model.geometry, model.model.terms, &self.input())?;
        if let Some(t) = &model.tail {
            let phase = TailRotor::smoothed_main_phase(&self.recorded_phase, fs)?;
            cols.extend(t.rotor.regressors(
                t.model.terms,
                &self.b,
                &phase,
                &self.omega,
                t.offset_rad,
            )?);
        }
        Ok(cols)
    }

    /// The modelled interference of this stretch (main and tail rotor),
    /// nT.
    pub fn predict(&self, model: &RotorModelFile, fs: f64) -> Result<Vec<f64>> {
        let mut p = model.model.predict(&model.geometry, &self.input())?;
        if let Some(t) = &model.tail {
            let tp = t.rotor.predict(
                &t.model,
                t.offset_rad,
                &self.b,
                &self.recorded_phase,
                &self.omega,
                fs,
            )?;
            p.iter_mut().zip(tp).for_each(|(a, b)| *a += b);
        }
        Ok(p)
    }

    pub fn input(&self) -> RotorInput<'_> {
        RotorInput {
            b_body_nt: &self.b,
            phase_rad: &self.phase,
            omega_rad_s: &self.omega,
            angles: &self.angles,
        }
    }
}

/// Phase (from the channel, or estimated and aligned to `model`) and the
/// slowly varying angles (tracked with `model`'s parameters fixed) of rows
/// `r`: what `rotor apply` does to a stretch, and what `rotor fit` does to
/// the stretches it refits on.
pub(super) fn track_segment(
    model: &RotorModelFile,
    cols: &RotorColumns,
    r: &Range<usize>,
    fs: f64,
    file: &str,
) -> Result<TrackedSegment> {
    let g = &model.geometry;
    let nominal = [model.nominal_angles];
    let b = cols.field(r);
    let (mut phase, omega) =
        segment_phase(cols, r, fs, g.blades, model.phase.rotor_hz_range, file)?;
    // The phase channel checked as the fit checks it: a phase in radians,
    // reversed, stuck or random was applied with exit 0 (interference of
    // ±10⁴ nT).
    check_rotor_speed(
        mean_rotor_hz(&omega),
        fs,
        g.blades,
        model.phase.column.as_deref(),
        model.tail.as_ref().map(|t| &t.rotor),
        file,
    )?;
    let recorded_phase = phase.clone();
    // The slow angles are tracked on the reading minus the tail rotor's part.
    let rest;
    let mag = match &model.tail {
        None => &cols.mag[r.clone()],
        Some(t) => {
            let tp = t
                .rotor
                .predict(&t.model, t.offset_rad, &b, &phase, &omega, fs)?;
            rest = cols.mag[r.clone()]
                .iter()
                .zip(tp)
                .map(|(m, p)| m - p)
                .collect::<Vec<f64>>();
            &rest
        }
    };
    let estimated = model.phase.column.is_none();
    if estimated {
        let inp = RotorInput {
            b_body_nt: &b,
            phase_rad: &phase,
            omega_rad_s: &omega,
            angles: &nominal,
        };
        let c = align_phase_offset(g, &model.model, &inp, mag, fs, &model.fit_options)?;
        phase.iter_mut().for_each(|p| *p += c);
    }
    let inp = RotorInput {
        b_body_nt: &b,
        phase_rad: &phase,
        omega_rad_s: &omega,
        angles: &nominal,
    };
    let opts = if estimated {
        tracking_with_phase(&model.slow_angles)
    } else {
        model.slow_angles
    };
    let slow = track_slow_angles(g, &model.model, &inp, mag, fs, &model.fit_options, &opts)?;
    Ok(TrackedSegment {
        b,
        omega,
        phase: slow.phase_rad,
        angles: slow.angles,
        recorded_phase,
    })
}

impl Compensator for RotorModelFile {
    fn output(&self) -> OutputColumns {
        ROTOR_OUTPUT
    }

    /// The modelled rotor interference (nT, slow part included) of every
    /// stretch of at least 10 s without gaps or missing values; NaN
    /// elsewhere. A sample rate other than the model's is a warning.
    fn interference_observed(
        &self,
        flight: &Flight,
        observer: &mut dyn Observer,
    ) -> Result<Vec<f64>> {
        let raw = RotorColumns::of(flight, self.phase.column.as_deref())?;
        let fs = flight.sample_rate_hz()?;
        if (fs / self.sample_rate_hz - 1.0).abs() > 0.01 {
            observer.note(&Note::warning(format!(
                "{}: sample rate {} Hz differs from the model's {} Hz",
                flight.label(),
                figure(fs),
                figure(self.sample_rate_hz)
            )));
        }
        // Dropouts bridged as the fit bridges them (one missing cell every
        // 5 s left the whole flight uncompensated, with exit 0).
        let bridged = raw.bridged(fs);
        let cols = raw.with(&bridged.columns);
        for n in bridged.notes(flight, "to track the rotor") {
            observer.note(&n);
        }
        let mut out = vec![f64::NAN; flight.n_rows()];
        // Each stretch alone, the stretches on the cores; the first failure
        // in their order reported.
        let stretches = cols.usable_stretches(flight, fs)?;
        let label = flight.label();
        let threads = aeromag_core::parallel::threads();
        let predicted = aeromag_core::parallel::parallel_map(stretches.len(), threads, |i| {
            let t = track_segment(self, &cols, &stretches[i], fs, &label).in_file(&label)?;
            t.predict(self, fs)
        });
        for (r, p) in stretches.into_iter().zip(predicted) {
            out[r].copy_from_slice(&p?);
        }
        // A bridged row keeps its stretch whole, but its interference is
        // given only where its own readings are.
        let raw_cols = raw.all();
        for (i, o) in out.iter_mut().enumerate() {
            if raw_cols.iter().any(|c| !c[i].is_finite()) {
                *o = f64::NAN;
            }
        }
        Ok(out)
    }
}
