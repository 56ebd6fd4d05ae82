//! The main (core) field: IGRF-14 at each position and time.
//!
//! `aeromag-core`'s [`IgrfModel`] is evaluated at the flight's start epoch
//! at every position; the secular variation over the flight is added as
//! `(t − t₀) · Ḃ`, with `Ḃ` the IGRF rate of change at the centre of the
//! flight area:
//!
//! ```text
//! B(p, t) = B_IGRF(p, t₀) + (t − t₀) [B_IGRF(p_c, t₁) − B_IGRF(p_c, t₀)] / (t₁ − t₀)
//! ```
//!
//! IGRF coefficients are linear in time between epochs, so this is exact
//! except for the spatial variation of the secular variation across the
//! area (≲ 0.2 nT/yr per 20 km, i.e. < 1e-4 nT over a flight of hours).
//! Output in nT, geodetic north-east-down.

use aeromag_core::field::igrf::IgrfModel;
use aeromag_core::frames::Geodetic;
use aeromag_core::time::Date;
use nalgebra::Vector3;

use crate::error::Result;

/// Seconds per day.
const DAY_S: f64 = 86_400.0;

/// Decimal year of `start_utc_s` seconds after 00:00 UTC of `date`.
pub fn decimal_year(date: &Date, seconds_of_day: f64) -> f64 {
    let days_in_year = if Date::new(date.year, 2, 29).is_ok() {
        366.0
    } else {
        365.0
    };
    date.decimal_year() + seconds_of_day / (DAY_S * days_in_year)
}

/// The IGRF-14 main field over one flight.
#[derive(Debug, Clone)]
pub struct MainField {
    model: IgrfModel,
    rate_nt_per_s: Vector3<f64>,
}

impl MainField {
    /// The field for a flight starting `start_utc_s` seconds after 00:00 UTC
    /// of `date`, lasting `duration_s`, over an area centred at `centre`.
    /// Errors if the dates are outside IGRF-14 (1900–2030).
    pub fn new(date: &Date, start_utc_s: f64, duration_s: f64, centre: &Geodetic) -> Result<Self> {
        let y0 = decimal_year(date, start_utc_s);
        let span = duration_s.max(3600.0);
        let y1 = decimal_year(date, start_utc_s + span);
        let model = IgrfModel::new(y0)?;
        let model1 = IgrfModel::new(y1)?;
        let b0 = model.field_geodetic(centre).ned_nt();
        let b1 = model1.field_geodetic(centre).ned_nt();
        Ok(Self {
            model,
            rate_nt_per_s: (b1 - b0) / span,
        })
    }

    /// Main field (nT, NED) at `pos`, `t_s` seconds after the start.
    pub fn field_nt(&self, pos: &Geodetic, t_s: f64) -> Vector3<f64> {
        self.model.field_geodetic(pos).ned_nt() + self.rate_nt_per_s * t_s
    }

    /// Secular variation used, nT/s (NED).
    pub fn rate_nt_per_s(&self) -> Vector3<f64> {
        self.rate_nt_per_s
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use aeromag_core::field::igrf::igrf_geodetic;

    #[test]
    fn matches_igrf_at_the_start_and_interpolates_in_time() {
        let date = Date::new(2025, 6, 1).unwrap();
        let c = Geodetic::new(56.0, 38.0, 3000.0);
        let mf = MainField::new(&date, 36_000.0, 7200.0, &c).unwrap();
        let y0 = decimal_year(&date, 36_000.0);
        let direct = igrf_geodetic(&c, y0).unwrap().ned_nt();
        assert!((mf.field_nt(&c, 0.0) - direct).norm() < 1e-9);
        let y1 = decimal_year(&date, 36_000.0 + 5400.0);
        let later = igrf_geodetic(&c, y1).unwrap().ned_nt();
        assert!((mf.field_nt(&c, 5400.0) - later).norm() < 1e-6);
        // Secular variation is tens of nT per year: ≪ 1 nT per hour.
        assert!(mf.rate_nt_per_s().norm() * 3600.0 < 0.05);
    }

    #[test]
    fn out_of_range_dates_are_errors() {
        let date = Date::new(2035, 1, 1).unwrap();
        assert!(MainField::new(&date, 0.0, 10.0, &Geodetic::new(0.0, 0.0, 0.0)).is_err());
    }
}
