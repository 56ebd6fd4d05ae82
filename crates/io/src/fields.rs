//! Fields aeromag recognises by name, with their units: the canonical
//! columns, and the fields of the SGL surveys in their HDF5 layout and
//! their Geosoft XYZ export (spec `data-formats.md`, "Real survey files").
//! Names are compared without regard to case.
//!
//! ```
//! use aeromag_io::known_field;
//! assert_eq!(known_field("UNCOMPMAG3").unwrap().unit, "nT");
//! assert_eq!(known_field("ins_lat").unwrap().unit, "rad"); // not degrees
//! assert_eq!(known_field("CUR_ACHi").unwrap().unit, "A");
//! assert!(known_field("PITOT_P").is_none());
//! ```

use serde::Serialize;

/// A recognised field: its unit and what it is.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub struct KnownField {
    /// Unit as written in reports (`nT`, `deg`, `rad`, `m/s`, `A`, `V`, `s`,
    /// `m`, `m/s²`, `deg/s`; `—` for labels and counts).
    pub unit: &'static str,
    /// What the field holds.
    pub meaning: &'static str,
}

const fn f(unit: &'static str, meaning: &'static str) -> KnownField {
    KnownField { unit, meaning }
}

/// Fields known by their whole (lower-case) name.
const EXACT: &[(&str, KnownField)] = &[
    // canonical columns (spec "Flight data tables")
    ("time", f("s", "time")),
    ("lat", f("deg", "latitude, WGS84")),
    ("lon", f("deg", "longitude, WGS84")),
    ("alt", f("m", "altitude")),
    ("vn", f("m/s", "velocity north")),
    ("ve", f("m/s", "velocity east")),
    ("vd", f("m/s", "velocity down")),
    ("roll", f("deg", "roll")),
    ("pitch", f("deg", "pitch")),
    ("yaw", f("deg", "yaw (heading, clockwise from north)")),
    ("mag", f("nT", "scalar magnetometer, uncompensated")),
    ("flux_x", f("nT", "vector magnetometer x, body frame")),
    ("flux_y", f("nT", "vector magnetometer y, body frame")),
    ("flux_z", f("nT", "vector magnetometer z, body frame")),
    ("line", f("—", "line label")),
    ("diurnal", f("nT", "base station (diurnal variation)")),
    ("igrf", f("nT", "main field (IGRF)")),
    // SGL HDF5 layout
    ("tt", f("s", "seconds past midnight UTC")),
    ("flight", f("—", "flight number")),
    ("year", f("—", "year")),
    ("doy", f("—", "day of year")),
    ("utm_x", f("m", "UTM easting")),
    ("utm_y", f("m", "UTM northing")),
    ("utm_z", f("m", "GPS ellipsoidal height")),
    ("msl", f("m", "height above mean sea level")),
    ("baro", f("m", "barometric altitude")),
    ("radar", f("m", "radar altimeter (height above ground)")),
    ("topo", f("m", "topography")),
    ("dem", f("m", "digital elevation model")),
    ("drape", f("m", "planned drape surface")),
    ("ins_lat", f("rad", "INS latitude (radians)")),
    ("ins_lon", f("rad", "INS longitude (radians)")),
    ("ins_alt", f("m", "INS altitude")),
    ("ins_vn", f("m/s", "INS velocity north")),
    ("ins_vw", f("m/s", "INS velocity west (east = −west)")),
    ("ins_vu", f("m/s", "INS velocity up (down = −up)")),
    ("ins_roll", f("deg", "INS roll")),
    ("ins_pitch", f("deg", "INS pitch")),
    ("ins_yaw", f("deg", "INS yaw (clockwise from north)")),
    ("ins_wander", f("rad", "INS wander angle")),
    ("mag_1_c", f("nT", "contractor's compensated Mag 1")),
    ("mag_1_lag", f("nT", "contractor's lag-corrected Mag 1")),
    ("mag_1_dc", f("nT", "contractor's diurnal-corrected Mag 1")),
    (
        "mag_1_igrf",
        f("nT", "contractor's IGRF-corrected Mag 1 (anomaly)"),
    ),
    ("ogs_mag", f("nT", "OGS magnetic anomaly map")),
    ("ogs_alt", f("m", "altitude of the OGS map")),
    // Geosoft XYZ export of the same surveys
    ("flt", f("—", "flight number")),
    ("utm-x", f("m", "UTM easting")),
    ("utm-y", f("m", "UTM northing")),
    ("utm-z", f("m", "GPS ellipsoidal height")),
    ("msl-z", f("m", "height above mean sea level")),
    ("long", f("deg", "longitude, WGS84")),
    ("azimuth", f("deg", "heading, clockwise from north")),
    ("compmag1", f("nT", "contractor's compensated Mag 1")),
    ("lagmag1", f("nT", "contractor's lag-corrected Mag 1")),
    ("dcmag1", f("nT", "contractor's diurnal-corrected Mag 1")),
    (
        "igrfmag1",
        f("nT", "contractor's IGRF-corrected Mag 1 (anomaly)"),
    ),
    ("ogs_hgt", f("m", "altitude of the OGS map")),
    ("ins_acc_x", f("m/s²", "INS acceleration x")),
    ("ins_acc_y", f("m/s²", "INS acceleration y")),
    ("ins_acc_z", f("m/s²", "INS acceleration z")),
    ("ins_hgt", f("m", "INS altitude")),
    ("ins_vel_n", f("m/s", "INS velocity north")),
    ("ins_vel_w", f("m/s", "INS velocity west (east = −west)")),
    ("ins_vel_v", f("m/s", "INS velocity up (down = −up)")),
    ("pitchrt", f("deg/s", "pitch rate")),
    ("rollrt", f("deg/s", "roll rate")),
    ("yawrt", f("deg/s", "yaw rate")),
];

/// The field `name` is, if aeromag knows it (see the module docs).
pub fn known_field(name: &str) -> Option<KnownField> {
    let lower = name.to_ascii_lowercase();
    let n = lower.as_str();
    if let Some((_, k)) = EXACT.iter().find(|(e, _)| *e == n) {
        return Some(*k);
    }
    let digit = |s: &str| !s.is_empty() && s.bytes().all(|b| b.is_ascii_digit());
    let axis = |s: &str| matches!(s, "x" | "y" | "z");
    let sensor = |s: &str| s.len() == 1 && s.bytes().all(|b| b.is_ascii_lowercase());
    // mag_N_uc / UNCOMPMAGN: the scalar magnetometers
    if let Some(d) = n.strip_prefix("mag_").and_then(|r| r.strip_suffix("_uc"))
        && digit(d)
    {
        return Some(f("nT", "scalar magnetometer, uncompensated"));
    }
    if n.strip_prefix("uncompmag").is_some_and(digit) {
        return Some(f("nT", "scalar magnetometer, uncompensated"));
    }
    // flux_a_x … flux_d_t / FLUXA_X … FLUXD_TOT: the vector magnetometers
    let flux = n
        .strip_prefix("flux_")
        .and_then(|r| r.split_once('_'))
        .or_else(|| n.strip_prefix("flux").and_then(|r| r.split_once('_')));
    if let Some((s, c)) = flux
        && sensor(s)
    {
        if axis(c) {
            return Some(f("nT", "vector magnetometer component, body frame"));
        }
        if c == "t" || c == "tot" {
            return Some(f("nT", "vector magnetometer total"));
        }
    }
    if n.starts_with("cur_") {
        return Some(f("A", "current of on-board equipment"));
    }
    if n.starts_with("vol_") || n.starts_with("v_") {
        return Some(f("V", "voltage of on-board equipment"));
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sgl_and_xyz_names_with_their_units() {
        for (name, unit) in [
            ("tt", "s"),
            ("TIME", "s"),
            ("mag_5_uc", "nT"),
            ("UNCOMPMAG2", "nT"),
            ("flux_d_z", "nT"),
            ("FLUXB_TOT", "nT"),
            ("ins_lon", "rad"),
            ("INS_LAT", "rad"),
            ("INS_VEL_W", "m/s"),
            ("LONG", "deg"),
            ("cur_strb", "A"),
            ("CUR_SRVO_O", "A"),
            ("vol_bat_1", "V"),
            ("V_BAT1", "V"),
            ("LINE", "—"),
        ] {
            assert_eq!(known_field(name).map(|k| k.unit), Some(unit), "{name}");
        }
        for name in ["flux_ab_x", "mag_x_uc", "uncompmag", "fluxa_w", "pitot_p"] {
            assert_eq!(known_field(name), None, "{name}");
        }
    }
}
