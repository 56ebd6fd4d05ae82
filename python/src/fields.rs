//! The IGRF-14 main field, vectorised over points (`aeromag igrf` at one
//! point).

use crate::errors::{IntoPy, bad_argument};
use aeromag::core::field::igrf::IgrfModel;
use aeromag::core::frames::Geodetic;
use aeromag::core::time::Date;
use numpy::{PyArray1, PyReadonlyArray1};
use pyo3::prelude::*;

/// The decimal year of a date `YYYY-MM-DD` (2025-07-02 → 2025.5).
#[pyfunction]
pub fn decimal_year(date: &str) -> PyResult<f64> {
    Ok(Date::parse(date).py_err()?.decimal_year())
}

/// North, east and down components of the IGRF-14 main field (nT) at
/// geodetic points: latitude and longitude in degrees, altitude above the
/// WGS84 ellipsoid in m, time as decimal years; all four arrays of one
/// length (the Python layer broadcasts). The GIL is released.
#[pyfunction]
#[allow(clippy::type_complexity)]
pub fn igrf<'py>(
    py: Python<'py>,
    lat_deg: PyReadonlyArray1<'py, f64>,
    lon_deg: PyReadonlyArray1<'py, f64>,
    alt_m: PyReadonlyArray1<'py, f64>,
    decimal_year: PyReadonlyArray1<'py, f64>,
) -> PyResult<(
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray1<f64>>,
)> {
    let (lat, lon, alt, year) = (
        lat_deg.as_slice()?,
        lon_deg.as_slice()?,
        alt_m.as_slice()?,
        decimal_year.as_slice()?,
    );
    let n = lat.len();
    if [lon.len(), alt.len(), year.len()].iter().any(|&l| l != n) {
        return Err(bad_argument("lat, lon, alt and time must have one length"));
    }
    for (i, ((&la, &lo), &al)) in lat.iter().zip(lon).zip(alt).enumerate() {
        let lon_ok = lo.abs() <= aeromag::core::field::MAX_LON_DEG;
        if la.is_nan() || la.abs() > 90.0 || !lon_ok || !(-1.0e4..=1.0e6).contains(&al) {
            return Err(bad_argument(format!(
                "point {i}: lat {la}° (−90…90), lon {lo}° (−360…360), alt {al} m (−10 km … 1000 km)"
            )));
        }
    }
    let out = py.detach(|| -> aeromag::Result<[Vec<f64>; 3]> {
        let mut out = [vec![0.0; n], vec![0.0; n], vec![0.0; n]];
        let mut model: Option<IgrfModel> = None;
        for i in 0..n {
            // One model per run of equal times (a flight's date).
            if model.as_ref().is_none_or(|m| m.decimal_year() != year[i]) {
                model = Some(IgrfModel::new(year[i])?);
            }
            let f = model
                .as_ref()
                .expect("set above")
                .field_geodetic(&Geodetic::new(lat[i], lon[i], alt[i]));
            out[0][i] = f.x_nt;
            out[1][i] = f.y_nt;
            out[2][i] = f.z_nt;
        }
        Ok(out)
    });
    let [x, y, z] = out.py_err()?;
    Ok((
        PyArray1::from_vec(py, x),
        PyArray1::from_vec(py, y),
        PyArray1::from_vec(py, z),
    ))
}
