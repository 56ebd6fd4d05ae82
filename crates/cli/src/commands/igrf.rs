//! `aeromag igrf`: the IGRF-14 main field at a point.

use crate::exit::bad_input;
use aeromag_core::error::shown;
use aeromag_core::field::MAX_LON_DEG;
use aeromag_core::field::igrf::igrf_geodetic;
use aeromag_core::frames::Geodetic;
use aeromag_core::time::Date;

/// Print the IGRF-14 main field at a WGS84 geodetic point and date.
///
/// Prints X (north), Y (east), Z (down) and the total intensity F in nT, the
/// declination D and inclination I in degrees.
///
/// Example: `aeromag igrf --lat 55.75 --lon 37.62 --alt 200 --date 2025-06-01`
#[derive(Debug, clap::Args)]
#[command(verbatim_doc_comment)]
pub struct Args {
    /// Geodetic latitude, degrees (−90 … 90, north positive).
    #[arg(long, allow_negative_numbers = true)]
    lat: f64,
    /// Longitude, degrees (east positive, −360 … 360).
    #[arg(long, allow_negative_numbers = true)]
    lon: f64,
    /// Height above the WGS84 ellipsoid, metres.
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    alt: f64,
    /// Date YYYY-MM-DD (IGRF-14 is defined 1900–2030).
    #[arg(long)]
    date: String,
    /// Print a JSON object with keys x, y, z, f, declination, inclination.
    #[arg(long)]
    json: bool,
}

pub fn run(a: Args) -> anyhow::Result<()> {
    if !a.lat.is_finite() || a.lat.abs() > 90.0 {
        return Err(bad_input!(
            "--lat {} is not a latitude in −90…90 degrees",
            shown(a.lat)
        ));
    }
    if !(-MAX_LON_DEG..=MAX_LON_DEG).contains(&a.lon) {
        return Err(bad_input!(
            "--lon {} is not a longitude in −360…360 degrees",
            shown(a.lon)
        ));
    }
    if !a.alt.is_finite() || !(-1.0e4..=1.0e6).contains(&a.alt) {
        return Err(bad_input!(
            "--alt {} m is outside −10 km … 1000 km",
            shown(a.alt)
        ));
    }
    let date = Date::parse(&a.date)?;
    let f = igrf_geodetic(&Geodetic::new(a.lat, a.lon, a.alt), date.decimal_year())?;
    if a.json {
        let v = serde_json::json!({
            "x": f.x_nt, "y": f.y_nt, "z": f.z_nt, "f": f.f_nt(),
            "declination": f.declination_deg(), "inclination": f.inclination_deg(),
        });
        println!("{}", serde_json::to_string_pretty(&v)?);
    } else {
        println!(
            "IGRF-14 at lat {:.5}°, lon {:.5}°, alt {:.1} m, {}",
            a.lat, a.lon, a.alt, a.date
        );
        println!("  X (north) {:>12.1} nT", f.x_nt);
        println!("  Y (east)  {:>12.1} nT", f.y_nt);
        println!("  Z (down)  {:>12.1} nT", f.z_nt);
        println!("  F         {:>12.1} nT", f.f_nt());
        println!("  D         {:>12.3} °", f.declination_deg());
        println!("  I         {:>12.3} °", f.inclination_deg());
    }
    Ok(())
}
