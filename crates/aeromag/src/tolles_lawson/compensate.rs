//! A Tolles-Lawson model applied to a flight.

use crate::compensate::{Compensator, OutputColumns};
use crate::error::Result;
use crate::flight::{Flight, SegmentRule, TlInputs};
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
    /// not matter), NaN elsewhere. Reads `time`, `flux_x/y/z` and `mag`.
    fn interference_observed(
        &self,
        flight: &Flight,
        _observer: &mut dyn Observer,
    ) -> Result<Vec<f64>> {
        let cols = TlInputs::of(flight)?;
        let mut out = vec![f64::NAN; flight.n_rows()];
        let segs = cols.segments(&SegmentRule::ignoring_lines());
        debug_assert!(segs.short.is_empty());
        let coef = self.coef();
        for r in segs.kept {
            let f = [
                &cols.flux[0][r.clone()],
                &cols.flux[1][r.clone()],
                &cols.flux[2][r.clone()],
            ];
            let v = self.design.interference(&coef, &cols.time[r.clone()], f);
            out[r].copy_from_slice(&v);
        }
        Ok(out)
    }
}
