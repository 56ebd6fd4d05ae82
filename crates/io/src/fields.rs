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
//! assert_eq!(known_field("PITOT_P").unwrap().unit, "kPa");
//! assert_eq!(known_field("rotor_phase").unwrap().unit, "deg");
//! assert!(known_field("MY_CHANNEL").is_none());
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
    // the rotor and pod models' channels (an HDF5 `units` attribute of
    // `rad` on them is refused, not read as degrees)
    ("rotor_phase", f("deg", "rotor phase of blade 0, [0, 360)")),
    (
        "cable_inclination",
        f("deg", "tow cable inclination below the horizontal"),
    ),
    (
        "cable_azimuth",
        f("deg", "tow cable azimuth from magnetic north, [0, 360)"),
    ),
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
    (
        "long_acc",
        f("g", "longitudinal (forward) acceleration, avionics"),
    ),
    (
        "lat_acc",
        f("g", "lateral (starboard) acceleration, avionics"),
    ),
    (
        "norm_acc",
        f(
            "g",
            "normal (vertical) acceleration, avionics, without gravity",
        ),
    ),
    ("true_as", f("m/s", "true airspeed")),
    ("tot_p", f("kPa", "total pressure")),
    // avionics, SGL HDF5 names (MagNav readmes/sgl_2020_fields_readme.txt)
    ("pitch_rate", f("deg/s", "pitch rate")),
    ("roll_rate", f("deg/s", "roll rate")),
    ("yaw_rate", f("deg/s", "yaw rate")),
    (
        "lgtl_acc",
        f("g", "longitudinal (forward) acceleration, avionics"),
    ),
    (
        "ltrl_acc",
        f("g", "lateral (starboard) acceleration, avionics"),
    ),
    (
        "nrml_acc",
        f(
            "g",
            "normal (vertical) acceleration, avionics, without gravity",
        ),
    ),
    ("tas", f("m/s", "true airspeed")),
    ("pitot_p", f("kPa", "pitot pressure")),
    ("static_p", f("kPa", "static pressure")),
    ("total_p", f("kPa", "total pressure")),
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
    // mag_N: further scalar magnetometers of a simulated flight
    if n.strip_prefix("mag_").is_some_and(digit) {
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
            ("PITOT_P", "kPa"),
            ("NORM_ACC", "g"),
            ("TRUE_AS", "m/s"),
            ("mag_3", "nT"),
        ] {
            assert_eq!(known_field(name).map(|k| k.unit), Some(unit), "{name}");
        }
        for name in ["flux_ab_x", "mag_x_uc", "uncompmag", "fluxa_w", "pitot"] {
            assert_eq!(known_field(name), None, "{name}");
        }
    }

    /// Every field of the SGL 2020 HDF5 layout (MagNav's
    /// `readmes/sgl_2020_fields_readme.txt`) and every column of the
    /// contractor's XYZ export (the header of `Flt1003_sample.xyz`) is known
    /// with a unit.
    #[test]
    fn every_sgl_field_and_xyz_column_has_a_unit() {
        let hdf5 = [
            "line",
            "flight",
            "year",
            "doy",
            "tt",
            "utm_x",
            "utm_y",
            "utm_z",
            "msl",
            "lat",
            "lon",
            "baro",
            "radar",
            "topo",
            "dem",
            "drape",
            "ins_pitch",
            "ins_roll",
            "ins_yaw",
            "diurnal",
            "mag_1_c",
            "mag_1_lag",
            "mag_1_dc",
            "mag_1_igrf",
            "mag_1_uc",
            "mag_2_uc",
            "mag_3_uc",
            "mag_4_uc",
            "mag_5_uc",
            "mag_6_uc",
            "flux_a_x",
            "flux_a_y",
            "flux_a_z",
            "flux_a_t",
            "flux_b_x",
            "flux_b_y",
            "flux_b_z",
            "flux_b_t",
            "flux_c_x",
            "flux_c_y",
            "flux_c_z",
            "flux_c_t",
            "flux_d_x",
            "flux_d_y",
            "flux_d_z",
            "flux_d_t",
            "ogs_mag",
            "ogs_alt",
            "ins_acc_x",
            "ins_acc_y",
            "ins_acc_z",
            "ins_wander",
            "ins_lat",
            "ins_lon",
            "ins_alt",
            "ins_vn",
            "ins_vw",
            "ins_vu",
            "pitch_rate",
            "roll_rate",
            "yaw_rate",
            "lgtl_acc",
            "ltrl_acc",
            "nrml_acc",
            "tas",
            "pitot_p",
            "static_p",
            "total_p",
            "cur_com_1",
            "cur_ac_hi",
            "cur_ac_lo",
            "cur_tank",
            "cur_flap",
            "cur_strb",
            "cur_srvo_o",
            "cur_srvo_m",
            "cur_srvo_i",
            "cur_heat",
            "cur_acpwr",
            "cur_outpwr",
            "cur_bat_1",
            "cur_bat_2",
            "vol_acpwr",
            "vol_outpwr",
            "vol_bat_1",
            "vol_bat_2",
            "vol_res_p",
            "vol_res_n",
            "vol_back_p",
            "vol_back_n",
            "vol_gyro_1",
            "vol_gyro_2",
            "vol_acc_p",
            "vol_acc_n",
            "vol_block",
            "vol_back",
            "vol_srvo",
            "vol_cabt",
            "vol_fan",
        ];
        let xyz = [
            "LINE",
            "FLT",
            "YEAR",
            "DOY",
            "TIME",
            "UTM-X",
            "UTM-Y",
            "UTM-Z",
            "MSL-Z",
            "LAT",
            "LONG",
            "BARO",
            "RADAR",
            "TOPO",
            "DEM",
            "DRAPE",
            "PITCH",
            "ROLL",
            "AZIMUTH",
            "DIURNAL",
            "COMPMAG1",
            "LAGMAG1",
            "DCMAG1",
            "IGRFMAG1",
            "UNCOMPMAG1",
            "UNCOMPMAG2",
            "UNCOMPMAG3",
            "UNCOMPMAG4",
            "UNCOMPMAG5",
            "FLUXA_X",
            "FLUXA_Y",
            "FLUXA_Z",
            "FLUXA_TOT",
            "FLUXB_X",
            "FLUXB_Y",
            "FLUXB_Z",
            "FLUXB_TOT",
            "FLUXC_X",
            "FLUXC_Y",
            "FLUXC_Z",
            "FLUXC_TOT",
            "FLUXD_X",
            "FLUXD_Y",
            "FLUXD_Z",
            "FLUXD_TOT",
            "OGS_MAG",
            "OGS_HGT",
            "INS_ACC_X",
            "INS_ACC_Y",
            "INS_ACC_Z",
            "INS_WANDER",
            "INS_LAT",
            "INS_LON",
            "INS_HGT",
            "INS_VEL_N",
            "INS_VEL_W",
            "INS_VEL_V",
            "PITCHRT",
            "ROLLRT",
            "YAWRT",
            "LONG_ACC",
            "LAT_ACC",
            "NORM_ACC",
            "TRUE_AS",
            "PITOT_P",
            "STATIC_P",
            "TOT_P",
            "CUR_COM1",
            "CUR_ACHi",
            "CUR_ACLo",
            "CUR_TANK",
            "CUR_FLAP",
            "CUR_STRB",
            "CUR_SRVO_O",
            "CUR_SRVO_M",
            "CUR_SRVO_I",
            "CUR_IHTR",
            "CUR_ACPWR",
            "CUR_OUTPWR",
            "CUR_BAT1",
            "CUR_BAT2",
            "V_ACPWR",
            "V_OUTPWR",
            "V_BAT1",
            "V_BAT2",
            "V_RESp",
            "V_RESn",
            "V_BACKp",
            "V_BACKn",
            "V_GYRO1",
            "V_GYRO2",
            "V_ACCp",
            "V_ACCn",
            "V_BLOCK",
            "V_BACK",
            "V_SERVO",
            "V_CABT",
            "V_FAN",
        ];
        for name in hdf5.iter().chain(&xyz) {
            assert!(known_field(name).is_some(), "{name}");
        }
    }
}
