//! The identities of the Tolles-Lawson terms on random attitudes, fields
//! and rotation rates (property tests): `eᵀe = 1`, the induced diagonal
//! `Σ e_i B_i = |B|`, and `eᵀ·ė = 0`, i.e. the eddy diagonal
//! `Σ e_i Ḃ_i = d|B|/dt`, which vanishes while the aircraft only turns in a
//! constant field. The last two are the two collinearities that make the
//! 18-term set (`p3,i6,e9`) singular in a calibration and the 16-term set
//! (`p3,i5,e8`) the observable one.

use aeromag_compensation::tolles_lawson::{DEFAULT_BT_SCALE_NT, Design, TermSet};
use aeromag_core::frames::Attitude;
use nalgebra::Vector3;
use proptest::prelude::*;
use std::f64::consts::PI;

/// A field in NED of magnitude `f` (nT) with inclination `inc` and
/// declination `dec` (rad).
fn field_ned(f: f64, inc: f64, dec: f64) -> Vector3<f64> {
    Vector3::new(
        f * inc.cos() * dec.cos(),
        f * inc.cos() * dec.sin(),
        f * inc.sin(),
    )
}

fn attitude() -> impl Strategy<Value = (f64, f64, f64)> {
    (-0.8f64..0.8, -0.5f64..0.5, -PI..PI)
}

fn earth_field() -> impl Strategy<Value = Vector3<f64>> {
    (20_000.0f64..70_000.0, -1.5f64..1.5, -PI..PI).prop_map(|(f, inc, dec)| field_ned(f, inc, dec))
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    /// At one instant: `eᵀe = 1`, the induced diagonal sums to
    /// `|B|/bt_scale`, and with the body-frame field rate of a pure rotation
    /// at rate `ω` (`Ḃ = −ω × B`) the eddy diagonal sums to zero.
    #[test]
    fn the_row_identities_hold_at_any_attitude(
        (roll, pitch, yaw) in attitude(),
        b_ned in earth_field(),
        w in (-0.3f64..0.3, -0.3f64..0.3, -0.3f64..0.3),
    ) {
        let b = Attitude::new(roll, pitch, yaw).ned_to_body(&b_ned);
        let omega = Vector3::new(w.0, w.1, w.2);
        let db = -omega.cross(&b);
        let terms = TermSet::full18();
        let mut row = vec![0.0; terms.n_columns()];
        terms.row([b.x, b.y, b.z], [db.x, db.y, db.z], &[], &[], DEFAULT_BT_SCALE_NT, &mut row);
        let e2: f64 = row[0..3].iter().map(|v| v * v).sum();
        prop_assert!((e2 - 1.0).abs() < 1e-14, "eᵀe = {e2}");
        // i6 order: xx, xy, xz, yy, yz, zz.
        let induced = row[3] + row[6] + row[8];
        prop_assert!((induced - b.norm() / DEFAULT_BT_SCALE_NT).abs() < 1e-13);
        // e9 row-major: xx at 9, yy at 13, zz at 17.
        let eddy = row[9] + row[13] + row[17];
        let scale = db.norm() / DEFAULT_BT_SCALE_NT;
        prop_assert!(eddy.abs() <= 1e-12 * scale.max(1e-12), "eᵀḂ = {eddy}");
    }

    /// Over a manoeuvre (attitude turning at random rates in a constant
    /// field) the design columns of the 18-term set carry the two
    /// collinearities on every sample: the induced diagonal is the constant
    /// `|B|/bt_scale`, and the eddy diagonal (physical derivative) is zero up
    /// to the central difference's truncation error.
    #[test]
    fn the_full_set_is_collinear_over_a_manoeuvre(
        (roll, pitch, yaw) in attitude(),
        rates in (-0.2f64..0.2, -0.2f64..0.2, -0.2f64..0.2),
        b_ned in earth_field(),
    ) {
        let n = 200;
        let dt = 0.1;
        let time: Vec<f64> = (0..n).map(|k| k as f64 * dt).collect();
        let mut flux = [vec![0.0; n], vec![0.0; n], vec![0.0; n]];
        for (k, t) in time.iter().enumerate() {
            let a = Attitude::new(roll + rates.0 * t, pitch + rates.1 * t, yaw + rates.2 * t);
            let b = a.ned_to_body(&b_ned);
            for j in 0..3 {
                flux[j][k] = b[j];
            }
        }
        let cols = Design::new(TermSet::full18()).columns(&time, [&flux[0], &flux[1], &flux[2]]);
        let f = b_ned.norm() / DEFAULT_BT_SCALE_NT;
        // The largest body-frame rate: |Ḃ| ≤ |ω||B|, and the central
        // difference errs by ~|ω|²|B| dt² relative to it.
        let w = (rates.0.powi(2) + rates.1.powi(2) + rates.2.powi(2)).sqrt() * 2.0;
        for k in 1..n - 1 {
            prop_assert!((cols[3][k] + cols[6][k] + cols[8][k] - f).abs() < 1e-12);
            let eddy = cols[9][k] + cols[13][k] + cols[17][k];
            prop_assert!(eddy.abs() <= f * w.powi(3) * dt * dt + 1e-12, "sample {k}: {eddy}");
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// The column-wise design (what the fit filters) and the block-wise
    /// interference (what `compensate` subtracts) are the row-wise design
    /// bit for bit, with lagged eddy columns (whose lags run across the
    /// interference's blocks), extra regressors (one lagged) and in both
    /// derivative conventions.
    #[test]
    fn columns_and_interference_are_the_rows_bit_for_bit(
        (roll, pitch, yaw) in attitude(),
        rates in (-0.2f64..0.2, -0.2f64..0.2, -0.2f64..0.2),
        b_ned in earth_field(),
        n in 3usize..9000,
        magnav in any::<bool>(),
        coef_seed in 0u64..1000,
    ) {
        use aeromag_compensation::tolles_lawson::{Convention, ExtraTerm, design::Channels, eddy_lag::{FirstOrderLag, LagBank}, terms::derivative};
        let time: Vec<f64> = (0..n).map(|k| k as f64 * 0.1 + 0.003 * (k % 7) as f64).collect();
        let mut flux = [vec![0.0; n], vec![0.0; n], vec![0.0; n]];
        for (k, t) in time.iter().enumerate() {
            let a = Attitude::new(roll + rates.0 * t.sin(), pitch + rates.1 * t, yaw + rates.2 * t);
            let b = a.ned_to_body(&b_ned);
            for j in 0..3 {
                flux[j][k] = b[j];
            }
        }
        let strobe: Vec<f64> = (0..n).map(|k| 4.0 * ((k / 11) % 2) as f64 + 0.5).collect();
        let ramp: Vec<f64> = (0..n).map(|k| ((k + coef_seed as usize) % 97) as f64 * 0.03).collect();
        let chs = [&strobe[..], &ramp[..]];
        let terms = TermSet::parse("p3,i6,e9,bias").unwrap().with_eddy_lags(&[0.3, 1.1]).unwrap()
            .with_extras(&[ExtraTerm::new("strobe"), ExtraTerm::lagged("ramp", 0.6)]).unwrap();
        let mut design = Design::new(terms.clone());
        design.convention = if magnav { Convention::MagNav } else { Convention::Physical };
        let f = [&flux[0][..], &flux[1][..], &flux[2][..]];
        let cols = design.columns_with(&time, f, Channels::new(&chs));
        let coef: Vec<f64> = (0..terms.n_columns()).map(|k| ((k as u64 * 7919 + coef_seed) % 201) as f64 - 100.0).collect();
        let interference = design.interference_with(&coef, &time, f, Channels::new(&chs));
        let db = [0, 1, 2].map(|k| derivative(&flux[k], &time, design.convention));
        let mut lags = LagBank::new(terms.eddy_lags_s());
        let mut ramp_lag = FirstOrderLag::new(0.6);
        let mut row = vec![0.0; terms.n_columns()];
        for k in 0..n {
            let d = [db[0][k], db[1][k], db[2][k]];
            let lagged = lags.step(time[k], d);
            let extra = [[strobe[k], f64::NAN], [ramp[k], ramp_lag.step(time[k], ramp[k])]];
            terms.row([flux[0][k], flux[1][k], flux[2][k]], d, lagged, &extra, DEFAULT_BT_SCALE_NT, &mut row);
            for (c, v) in cols.iter().zip(&row) {
                prop_assert_eq!(c[k].to_bits(), v.to_bits());
            }
            let dot: f64 = row.iter().zip(&coef).map(|(a, c)| a * c).sum();
            prop_assert_eq!(interference[k].to_bits(), dot.to_bits());
        }
    }
}
