//! Several scalar magnetometers in one run: one Tolles-Lawson model per
//! sensor, the reference-sensor mode, and the compensated readings and
//! their differences (gradients).
//!
//! A survey or magnetic-navigation aircraft carries several scalar
//! magnetometers (SGL's: a tail stinger and four cabin sensors) and several
//! fluxgates. [`calibrate_sensors`] fits each scalar sensor with its vector
//! magnetometer ([`SensorColumns`]) by the method of the options, and
//! writes one model file ([`SensorsModel`], kind `tolles-lawson-sensors`);
//! [`SensorsModel::compensate`] applies it, giving `<name>_comp` and
//! `<name>_interf` per sensor (`mag_3` for `mag_3_uc`) and the differences
//! of the compensated readings to the first sensor's, `<name>_grad` (nT).
//!
//! **Reference-sensor mode** ([`SensorSet::reference`]): a well-compensated
//! sensor — the tail stinger — is the external-field reference of the
//! others over the whole flight, not only the calibration box. The
//! reference sensor is fitted first (or, when it is not among the sensors,
//! read as an already compensated column such as SGL's `mag_1_c`); the
//! other sensors are then fitted to `mag_k − ref_comp`, the interference at
//! sensor `k` plus the (small, slowly varying) difference of the external
//! field between the two positions, on every row: without the band-pass
//! filter, with a `bias` term for the mean difference. This is how cabin
//! sensors are used in magnetic-navigation research (the compensated tail
//! as target); it needs no manoeuvres, only a flight whose headings and
//! currents vary. The other sensors are fitted by least squares whatever
//! the method (the Kalman method's random-walk field would absorb the
//! slowly switching currents: 0.631 against 0.210 nT on a cabin sensor),
//! and their reference is the reference sensor compensated by band-pass
//! LS even when its own model is fitted by the Kalman method: on two
//! simulated cabins (demo seed 1; `tools/validate/perturb_installation.py`
//! seed 23) that reference left six of eight cabin sensors lower on the
//! survey (mag_3 0.1022 against 0.1055 nT), one equal, one higher
//! (0.1860 against 0.1846 nT).
//!
//! The reference sensor itself is fitted through the box's turns: its legs
//! end at time gaps and unusable rows, not at changes of `line` (the other
//! sensors are fitted against it on every row, turns included). The turns'
//! heading changes carry its permanent terms, which a band-pass fit leg by
//! leg only sees through the small attitude changes of the manoeuvres; its
//! heading error passes on to every sensor referred to it. On the cabin of
//! `perturb_installation.py` seed 23 (box seed 7, survey seed 8) the
//! stinger went 0.176 → 0.157 nT on the survey, and the cabin sensors
//! against their oracles 1.02/1.39/1.03/2.74 → 1.03/1.44/1.03/1.21
//! (mag_5_uc 0.075 → 0.033 nT: its per-line offsets were the stinger's).

use super::calibrate::{CalibrateOptions, Calibration, Method, calibrate_with};
use super::compensate::tl_interference;
use crate::error::{Error, Result};
use crate::flight::{Flight, ReferenceChannels, SensorColumns};
use crate::observer::{Note, Notes, Observer};
use aeromag_compensation::model_file::{SensorModel, SensorsModel};
use aeromag_compensation::tolles_lawson::TermGroup;
use aeromag_compensation::tolles_lawson::fit_ls::LsConfig;
use aeromag_io::FlightTable;

/// The sensors of a multi-sensor calibration.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct SensorSet {
    /// The scalar sensors with their vector magnetometers, in order (the
    /// first is the base of the gradients).
    pub sensors: Vec<SensorColumns>,
    /// Reference-sensor mode (module docs): the scalar sensor (one of
    /// `sensors`, by its column) whose compensated reading is the other
    /// sensors' external-field reference, or an already compensated column.
    pub reference: Option<String>,
}

/// The result of [`calibrate_sensors`].
#[derive(Debug, Clone)]
pub struct SensorsCalibration {
    /// The model file.
    pub model: SensorsModel,
    /// Each sensor's calibration, in the order of the model's sensors.
    pub calibrations: Vec<Calibration>,
    /// Notes and warnings raised while fitting, in order.
    pub notes: Vec<Note>,
}

/// Fit one Tolles-Lawson model per sensor of `set` on `flight` with the
/// options `opts` (their `sensor` is replaced by each of `set`'s). Reads
/// what [`super::calibrate`] reads for each sensor; never a `true_` column.
pub fn calibrate_sensors(
    flight: &Flight,
    set: &SensorSet,
    opts: &CalibrateOptions,
    observer: &mut dyn Observer,
) -> Result<SensorsCalibration> {
    if set.sensors.is_empty() {
        return Err(Error::bad_input("no scalar sensor to calibrate"));
    }
    let mut notes = Notes::new(observer);
    let names: Vec<String> = set.sensors.iter().map(SensorColumns::stem).collect();
    if let Some((k, n)) = names
        .iter()
        .enumerate()
        .find(|(k, n)| names[..*k].contains(n))
    {
        return Err(Error::bad_input(format!(
            "sensor {} ({}) is given twice",
            set.sensors[k].mag, n
        )));
    }
    if set.sensors.len() > 1 && opts.lever_arm.is_some() {
        return Err(Error::bad_input(
            "--lever-arm is one sensor's: calibrate several sensors without it",
        ));
    }
    let of = |s: &SensorColumns| CalibrateOptions {
        sensor: s.clone(),
        ..opts.clone()
    };
    // The reference: fitted first when it is one of the sensors.
    // By its SGL name in either naming (`UNCOMPMAG1` is `mag_1_uc`), or
    // its stem (`mag_1`).
    let ref_index = match &set.reference {
        Some(r) => set.sensors.iter().position(|s| {
            aeromag_io::sensor_names(r)
                .iter()
                .any(|n| s.mag.eq_ignore_ascii_case(n))
                || s.stem() == *r
        }),
        None => None,
    };
    // The model keeps the MagNav name (module docs of `SensorColumns::find`).
    let reference_name = set.reference.as_ref().map(|r| match ref_index {
        Some(i) => set.sensors[i].mag.clone(),
        None => aeromag_io::magnav_name(r),
    });
    let mut fitted: Vec<Option<(Calibration, Option<String>)>> = vec![None; set.sensors.len()];
    let mut reference_nt: Option<Vec<f64>> = None;
    if let Some(i) = ref_index {
        let s = &set.sensors[i];
        notes.stage(&format!("calibrating the reference sensor {}", s.mag));
        notes.check_cancelled()?;
        // Filtered through the turns, as the other sensors are fitted
        // against it (module docs).
        let through = CalibrateOptions {
            split_lines: false,
            ..of(s)
        };
        let cal = calibrate_with(flight, &through, None, &mut notes)?;
        // The other sensors' reference is the reference sensor compensated
        // by band-pass LS, whatever the method of its own model (module
        // docs).
        let ls_model = if opts.method == Method::Ls {
            None
        } else {
            notes.stage(&format!("least-squares reference fit of {}", s.mag));
            notes.check_cancelled()?;
            let ls = CalibrateOptions {
                method: Method::Ls,
                ..through.clone()
            };
            Some(calibrate_with(flight, &ls, None, &mut notes)?.model)
        };
        let interf = tl_interference(ls_model.as_ref().unwrap_or(&cal.model), flight, s)?;
        let mag = flight.require(&s.mag)?;
        reference_nt = Some(mag.iter().zip(&interf).map(|(m, i)| m - i).collect());
        fitted[i] = Some((cal, None));
    }
    if set.reference.is_some() && opts.method == Method::Kalman {
        notes.note(
            "reference-sensor mode: the reference removes the external field, so the Kalman \
             method's field model has nothing to estimate; the other sensors are fitted by least \
             squares on every row (the Kalman method with a constant field), against the \
             reference sensor compensated by band-pass least squares",
        );
    }
    for (k, s) in set.sensors.iter().enumerate() {
        if fitted[k].is_some() {
            continue;
        }
        notes.stage(&format!("calibrating {}", s.mag));
        notes.check_cancelled()?;
        let (o, series, reference) = match (&reference_name, &reference_nt) {
            (None, _) => (of(s), None, None),
            (Some(r), Some(series)) => {
                (reference_mode(&of(s))?, Some(&series[..]), Some(r.clone()))
            }
            (Some(r), None) => {
                // An already compensated column: the reference channel.
                let o = CalibrateOptions {
                    reference: ReferenceChannels::Columns(vec![r.clone()]),
                    ..reference_mode(&of(s))?
                };
                (o, None, Some(r.clone()))
            }
        };
        let cal = calibrate_with(flight, &o, series, &mut notes)?;
        fitted[k] = Some((cal, reference));
    }
    let mut calibrations = Vec::new();
    let mut sensors = Vec::new();
    for ((s, name), f) in set.sensors.iter().zip(names).zip(fitted) {
        let (cal, reference_sensor) = f.expect("every sensor fitted");
        sensors.push(SensorModel {
            name,
            mag: s.mag.clone(),
            flux: s.flux.clone(),
            reference_sensor,
            model: cal.model.clone(),
        });
        calibrations.push(cal);
    }
    Ok(SensorsCalibration {
        model: SensorsModel::new(sensors),
        calibrations,
        notes: notes.into_notes(),
    })
}

/// The options of a sensor fitted against a reference sensor: every row
/// unfiltered (the reference removes the external field, so no reference
/// channel is subtracted besides it), a `bias` term for the mean
/// difference of the field between the two positions, by least squares
/// whatever the method of `opts`, in contiguous stretches rather than line
/// by line.
///
/// Not split at the lines because nothing is filtered leg by leg here and
/// the lagged terms must run through the line changes as the compensation
/// applies them: restarted at each leg in steady state, a lagged current
/// that switched shortly before left a transient the fit could not explain
/// (on a cabin whose heater gives 11 nT through a 0.63 s lag, split fits
/// left 2.4 nT RMS on the box where the same model applied through the
/// line changes left 0.9, and the lag searches put another current's lag
/// at the end of their range, 4 s for 0.74; fitted through the line
/// changes: 0.28 nT, lags 0.81/0.39/0.63 s for 0.74/0.39/0.63).
///
/// Least squares because the Kalman method's stochastic field has nothing
/// to model here but the constant difference: given the freedom of a
/// random-walk field along the track (and of the vertical-gradient states,
/// which follow the altitude changes of the pitch manoeuvres), it absorbs
/// the slowly switching currents' interference and biases their
/// coefficients. Measured on the SGL-like installation (8-cycle box seed 1,
/// 3-line survey seed 2, `mag_5_uc` with the heater): least squares
/// 0.210 nT, the Kalman method 0.631 nT (tuned), 0.421–0.455 nT with a
/// deterministic field (noise fixed at zero, by legs or one run).
fn reference_mode(opts: &CalibrateOptions) -> Result<CalibrateOptions> {
    let terms = &opts.ls.design.terms;
    let mut groups = terms.groups().to_vec();
    if !groups.contains(&TermGroup::Bias) {
        groups.push(TermGroup::Bias);
    }
    let with_bias = aeromag_compensation::tolles_lawson::TermSet::new(&groups)
        .and_then(|t| t.with_eddy_lags(terms.eddy_lags_s()))
        .and_then(|t| t.with_extras(terms.extras()))
        .map_err(|e| Error::bad_input(format!("terms: {e}")))?;
    Ok(CalibrateOptions {
        method: Method::Ls,
        ls: LsConfig {
            design: opts.ls.design.with_terms(with_bias),
            band_hz: None,
            trim: 0,
            ..opts.ls.clone()
        },
        reference: ReferenceChannels::None,
        split_lines: false,
        ..opts.clone()
    })
}

/// The compensated readings of a [`SensorsModel`] on a flight.
#[derive(Debug, Clone, PartialEq)]
pub struct SensorsCompensated {
    /// Per sensor: its name (`mag_3`), interference and compensated
    /// reading (nT; NaN where the model could not be applied).
    pub sensors: Vec<(String, Vec<f64>, Vec<f64>)>,
}

impl SensorsCompensated {
    /// The columns added to a table: `<name>_interf`, `<name>_comp` per
    /// sensor, then `<name>_grad = <name>_comp − <first>_comp` for every
    /// sensor after the first.
    pub fn columns(&self) -> Vec<(String, Vec<f64>)> {
        let mut out = Vec::new();
        for (name, interf, comp) in &self.sensors {
            out.push((format!("{name}_interf"), interf.clone()));
            out.push((format!("{name}_comp"), comp.clone()));
        }
        if let Some((_, _, base)) = self.sensors.first() {
            for (name, _, comp) in &self.sensors[1..] {
                let g = comp.iter().zip(base).map(|(a, b)| a - b).collect();
                out.push((format!("{name}_grad"), g));
            }
        }
        out
    }

    /// Rows where some sensor's model could not be applied.
    pub fn missing(&self) -> usize {
        let n = self.sensors.first().map_or(0, |s| s.1.len());
        (0..n)
            .filter(|&i| self.sensors.iter().any(|s| !s.1[i].is_finite()))
            .count()
    }

    /// Add the [`SensorsCompensated::columns`] to `table` (a column that
    /// exists already is bad input).
    pub fn add_to(self, table: &mut FlightTable) -> Result<()> {
        let cols = self.columns();
        crate::compensate::check_new_columns(table, cols.iter().map(|(n, _)| n.as_str()))?;
        for (name, v) in cols {
            table.add_column(&name, v)?;
        }
        Ok(())
    }
}

/// Apply a multi-sensor model.
pub trait CompensateSensors {
    /// The interference and compensated reading of every sensor of the
    /// model on `flight`.
    fn compensate(&self, flight: &Flight) -> Result<SensorsCompensated>;
}

impl SensorsCompensated {
    /// Every sensor of `model` on `flight`, its interference given by
    /// `interference(sensor's model, its columns)`: the reading minus it.
    pub(crate) fn of(
        model: &SensorsModel,
        flight: &Flight,
        mut interference: impl FnMut(usize, &SensorColumns) -> Result<Vec<f64>>,
    ) -> Result<Self> {
        let mut sensors = Vec::new();
        for (k, s) in model.sensors.iter().enumerate() {
            let cols = SensorColumns {
                mag: s.mag.clone(),
                flux: s.flux.clone(),
            };
            let interf = interference(k, &cols)?;
            crate::compensate::check_interference(flight, super::TL_OUTPUT, &interf)?;
            let mag = flight.require(&s.mag)?;
            let comp = mag.iter().zip(&interf).map(|(m, i)| m - i).collect();
            sensors.push((s.name.clone(), interf, comp));
        }
        Ok(SensorsCompensated { sensors })
    }
}

impl CompensateSensors for SensorsModel {
    fn compensate(&self, flight: &Flight) -> Result<SensorsCompensated> {
        SensorsCompensated::of(self, flight, |k, cols| {
            tl_interference(&self.sensors[k].model, flight, cols)
        })
    }
}
