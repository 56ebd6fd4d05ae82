//! Canonical column names and the mapping of file columns onto them.
//!
//! Every command of aeromag works on the canonical names of
//! `spec/data-formats.md` ("Flight data tables"):
//!
//! | column | unit | meaning |
//! |---|---|---|
//! | `time` | s | strictly increasing |
//! | `lat`, `lon` | deg | WGS84 |
//! | `alt` | m | altitude |
//! | `vn`, `ve`, `vd` | m/s | NED velocity |
//! | `roll`, `pitch`, `yaw` | deg | attitude, Z-Y-X Euler angles |
//! | `mag` | nT | scalar magnetometer, uncompensated |
//! | `flux_x`, `flux_y`, `flux_z` | nT | vector magnetometer, body frame |
//! | `line` | — | line label |
//! | `diurnal`, `igrf` | nT | optional |
//!
//! Columns named `true_*` (the simulator's known truth, e.g. `true_anomaly`)
//! pass through and are always numeric.
//!
//! A file may call its columns differently. A [`ColumnMap`], parsed from the
//! command-line text `--columns mag=mag_1_uc,flux_x=flux_a_x`, says which file
//! column plays which canonical role. Rules (checked by [`ColumnMap::parse`]):
//!
//! - entries are `canonical=file_column`, separated by commas; spaces around
//!   names are ignored; an empty text is an empty map;
//! - the left side must be a canonical name or a `true_*` name (anything else
//!   is rejected with a "did you mean" suggestion: a typo such as `flux_X`
//!   would otherwise silently do nothing);
//! - a canonical name may appear once, and a file column may be mapped once.
//!
//! Mapping does not rename anything: the file column keeps its name (and is
//! written back under it); the canonical name becomes an alias that
//! [`FlightTable::column`](crate::FlightTable::column) resolves. An explicit
//! mapping wins over a file column that happens to have the canonical name.
//!
//! # Names are matched without regard to case; the MagNav/SGL preset
//!
//! A header column that differs from a canonical name only in case
//! (`TIME`, `LAT`, `LINE`) plays that role. Files of the SGL (Signal
//! Geophysics Ltd.) surveys that MagNav.jl uses name their fields
//! differently, in the HDF5 layout (`tt`, `mag_1_uc`, `flux_a_x`, …) and in
//! the contractor's Geosoft XYZ export (`TIME`, `LONG`, `UNCOMPMAG1`,
//! `FLUXA_X`, `AZIMUTH`, …; spec `data-formats.md`, "Real survey files").
//! When [`ReadOptions::magnav_preset`](crate::ReadOptions) is on (default)
//! and a canonical column is neither in the file nor mapped by the user, the
//! first present candidate of [`MAGNAV_PRESET`] (compared without regard to
//! case) is used, and the table records it (origin
//! [`MapOrigin::MagNavPreset`]) so the command line can report what was
//! mapped. The flux triplet is taken from the first vector magnetometer (A,
//! B, C, D; `flux_a_x` or `FLUXA_X`) that has all three components.
//!
//! Any other SGL field is found in either naming without a mapping:
//! [`FlightTable::resolve`](crate::FlightTable::resolve) falls back on
//! [`sensor_names`] (`mag_1_uc` ↔ `UNCOMPMAG1`, `cur_com_1` ↔ `CUR_COM1`,
//! `flux_b_x` ↔ `FLUXB_X`), so the columns a model, `--extra` or
//! `--reference-sensor` name apply to a flight of either naming, and a
//! model keeps the MagNav name ([`magnav_name`]).
//!
//! Fields in another unit are **not** mapped, because an alias cannot
//! convert: `ins_lat`/`ins_lon` (`INS_LAT`/`INS_LON`) are radians in the
//! SGL layout (degrees in MagNav's XYZ0 layout; [`crate::derive`] tells
//! them apart by their values), and
//! `ins_vw`/`ins_vu` (`INS_VEL_W`/`INS_VEL_V`) point west and up. They are
//! recognised with their units ([`known_field`](crate::known_field)), and
//! mapping one of them onto a degree or NED column by hand is caught by the
//! unit checks ([`check_units`](crate::check_units)).

use serde::Serialize;

use crate::error::{IoError, Result};

/// The canonical column names of `spec/data-formats.md`, in the spec's order.
pub const CANONICAL_COLUMNS: [&str; 17] = [
    "time", "lat", "lon", "alt", "vn", "ve", "vd", "roll", "pitch", "yaw", "mag", "flux_x",
    "flux_y", "flux_z", "line", "diurnal", "igrf",
];

/// Magnetic-induction columns (nT): checked for tesla-like values by
/// [`check_units`](crate::check_units).
pub const MAGNETIC_COLUMNS: [&str; 6] = ["mag", "flux_x", "flux_y", "flux_z", "diurnal", "igrf"];

/// MagNav/SGL preset: canonical name → candidate file columns (SGL HDF5
/// names, then the Geosoft XYZ export's), first present wins, compared
/// without regard to case. Every candidate is in the canonical column's
/// unit. The flux components are handled as a triplet (see the module docs).
pub const MAGNAV_PRESET: [(&str, &[&str]); 13] = [
    ("time", &["tt"]),
    ("lat", &[]),
    ("lon", &["long"]),
    ("alt", &["utm_z", "utm-z", "ins_alt", "ins_hgt"]),
    ("vn", &["ins_vn", "ins_vel_n"]),
    ("ve", &["ins_ve"]),
    ("vd", &["ins_vd"]),
    ("roll", &["ins_roll"]),
    ("pitch", &["ins_pitch"]),
    ("yaw", &["ins_yaw", "azimuth"]),
    (
        "mag",
        &[
            "mag_1_uc",
            "mag_2_uc",
            "mag_3_uc",
            "mag_4_uc",
            "mag_5_uc",
            "uncompmag1",
            "uncompmag2",
            "uncompmag3",
            "uncompmag4",
            "uncompmag5",
        ],
    ),
    ("diurnal", &[]),
    ("igrf", &[]),
];

/// Vector magnetometer prefixes, in order of preference: SGL HDF5
/// (`flux_a_x`, …) and XYZ export (`FLUXA_X`, …).
const MAGNAV_FLUX_PREFIXES: [&str; 8] = [
    "flux_a", "flux_b", "flux_c", "flux_d", "fluxa", "fluxb", "fluxc", "fluxd",
];

/// True for the canonical names of [`CANONICAL_COLUMNS`].
pub fn is_canonical(name: &str) -> bool {
    CANONICAL_COLUMNS.contains(&name)
}

/// True for simulator truth columns: `true_` followed by at least one character.
pub fn is_truth_column(name: &str) -> bool {
    name.len() > "true_".len() && name.starts_with("true_")
}

/// The compensation's own columns that a file of another processing may
/// hold under other names, mapped for `report` to score them
/// (`--columns mag_comp=COMPMAG1`: SGL's compensated reading).
pub const RESULT_COLUMNS: [&str; 2] = ["mag_comp", "mag_interf"];

/// True when text in the column (by its canonical role) is an error rather
/// than a pass-through text column: every canonical column except `line`
/// (which the spec calls a label and may be text such as `L1010`), and every
/// `true_*` column.
pub(crate) fn must_be_numeric(role: &str) -> bool {
    (is_canonical(role) && role != "line")
        || is_truth_column(role)
        || RESULT_COLUMNS.contains(&role)
}

/// Where a canonical alias came from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum MapOrigin {
    /// The user's `--columns` map.
    User,
    /// The built-in MagNav/SGL preset ([`MAGNAV_PRESET`]).
    MagNavPreset,
    /// The sensor chosen with `--mag` or `--vector` ([`Sensors`]).
    Selected,
}

/// One resolved alias: the canonical name `canonical` reads the file column `file_column`.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, serde::Deserialize)]
pub struct MappedColumn {
    /// Canonical (or `true_*`) name.
    pub canonical: String,
    /// Column name in the file.
    pub file_column: String,
    /// Who asked for it.
    pub origin: MapOrigin,
}

/// A user's mapping of canonical names onto file column names
/// (`--columns mag=mag_1_uc,flux_x=flux_a_x`). See the module docs for the rules.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct ColumnMap {
    pairs: Vec<(String, String)>,
}

impl ColumnMap {
    /// An empty map.
    pub fn new() -> Self {
        Self::default()
    }

    /// Parses `canonical=file_column,...`. Errors ([`IoError::ColumnMap`]) on
    /// an entry without exactly one `=`, an empty name, an unknown canonical
    /// name, or a name used twice.
    pub fn parse(text: &str) -> Result<Self> {
        Self::parse_for(text, None)
    }

    /// [`ColumnMap::parse`] for a reader of the fields `fields` alone: a
    /// canonical name it does not read is an error naming those it does
    /// (`--columns mag=b1_x` to `aeromag dipole locate`, which reads no
    /// `mag`, was taken and changed nothing, without a word).
    pub fn parse_within(text: &str, fields: &[String]) -> Result<Self> {
        Self::parse_for(text, Some(fields))
    }

    fn parse_for(text: &str, fields: Option<&[String]>) -> Result<Self> {
        let mut map = ColumnMap::new();
        if text.trim().is_empty() {
            return Ok(map);
        }
        let err = |reason: String| IoError::ColumnMap {
            text: text.to_string(),
            reason,
        };
        for (k, entry) in text.split(',').enumerate() {
            let entry = entry.trim();
            if entry.is_empty() {
                return Err(err(format!(
                    "entry {} is empty (two commas in a row, or a trailing comma?)",
                    k + 1
                )));
            }
            let mut parts = entry.split('=');
            let (Some(canonical), Some(file_column), None) =
                (parts.next(), parts.next(), parts.next())
            else {
                return Err(err(format!(
                    "entry '{entry}' must have the form canonical=file_column"
                )));
            };
            if let Some(fields) = fields
                && !fields.iter().any(|f| f == canonical.trim())
            {
                let read: Vec<&str> = fields
                    .iter()
                    .map(String::as_str)
                    .filter(|f| is_canonical(f))
                    .collect();
                return Err(err(format!(
                    "'{}' is not a column this command reads; it maps: {}",
                    canonical.trim(),
                    read.join(", ")
                )));
            }
            map.insert(canonical.trim(), file_column.trim())
                .map_err(|e| match e {
                    IoError::ColumnMap { reason, .. } => err(reason),
                    other => other,
                })?;
        }
        Ok(map)
    }

    /// Adds one mapping with the same checks as [`ColumnMap::parse`].
    pub fn insert(&mut self, canonical: &str, file_column: &str) -> Result<()> {
        let err = |reason: String| IoError::ColumnMap {
            text: format!("{canonical}={file_column}"),
            reason,
        };
        if canonical.is_empty() || file_column.is_empty() {
            return Err(err("both sides of '=' need a name".into()));
        }
        if !is_canonical(canonical)
            && !is_truth_column(canonical)
            && !RESULT_COLUMNS.contains(&canonical)
        {
            let hint = closest_canonical(canonical)
                .map(|c| format!("did you mean '{c}'? "))
                .unwrap_or_default();
            // An SGL field needs no mapping: it is found in either naming.
            let sgl = if closest_canonical(canonical)
                .is_none_or(|c| !c.eq_ignore_ascii_case(canonical))
                && sensor_names(canonical).len() > 1
            {
                format!(
                    "'{canonical}' needs no mapping: SGL fields are found under their MagNav or XYZ export names ({}) without one; ",
                    sensor_names(canonical).join(" = ")
                )
            } else {
                String::new()
            };
            return Err(err(format!(
                "'{canonical}' is not a canonical column name; {sgl}{hint}known names: {}, {}, or true_*",
                CANONICAL_COLUMNS.join(", "),
                RESULT_COLUMNS.join(", ")
            )));
        }
        if self.get(canonical).is_some() {
            return Err(err(format!("'{canonical}' is mapped twice")));
        }
        if let Some((c, _)) = self.pairs.iter().find(|(_, f)| f == file_column) {
            return Err(err(format!(
                "file column '{file_column}' is already mapped to '{c}'"
            )));
        }
        self.pairs
            .push((canonical.to_string(), file_column.to_string()));
        Ok(())
    }

    /// The file column mapped to `canonical`, if any.
    pub fn get(&self, canonical: &str) -> Option<&str> {
        self.pairs
            .iter()
            .find(|(c, _)| c == canonical)
            .map(|(_, f)| f.as_str())
    }

    /// `(canonical, file_column)` pairs in the order given.
    pub fn pairs(&self) -> impl Iterator<Item = (&str, &str)> {
        self.pairs.iter().map(|(c, f)| (c.as_str(), f.as_str()))
    }

    /// True when nothing is mapped.
    pub fn is_empty(&self) -> bool {
        self.pairs.is_empty()
    }
}

impl std::str::FromStr for ColumnMap {
    type Err = IoError;
    fn from_str(s: &str) -> Result<Self> {
        ColumnMap::parse(s)
    }
}

/// The user's and the sensors' mappings `out` play measured roles only: a
/// `true_…` column mapped onto a measured role (`--columns mag=true_external`
/// was fitted; estimators never read truth), or a canonical column mapped
/// onto another role while it keeps its own (`--columns flux_x=flux_y`:
/// `flux_y` read as both) is bad input. Swapping two columns
/// (`flux_x=flux_y,flux_y=flux_x`) is a mapping of each.
fn check_roles(file: &str, map: &ColumnMap, out: &[MappedColumn]) -> Result<()> {
    let err = |m: &MappedColumn, reason: String| IoError::MappedColumnRole {
        file: file.to_string(),
        canonical: m.canonical.clone(),
        file_column: m.file_column.clone(),
        reason,
    };
    for m in out {
        if is_truth_column(&m.file_column) && !is_truth_column(&m.canonical) {
            return Err(err(
                m,
                "it is simulation truth, which aeromag's estimators and models never read; map a measured column".into(),
            ));
        }
        let keeps_own = is_canonical(&m.file_column)
            && m.file_column != m.canonical
            && map.get(&m.file_column).is_none();
        if keeps_own {
            return Err(err(
                m,
                format!(
                    "it is read as `{}` too (one column in two roles); map `{}` elsewhere as well to swap them",
                    m.file_column, m.file_column
                ),
            ));
        }
    }
    Ok(())
}

/// Resolves the aliases for a file with the given header: the user's map
/// first (every mapped file column must exist), then, if `preset` is on, the
/// MagNav preset for canonical names that are neither in the header nor mapped.
pub(crate) fn resolve(
    file: &str,
    header: &[String],
    map: &ColumnMap,
    sensors: &Sensors,
    preset: bool,
) -> Result<Vec<MappedColumn>> {
    let has = |name: &str| header.iter().any(|h| h == name);
    // The header's spelling of `name`, compared without regard to case
    // (an exact match first), for canonical name `canonical`.
    let find = |name: &str, canonical: &str| -> Result<Option<&String>> {
        find_in(file, header, name, || {
            format!("--columns {canonical}=COLUMN")
        })
    };
    let mut out: Vec<MappedColumn> = Vec::new();
    for (canonical, file_column) in map.pairs() {
        if !has(file_column) {
            return Err(IoError::MappedColumnAbsent {
                file: file.to_string(),
                canonical: canonical.to_string(),
                file_column: file_column.to_string(),
                present: header.join(", "),
            });
        }
        out.push(MappedColumn {
            canonical: canonical.to_string(),
            file_column: file_column.to_string(),
            origin: MapOrigin::User,
        });
    }
    sensors.resolve(file, header, map, &mut out)?;
    check_roles(file, map, &out)?;
    if !preset {
        return Ok(out);
    }
    let taken =
        |out: &[MappedColumn], file_column: &str| out.iter().any(|m| m.file_column == file_column);
    let wanted = |out: &[MappedColumn], canonical: &str| {
        !has(canonical) && !out.iter().any(|m| m.canonical == canonical)
    };
    for (canonical, candidates) in MAGNAV_PRESET {
        if !wanted(&out, canonical) {
            continue;
        }
        let mut hit = None;
        for name in std::iter::once(canonical).chain(candidates.iter().copied()) {
            if let Some(c) = find(name, canonical)?
                && !taken(&out, c.as_str())
                && !is_canonical(c)
            {
                hit = Some(c);
                break;
            }
        }
        if let Some(c) = hit {
            out.push(MappedColumn {
                canonical: canonical.to_string(),
                file_column: c.clone(),
                origin: MapOrigin::MagNavPreset,
            });
        }
    }
    // `line` and the names of the spec in another case (`LINE`).
    for canonical in CANONICAL_COLUMNS {
        if wanted(&out, canonical)
            && let Some(c) = find(canonical, canonical)?.filter(|c| !taken(&out, c.as_str()))
        {
            out.push(MappedColumn {
                canonical: canonical.to_string(),
                file_column: c.clone(),
                origin: MapOrigin::MagNavPreset,
            });
        }
    }
    let flux = ["flux_x", "flux_y", "flux_z"];
    if flux.iter().all(|f| wanted(&out, f)) {
        for prefix in MAGNAV_FLUX_PREFIXES {
            let mut names: Vec<&String> = Vec::new();
            for (a, canonical) in ["x", "y", "z"].iter().zip(flux) {
                if let Some(n) = find(&format!("{prefix}_{a}"), canonical)?
                    && !taken(&out, n.as_str())
                {
                    names.push(n);
                }
            }
            if names.len() == 3 {
                for (canonical, file_column) in flux.iter().zip(names) {
                    out.push(MappedColumn {
                        canonical: canonical.to_string(),
                        file_column: file_column.clone(),
                        origin: MapOrigin::MagNavPreset,
                    });
                }
                break;
            }
        }
    }
    Ok(out)
}

/// The header's spelling of `name`: an exact match, else the one name
/// that differs from it only in case. Several of those (`MAG` and `Mag`
/// for `mag`) and no exact match is [`IoError::AmbiguousColumn`], whose
/// advice `choose` gives: taking the first would pick a sensor or a
/// processing stage by the order of the columns.
fn find_in<'h>(
    file: &str,
    header: &'h [String],
    name: &str,
    choose: impl FnOnce() -> String,
) -> Result<Option<&'h String>> {
    if let Some(h) = header.iter().find(|h| *h == name) {
        return Ok(Some(h));
    }
    let matches: Vec<&String> = header
        .iter()
        .filter(|h| h.eq_ignore_ascii_case(name))
        .collect();
    match matches[..] {
        [] => Ok(None),
        [one] => Ok(Some(one)),
        _ => Err(IoError::AmbiguousColumn {
            file: file.to_string(),
            name: name.to_string(),
            matches: matches
                .iter()
                .map(|h| format!("'{h}'"))
                .collect::<Vec<_>>()
                .join(", "),
            choose: choose(),
        }),
    }
}

/// The sensors of a flight with several magnetometers that a command uses
/// (`--mag NAME`, `--vector PREFIX`); `None` leaves the choice to the
/// column map and the preset (the first scalar and the first complete vector
/// magnetometer).
///
/// Names are the SGL HDF5 names (`mag_3_uc`, `flux_b`), which also find the
/// same sensor under its Geosoft XYZ export name (`UNCOMPMAG3`, `FLUXB_X`…),
/// or any column of the file (`--mag my_mag`, `--vector vec` for
/// `vec_x/vec_y/vec_z`), compared without regard to case.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Sensors {
    /// The scalar magnetometer that plays `mag`.
    pub mag: Option<String>,
    /// The prefix of the vector magnetometer whose `_x`, `_y`, `_z` play
    /// `flux_x`, `flux_y`, `flux_z`.
    pub vector: Option<String>,
}

impl Sensors {
    /// Adds the chosen sensors to `out` (after the user map, before the
    /// preset). Errors: a sensor the map also sets, or one the file lacks.
    fn resolve(
        &self,
        file: &str,
        header: &[String],
        map: &ColumnMap,
        out: &mut Vec<MappedColumn>,
    ) -> Result<()> {
        let conflict = |option: &str, name: &str, canonical: &str| IoError::ColumnMap {
            text: format!("{option} {name}"),
            reason: format!("'{canonical}' is also mapped by --columns; choose the sensor one way"),
        };
        let mut push = |canonical: &str, file_column: &String| {
            out.push(MappedColumn {
                canonical: canonical.to_string(),
                file_column: file_column.clone(),
                origin: MapOrigin::Selected,
            })
        };
        if let Some(name) = &self.mag {
            if map.get("mag").is_some() {
                return Err(conflict("--mag", name, "mag"));
            }
            let mut hit = None;
            for n in sensor_names(name) {
                hit = find_in(file, header, &n, || {
                    "--mag with its exact spelling".to_string()
                })?;
                if hit.is_some() {
                    break;
                }
            }
            let hit = hit.ok_or_else(|| IoError::SensorAbsent {
                file: file.to_string(),
                option: "--mag",
                name: name.clone(),
                candidates: candidates(header, |h| {
                    let l = h.to_ascii_lowercase();
                    (l.starts_with("mag") || l.contains("mag")) && !l.starts_with("flux")
                }),
            })?;
            push("mag", hit);
        }
        if let Some(prefix) = &self.vector {
            if ["flux_x", "flux_y", "flux_z"]
                .iter()
                .any(|c| map.get(c).is_some())
            {
                return Err(conflict("--vector", prefix, "flux_x/y/z"));
            }
            let mut triplet = None;
            for p in sensor_names(prefix) {
                let mut names: Vec<&String> = Vec::new();
                for a in ["x", "y", "z"] {
                    names.extend(find_in(file, header, &format!("{p}_{a}"), || {
                        "--vector with its exact spelling".to_string()
                    })?);
                }
                if names.len() == 3 {
                    triplet = Some(names);
                    break;
                }
            }
            let Some(names) = triplet else {
                return Err(IoError::SensorAbsent {
                    file: file.to_string(),
                    option: "--vector",
                    name: format!("{prefix} ({prefix}_x, {prefix}_y, {prefix}_z)"),
                    candidates: candidates(header, |h| {
                        let l = h.to_ascii_lowercase();
                        l.ends_with("_x") || l.ends_with("_y") || l.ends_with("_z")
                    }),
                });
            };
            for (canonical, file_column) in ["flux_x", "flux_y", "flux_z"].iter().zip(names) {
                push(canonical, file_column);
            }
        }
        Ok(())
    }
}

/// SGL fields whose Geosoft XYZ export name is not the HDF5 name in
/// another case nor follows [`sensor_names`]' patterns: `(HDF5, XYZ)`,
/// lower case. The pairs are MagNav.jl's: `xyz2h5` reads the export's
/// columns in the order of `readmes/sgl_2020_fields_readme.txt`, so the
/// export's header (`Flt1003_sample.xyz`) and that list pair up by
/// position. Fields that play a canonical role (`TIME`, `LONG`, `PITCH`,
/// `AZIMUTH`, …) are left to the preset ([`MAGNAV_PRESET`]).
const SGL_XYZ_NAMES: [(&str, &str); 50] = [
    ("flight", "flt"),
    ("utm_x", "utm-x"),
    ("utm_y", "utm-y"),
    ("utm_z", "utm-z"),
    ("msl", "msl-z"),
    ("ogs_alt", "ogs_hgt"),
    ("ins_alt", "ins_hgt"),
    ("ins_vn", "ins_vel_n"),
    ("ins_vw", "ins_vel_w"),
    ("ins_vu", "ins_vel_v"),
    ("pitch_rate", "pitchrt"),
    ("roll_rate", "rollrt"),
    ("yaw_rate", "yawrt"),
    ("lgtl_acc", "long_acc"),
    ("ltrl_acc", "lat_acc"),
    ("nrml_acc", "norm_acc"),
    ("tas", "true_as"),
    ("total_p", "tot_p"),
    ("cur_com_1", "cur_com1"),
    ("cur_ac_hi", "cur_achi"),
    ("cur_ac_lo", "cur_aclo"),
    ("cur_tank", "cur_tank"),
    ("cur_flap", "cur_flap"),
    ("cur_strb", "cur_strb"),
    ("cur_srvo_o", "cur_srvo_o"),
    ("cur_srvo_m", "cur_srvo_m"),
    ("cur_srvo_i", "cur_srvo_i"),
    ("cur_heat", "cur_ihtr"),
    ("cur_acpwr", "cur_acpwr"),
    ("cur_outpwr", "cur_outpwr"),
    ("cur_bat_1", "cur_bat1"),
    ("cur_bat_2", "cur_bat2"),
    ("vol_acpwr", "v_acpwr"),
    ("vol_outpwr", "v_outpwr"),
    ("vol_bat_1", "v_bat1"),
    ("vol_bat_2", "v_bat2"),
    ("vol_res_p", "v_resp"),
    ("vol_res_n", "v_resn"),
    ("vol_back_p", "v_backp"),
    ("vol_back_n", "v_backn"),
    ("vol_gyro_1", "v_gyro1"),
    ("vol_gyro_2", "v_gyro2"),
    ("vol_acc_p", "v_accp"),
    ("vol_acc_n", "v_accn"),
    ("vol_block", "v_block"),
    ("vol_back", "v_back"),
    ("vol_srvo", "v_servo"),
    ("vol_cabt", "v_cabt"),
    ("vol_fan", "v_fan"),
    ("ogs_mag", "ogs_mag"),
];

/// The MagNav (SGL HDF5) name of a field given by its MagNav name or its
/// Geosoft XYZ export name, in any case (`UNCOMPMAG3` → `mag_3_uc`,
/// `CUR_COM1` → `cur_com_1`, `FLUXB_X` → `flux_b_x`, `FLUXB` → `flux_b`);
/// any other name as it is. What a model file stores, so that it applies
/// to a flight in either naming ([`sensor_names`] finds the other).
pub fn magnav_name(name: &str) -> String {
    let names = sensor_names(name);
    let is_magnav = |n: &str| {
        let l = n.to_ascii_lowercase();
        SGL_XYZ_NAMES.iter().any(|(h, _)| *h == l)
            || (l.starts_with("mag_") && l.matches('_').count() == 2)
            || (l.starts_with("flux_") && l.len() >= 6)
    };
    let lower = name.to_ascii_lowercase();
    if is_canonical(&lower) {
        return name.to_string();
    }
    if (names.len() > 1 || SGL_XYZ_NAMES.iter().any(|(_, x)| *x == lower))
        && let Some(n) = names.iter().find(|n| is_magnav(n))
    {
        return n.to_ascii_lowercase();
    }
    name.to_string()
}

/// The names one sensor or field goes by: as given, and its SGL HDF5 /
/// Geosoft XYZ counterpart (`mag_3_uc` ↔ `UNCOMPMAG3`, `mag_1_c` ↔
/// `COMPMAG1`, `flux_b` ↔ `FLUXB`, `flux_b_x` ↔ `FLUXB_X`, `flux_b_t` ↔
/// `FLUXB_TOT`, `cur_com_1` ↔ `CUR_COM1`, the other pairs of
/// `SGL_XYZ_NAMES`). Compared without regard to case by every lookup.
pub fn sensor_names(name: &str) -> Vec<String> {
    let lower = name.to_ascii_lowercase();
    let mut names = vec![name.to_string()];
    for (h, x) in SGL_XYZ_NAMES {
        if lower == h && h != x {
            names.push(x.to_string());
        } else if lower == x && h != x {
            names.push(h.to_string());
        }
    }
    // flux_<s>_<c> ↔ flux<s>_<c>; total: flux_<s>_t ↔ flux<s>_tot
    let component = |c: &str| matches!(c, "x" | "y" | "z");
    if let Some((s, c)) = lower.strip_prefix("flux_").and_then(|r| r.split_once('_'))
        && s.len() == 1
    {
        if component(c) {
            names.push(format!("flux{s}_{c}"));
        } else if c == "t" {
            names.push(format!("flux{s}_tot"));
        }
    } else if let Some((s, c)) = lower.strip_prefix("flux").and_then(|r| r.split_once('_'))
        && s.len() == 1
        && s != "_"
    {
        if component(c) {
            names.push(format!("flux_{s}_{c}"));
        } else if c == "tot" {
            names.push(format!("flux_{s}_t"));
        }
    }
    let digits = |s: &str| !s.is_empty() && s.bytes().all(|b| b.is_ascii_digit());
    // mag_<k>_<kind> (HDF5) ↔ <KIND>MAG<k> (XYZ)
    const KINDS: [(&str, &str); 5] = [
        ("uc", "uncompmag"),
        ("c", "compmag"),
        ("lag", "lagmag"),
        ("dc", "dcmag"),
        ("igrf", "igrfmag"),
    ];
    let parts: Vec<&str> = lower.split('_').collect();
    if let ["mag", k, kind] = parts[..]
        && digits(k)
        && let Some((_, xyz)) = KINDS.iter().find(|(h, _)| *h == kind)
    {
        names.push(format!("{xyz}{k}"));
    }
    for (h, xyz) in KINDS {
        if let Some(k) = lower.strip_prefix(xyz)
            && digits(k)
        {
            names.push(format!("mag_{k}_{h}"));
        }
    }
    // flux_<s> ↔ flux<s>
    if let Some(s) = lower.strip_prefix("flux_")
        && s.len() == 1
    {
        names.push(format!("flux{s}"));
    } else if let Some(s) = lower.strip_prefix("flux")
        && s.len() == 1
        && s != "_"
    {
        names.push(format!("flux_{s}"));
    }
    names
}

/// The header names that pass `keep`, for a "present are …" hint.
fn candidates(header: &[String], keep: impl Fn(&str) -> bool) -> String {
    let c: Vec<&str> = header
        .iter()
        .map(String::as_str)
        .filter(|h| keep(h))
        .collect();
    if c.is_empty() {
        "none that looks like one".to_string()
    } else {
        c.join(", ")
    }
}

/// The canonical name closest to `name` (case-insensitive edit distance ≤ 2).
fn closest_canonical(name: &str) -> Option<&'static str> {
    // A canonical name in another case (`flux_X`) is the suggestion.
    CANONICAL_COLUMNS
        .iter()
        .find(|c| c.eq_ignore_ascii_case(name))
        .copied()
        .or_else(|| closest_name(name, CANONICAL_COLUMNS))
}

/// The name among `candidates` closest to `name`, for a "did you mean"
/// hint: edit distance at most 2, compared without regard to case (a
/// transposition such as `levle` is 2; a wider net suggests unrelated
/// names among a survey file's 50 columns), the first of equally close
/// ones. `None` for an exact match without regard to case: that is no typo.
pub fn closest_name<'c>(
    name: &str,
    candidates: impl IntoIterator<Item = &'c str>,
) -> Option<&'c str> {
    let lower = name.to_ascii_lowercase();
    candidates
        .into_iter()
        .map(|c| (edit_distance(&lower, &c.to_ascii_lowercase()), c))
        .filter(|(d, _)| (1..=2).contains(d))
        .min_by_key(|(d, _)| *d)
        .map(|(_, c)| c)
}

/// Levenshtein distance between two short strings (by chars).
fn edit_distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut prev: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut cur = vec![i + 1; b.len() + 1];
        for (j, cb) in b.iter().enumerate() {
            let sub = prev[j] + usize::from(ca != *cb);
            cur[j + 1] = sub.min(prev[j + 1] + 1).min(cur[j] + 1);
        }
        prev = cur;
    }
    prev[b.len()]
}

#[cfg(test)]
mod tests {
    use super::*;

    fn header(names: &[&str]) -> Vec<String> {
        names.iter().map(|s| s.to_string()).collect()
    }

    #[test]
    fn parses_pairs_with_spaces() {
        let m = ColumnMap::parse(" mag = mag_1_uc , flux_x=flux_a_x,true_anomaly=anom").unwrap();
        assert_eq!(m.get("mag"), Some("mag_1_uc"));
        assert_eq!(m.get("flux_x"), Some("flux_a_x"));
        assert_eq!(m.get("true_anomaly"), Some("anom"));
        assert_eq!(m.get("flux_y"), None);
        assert!(ColumnMap::parse("  ").unwrap().is_empty());
    }

    #[test]
    fn rejects_malformed_text() {
        for bad in [
            "mag",
            "mag=",
            "=x",
            "mag=a=b",
            "mag=a,,flux_x=b",
            "mag=a,",
            "mag=a,mag=b",
            "mag=a,igrf=a",
            "true_=x",
        ] {
            let e = ColumnMap::parse(bad).unwrap_err();
            assert!(matches!(e, IoError::ColumnMap { .. }), "{bad}: {e}");
            assert!(e.to_string().contains(bad), "{bad}: {e}");
        }
    }

    #[test]
    fn unknown_canonical_gets_suggestion() {
        let e = ColumnMap::parse("flux_X=a").unwrap_err().to_string();
        assert!(e.contains("did you mean 'flux_x'"), "{e}");
        let e = ColumnMap::parse("speed=a").unwrap_err().to_string();
        assert!(
            !e.contains("did you mean") && e.contains("not a canonical"),
            "{e}"
        );
    }

    #[test]
    fn user_map_requires_present_column() {
        let m = ColumnMap::parse("mag=mag_9_uc").unwrap();
        let e = resolve(
            "f.csv",
            &header(&["time", "mag_1_uc"]),
            &m,
            &Sensors::default(),
            true,
        )
        .unwrap_err();
        let s = e.to_string();
        assert!(matches!(e, IoError::MappedColumnAbsent { .. }));
        assert!(
            s.contains("mag_9_uc") && s.contains("f.csv") && s.contains("time, mag_1_uc"),
            "{s}"
        );
    }

    #[test]
    fn xyz_export_names_are_mapped_without_regard_to_case_and_radians_are_not() {
        // The header of the SGL surveys' Geosoft XYZ export (spec
        // "Real survey files"), shortened.
        let h = header(&[
            "LINE",
            "FLT",
            "TIME",
            "UTM-Z",
            "LAT",
            "LONG",
            "PITCH",
            "ROLL",
            "AZIMUTH",
            "DIURNAL",
            "COMPMAG1",
            "IGRFMAG1",
            "UNCOMPMAG1",
            "UNCOMPMAG2",
            "FLUXA_X",
            "FLUXA_Y",
            "FLUXA_Z",
            "FLUXA_TOT",
            "FLUXB_X",
            "FLUXB_Y",
            "FLUXB_Z",
            "INS_LAT",
            "INS_LON",
            "INS_HGT",
            "INS_VEL_N",
            "INS_VEL_W",
            "INS_VEL_V",
            "CUR_ACHi",
        ]);
        let m = resolve("f", &h, &ColumnMap::new(), &Sensors::default(), true).unwrap();
        let get = |c: &str| {
            m.iter()
                .find(|x| x.canonical == c)
                .map(|x| x.file_column.as_str())
        };
        for (canonical, file) in [
            ("time", "TIME"),
            ("lat", "LAT"),
            ("lon", "LONG"),
            ("alt", "UTM-Z"),
            ("roll", "ROLL"),
            ("pitch", "PITCH"),
            ("yaw", "AZIMUTH"),
            ("mag", "UNCOMPMAG1"),
            ("diurnal", "DIURNAL"),
            ("line", "LINE"),
            ("vn", "INS_VEL_N"),
            ("flux_x", "FLUXA_X"),
            ("flux_z", "FLUXA_Z"),
        ] {
            assert_eq!(get(canonical), Some(file), "{canonical}");
        }
        // West and up velocities and radian positions need a conversion:
        // never aliases. IGRFMAG1 is the anomaly, not the main field.
        for file in ["INS_LAT", "INS_LON", "INS_VEL_W", "INS_VEL_V", "IGRFMAG1"] {
            assert!(m.iter().all(|x| x.file_column != file), "{file}");
        }
        assert_eq!(get("ve"), None);
        assert_eq!(get("igrf"), None);
        // A file with only the INS position has no lat/lon at all.
        let ins_only = header(&["tt", "ins_lat", "ins_lon", "mag_1_uc"]);
        let m = resolve("f", &ins_only, &ColumnMap::new(), &Sensors::default(), true).unwrap();
        assert!(
            m.iter()
                .all(|x| x.canonical != "lat" && x.canonical != "lon")
        );
    }

    #[test]
    fn magnav_preset_fills_only_absent_names() {
        let h = header(&[
            "tt",
            "lat",
            "lon",
            "utm_z",
            "ins_alt",
            "ins_lat",
            "ins_roll",
            "ins_pitch",
            "ins_yaw",
            "mag_1_uc",
            "mag_3_uc",
            "flux_a_x",
            "flux_a_y",
            "flux_b_x",
            "flux_b_y",
            "flux_b_z",
            "line",
        ]);
        let m = resolve("f", &h, &ColumnMap::new(), &Sensors::default(), true).unwrap();
        let get = |c: &str| {
            m.iter()
                .find(|x| x.canonical == c)
                .map(|x| x.file_column.as_str())
        };
        assert_eq!(get("time"), Some("tt"));
        assert_eq!(get("lat"), None, "lat is in the file itself");
        assert_eq!(get("alt"), Some("utm_z"));
        assert_eq!(get("roll"), Some("ins_roll"));
        assert_eq!(get("mag"), Some("mag_1_uc"));
        // flux_a lacks z: the complete triplet B is used.
        assert_eq!(get("flux_x"), Some("flux_b_x"));
        assert_eq!(get("flux_z"), Some("flux_b_z"));
        assert!(m.iter().all(|x| x.origin == MapOrigin::MagNavPreset));
        // User map wins and the preset does not reuse its column.
        let user = ColumnMap::parse("mag=mag_3_uc").unwrap();
        let m = resolve("f", &h, &user, &Sensors::default(), true).unwrap();
        assert_eq!(m.iter().filter(|x| x.canonical == "mag").count(), 1);
        assert_eq!(m[0].origin, MapOrigin::User);
        assert!(
            resolve("f", &h, &ColumnMap::new(), &Sensors::default(), false)
                .unwrap()
                .is_empty()
        );
    }

    #[test]
    fn sensors_are_chosen_by_sgl_or_xyz_name() {
        let xyz = header(&[
            "TIME",
            "UNCOMPMAG1",
            "UNCOMPMAG3",
            "FLUXA_X",
            "FLUXA_Y",
            "FLUXA_Z",
            "FLUXB_X",
            "FLUXB_Y",
            "FLUXB_Z",
        ]);
        let choose = |mag: &str, vector: &str| Sensors {
            mag: Some(mag.into()),
            vector: Some(vector.into()),
        };
        for (mag, vector) in [
            ("mag_3_uc", "flux_b"),
            ("UNCOMPMAG3", "FLUXB"),
            ("uncompmag3", "fluxb"),
        ] {
            let m = resolve("f", &xyz, &ColumnMap::new(), &choose(mag, vector), true).unwrap();
            let get = |c: &str| m.iter().find(|x| x.canonical == c).unwrap();
            assert_eq!(get("mag").file_column, "UNCOMPMAG3", "{mag}");
            assert_eq!(get("mag").origin, MapOrigin::Selected);
            assert_eq!(get("flux_y").file_column, "FLUXB_Y", "{vector}");
            assert_eq!(m.iter().filter(|x| x.canonical == "mag").count(), 1);
        }
        let h5 = header(&[
            "tt", "mag_1_uc", "mag_3_uc", "flux_b_x", "flux_b_y", "flux_b_z",
        ]);
        let m = resolve(
            "f",
            &h5,
            &ColumnMap::new(),
            &choose("UNCOMPMAG3", "FLUXB"),
            true,
        )
        .unwrap();
        assert_eq!(m[0].file_column, "mag_3_uc");
        assert_eq!(m[1].file_column, "flux_b_x");
        // Absent sensors name the candidates; the map and the option cannot both choose.
        let e = resolve(
            "f",
            &h5,
            &ColumnMap::new(),
            &choose("mag_5_uc", "flux_b"),
            true,
        )
        .unwrap_err()
        .to_string();
        assert!(
            e.contains("--mag mag_5_uc") && e.contains("mag_1_uc, mag_3_uc"),
            "{e}"
        );
        let e = resolve(
            "f",
            &h5,
            &ColumnMap::new(),
            &choose("mag_1_uc", "flux_c"),
            true,
        )
        .unwrap_err()
        .to_string();
        assert!(
            e.contains("--vector flux_c") && e.contains("flux_b_x"),
            "{e}"
        );
        let map = ColumnMap::parse("mag=mag_1_uc").unwrap();
        assert!(resolve("f", &h5, &map, &choose("mag_3_uc", "flux_b"), true).is_err());
    }

    /// Two columns that differ only in case (`MAG`, `Mag`) both read as
    /// `mag`: the first was taken without a word, choosing a sensor by
    /// the columns' order. An exact spelling still wins, and the map or
    /// an exact `--mag`/`--vector` chooses.
    #[test]
    fn columns_equal_without_regard_to_case_are_ambiguous() {
        let h = header(&["time", "MAG", "Mag", "FLUX_X", "Flux_x", "flux_y", "flux_z"]);
        let none = Sensors::default();
        let e = resolve("f.csv", &h, &ColumnMap::new(), &none, true).unwrap_err();
        let msg = e.to_string();
        assert!(e.is_bad_input(), "{msg}");
        assert!(
            msg.contains("'f.csv': columns 'MAG', 'Mag' all read as 'mag'")
                && msg.contains("--columns mag=COLUMN"),
            "{msg}"
        );
        let map = ColumnMap::parse("mag=Mag").unwrap();
        let e = resolve("f.csv", &h, &map, &none, true)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("'FLUX_X', 'Flux_x' all read as 'flux_x'")
                && e.contains("--columns flux_x=COLUMN"),
            "{e}"
        );
        let map = ColumnMap::parse("mag=Mag,flux_x=FLUX_X").unwrap();
        let m = resolve("f.csv", &h, &map, &none, true).unwrap();
        assert_eq!(
            m.iter().find(|x| x.canonical == "mag").unwrap().file_column,
            "Mag"
        );
        // The exact spelling wins, as before.
        let exact = header(&["time", "MAG", "mag", "Mag"]);
        let m = resolve("f.csv", &exact, &ColumnMap::new(), &none, true).unwrap();
        assert!(m.iter().all(|x| x.canonical != "mag"), "{m:?}");
        // `--mag` with a spelling that matches two columns, then an exact one.
        let xyz = header(&[
            "TIME",
            "UNCOMPMAG3",
            "UncompMag3",
            "FLUXB_X",
            "FLUXB_Y",
            "FLUXB_Z",
        ]);
        let choose = |mag: &str| Sensors {
            mag: Some(mag.into()),
            vector: None,
        };
        let e = resolve("f.xyz", &xyz, &ColumnMap::new(), &choose("mag_3_uc"), true)
            .unwrap_err()
            .to_string();
        assert!(e.contains("--mag with its exact spelling"), "{e}");
        let m = resolve(
            "f.xyz",
            &xyz,
            &ColumnMap::new(),
            &choose("UncompMag3"),
            true,
        )
        .unwrap();
        assert_eq!(m[0].file_column, "UncompMag3");
    }

    #[test]
    fn sensor_names_pair_hdf5_and_xyz() {
        assert_eq!(sensor_names("mag_4_uc"), ["mag_4_uc", "uncompmag4"]);
        assert_eq!(sensor_names("COMPMAG1"), ["COMPMAG1", "mag_1_c"]);
        assert_eq!(sensor_names("flux_d"), ["flux_d", "fluxd"]);
        assert_eq!(sensor_names("FLUXA"), ["FLUXA", "flux_a"]);
        assert_eq!(sensor_names("my_mag"), ["my_mag"]);
    }

    /// Every SGL field pairs with its XYZ export name both ways, and the
    /// MagNav name is what a model keeps (the reviewer's `--extra
    /// cur_com_1` on `CUR_COM1`, a model's `mag_1_uc` on `UNCOMPMAG1`).
    #[test]
    fn sgl_fields_pair_with_their_xyz_export_names() {
        for (h5, xyz) in [
            ("mag_1_uc", "UNCOMPMAG1"),
            ("mag_1_dc", "DCMAG1"),
            ("mag_1_igrf", "IGRFMAG1"),
            ("cur_com_1", "CUR_COM1"),
            ("cur_ac_hi", "CUR_ACHi"),
            ("cur_heat", "CUR_IHTR"),
            ("cur_bat_2", "CUR_BAT2"),
            ("vol_srvo", "V_SERVO"),
            ("vol_res_p", "V_RESp"),
            ("flux_b_x", "FLUXB_X"),
            ("flux_c_t", "FLUXC_TOT"),
            ("flux_d", "FLUXD"),
            ("ins_vw", "INS_VEL_W"),
            ("pitch_rate", "PITCHRT"),
        ] {
            let lower = xyz.to_ascii_lowercase();
            assert!(
                sensor_names(h5).contains(&lower),
                "{h5}: {:?}",
                sensor_names(h5)
            );
            assert!(sensor_names(xyz).iter().any(|n| n == h5), "{xyz}");
            assert_eq!(magnav_name(xyz), h5);
            assert_eq!(magnav_name(h5), h5);
            assert_eq!(magnav_name(&h5.to_ascii_uppercase()), h5);
        }
        // Same name in both (any case), and names of no SGL field.
        assert_eq!(magnav_name("CUR_STRB"), "cur_strb");
        for other in ["my_mag", "mag_2", "cable_azimuth", "mag", "Flux_X"] {
            assert_eq!(magnav_name(other), other);
        }
        // A mapping of an SGL name says it needs none.
        let e = ColumnMap::parse("mag_1_uc=UNCOMPMAG1")
            .unwrap_err()
            .to_string();
        assert!(e.contains("needs no mapping"), "{e}");
    }

    #[test]
    fn closest_name_suggests_a_typo_not_an_unrelated_name() {
        let names = ["mag_comp", "mag_comp_level", "level_flag", "MAG"];
        assert_eq!(
            closest_name("mag_comp_levle", names),
            Some("mag_comp_level")
        );
        assert_eq!(closest_name("MAG_COMP_LEVL", names), Some("mag_comp_level"));
        assert_eq!(closest_name("altitude", names), None);
        assert_eq!(
            closest_name("mag", names),
            None,
            "a match in another case is no typo"
        );
    }

    #[test]
    fn edit_distance_is_levenshtein() {
        assert_eq!(edit_distance("kitten", "sitting"), 3);
        assert_eq!(edit_distance("", "abc"), 3);
        assert_eq!(edit_distance("flux_x", "flux_x"), 0);
    }
}
