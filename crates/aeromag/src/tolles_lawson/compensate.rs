//! A Tolles-Lawson model applied to a flight.

use crate::compensate::{Compensator, OutputColumns};
use crate::error::Result;
use crate::flight::{Flight, SegmentRule, SensorColumns, TlInputs};
use crate::observer::Observer;
use aeromag_compensation::model_file::TlModel;

/// The columns `compensate` adds: `mag_interf`, `mag_comp`, `comp_flag`.
pub const TL_OUTPUT: OutputColumns = OutputColumns {
    interference: "mag_interf",
    flag: "comp_flag",
    why_missing: "missing values",
};

impl Compensator for TlModel {
    fn output(&self) -> OutputColumns {
        TL_OUTPUT
    }

    /// `A c` on every stretch without gaps or missing values (the
    /// derivatives of the eddy terms must not cross them; line changes do
    /// not matter), NaN elsewhere. Reads `time`, `flux_x/y/z`, `mag` and
    /// the channels of the extra regressors.
    fn interference_observed(
        &self,
        flight: &Flight,
        _observer: &mut dyn Observer,
    ) -> Result<Vec<f64>> {
        tl_interference(self, flight, &SensorColumns::default())
    }
}

/// The interference `A c` (nT) of `model` at the sensor `sensor` of
/// `flight`, NaN on rows it cannot be applied to (see
/// [`Compensator::interference_observed`]).
pub(super) fn tl_interference(
    model: &TlModel,
    flight: &Flight,
    sensor: &SensorColumns,
) -> Result<Vec<f64>> {
    let cols =
        TlInputs::of_sensor(flight, sensor)?.with_extras(flight, model.design.terms.extras())?;
    let whole = cols.whole();
    let mut out = vec![f64::NAN; flight.n_rows()];
    let segs = cols.segments(&SegmentRule::ignoring_lines());
    debug_assert!(segs.short.is_empty());
    let coef = model.coef();
    for r in segs.kept {
        let s = whole.slice(r.clone());
        let v = model
            .design
            .interference_with(&coef, s.time, s.flux, s.channels);
        out[r].copy_from_slice(&v);
    }
    Ok(out)
}

/// A model's interference split by term group (nT per row, NaN where the
/// model cannot be applied): each part is the model with the other groups'
/// coefficients set to zero (for the exact magnitude, the part alone rather
/// than its share of the magnitude). The `bias` term is in none of them.
#[derive(Debug, Clone, PartialEq)]
pub struct InterferenceParts {
    /// Permanent magnetization (`p_`).
    pub permanent: Vec<f64>,
    /// Induced magnetization (`i_`).
    pub induced: Vec<f64>,
    /// Eddy currents (`e_`, and the lagged `l1_`, `l2_`).
    pub eddy: Vec<f64>,
    /// Extra regressors: the currents (`<channel>:e_x`, …).
    pub currents: Vec<f64>,
}

impl InterferenceParts {
    /// The parts of `model` at the sensor `sensor` of `flight`.
    pub fn of(model: &TlModel, flight: &Flight, sensor: &SensorColumns) -> Result<Self> {
        let part = |keep: &dyn Fn(&str) -> bool| {
            let mut m = model.clone();
            for c in &mut m.coefficients {
                if !keep(&c.name) {
                    c.value = 0.0;
                }
            }
            tl_interference(&m, flight, sensor)
        };
        Ok(Self {
            permanent: part(&|n| n.starts_with("p_"))?,
            induced: part(&|n| n.starts_with("i_"))?,
            eddy: part(&|n| n.starts_with("e_") || n.starts_with('l'))?,
            currents: part(&|n| n.contains(':'))?,
        })
    }
}
