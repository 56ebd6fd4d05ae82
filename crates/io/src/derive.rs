//! Canonical columns computed from fields in another unit or sign
//! convention (spec `data-formats.md`, "Real survey files").
//!
//! An alias cannot convert, so the SGL fields whose unit differs from the
//! canonical one are never mapped ([`columns`](crate::columns)); when the
//! canonical column is neither in the file nor mapped, it is computed:
//!
//! | canonical | from (HDF5 / XYZ name) | conversion |
//! |---|---|---|
//! | `lat` (deg) | `ins_lat` / `INS_LAT` (rad) | × 180/π |
//! | `lon` (deg) | `ins_lon` / `INS_LON` (rad) | × 180/π |
//! | `ve` (m/s, east) | `ins_vw` / `INS_VEL_W` (west) | × −1 |
//! | `vd` (m/s, down) | `ins_vu` / `INS_VEL_V` (up) | × −1 |
//! | `igrf` (nT) | `mag_1_dc` − `mag_1_igrf` / `DCMAG1` − `IGRFMAG1` | difference |
//!
//! **`ins_lat`/`ins_lon`: radians or degrees.** The SGL layout records
//! them in radians (`readmes/sgl_2020_fields_readme.txt`; MagNav.jl's
//! `get_XYZ20` uses them as radians), but MagNav's own XYZ0/XYZ1 layout
//! (`get_XYZ0`'s field table, its example `xyz.h5`) records them in
//! degrees. The values decide ([`ins_position_unit`]): a latitude beyond
//! ±π/2 or a longitude beyond ±π cannot be radians, so both fields (one
//! INS records both) are then taken as degrees as recorded, and
//! [`check_units`](crate::check_units) says so in a named warning
//! (`ins-degrees`). Otherwise they are radians, as before. A file in
//! degrees whose every position lies within ±π/2, ±π (within 1.6° of the
//! equator and 3.1° of Greenwich) cannot be told from radians:
//! `--columns lat=ins_lat,lon=ins_lon` reads it as degrees.
//!
//! **`igrf`.** MagNav.jl's `get_XYZ20` provides the main field "for
//! convenience" as `igrf = mag_1_dc - mag_1_igrf` (`src/get_XYZ.jl`): the
//! contractor's diurnal-corrected Mag 1 minus its IGRF- and
//! diurnal-corrected Mag 1, nT. A file with both and no `igrf` gets it the
//! same way, so `--reference auto` subtracts the main field as it does
//! for a file that records it.
//!
//! A derived column is added under its canonical name and listed by
//! [`FlightTable::derived`](crate::FlightTable::derived) (which `inspect`
//! prints); writers leave it out, so an output file holds the input's
//! columns as they were plus the results.
//!
//! ```
//! use aeromag_io::{FlightTable, derive_columns};
//! let mut t = FlightTable::new();
//! t.add_column("ins_lat", vec![0.785_398_163_397_448_3])?; // π/4 rad
//! t.add_column("ins_vw", vec![12.0])?;
//! derive_columns(&mut t)?;
//! assert!((t.column("lat").unwrap()[0] - 45.0).abs() < 1e-12);
//! assert_eq!(t.column("ve").unwrap(), &[-12.0]);
//! assert_eq!(t.derived().len(), 2);
//! # Ok::<(), aeromag_io::IoError>(())
//! ```

use serde::Serialize;

use crate::error::Result;
use crate::table::FlightTable;

/// How a derived column is computed from its source.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Conversion {
    /// Radians to degrees.
    RadiansToDegrees,
    /// Degrees as recorded: an INS position whose values cannot be
    /// radians (module docs).
    DegreesAsRecorded,
    /// Sign flipped (west → east, up → down).
    Negated,
    /// The source minus a second column ([`DerivedColumn::minus`]).
    Difference,
}

impl Conversion {
    /// Applies the conversion to one value ([`Conversion::Difference`]:
    /// the value as it is; the second column is subtracted by
    /// [`derive_columns`]).
    pub fn apply(self, v: f64) -> f64 {
        match self {
            Conversion::RadiansToDegrees => v.to_degrees(),
            Conversion::DegreesAsRecorded | Conversion::Difference => v,
            Conversion::Negated => -v,
        }
    }

    /// Short description for `inspect` (`rad → deg`, `× −1`).
    pub fn describe(self) -> &'static str {
        match self {
            Conversion::RadiansToDegrees => "rad → deg",
            Conversion::DegreesAsRecorded => "deg as recorded",
            Conversion::Negated => "× −1",
            Conversion::Difference => "difference",
        }
    }
}

/// A canonical column computed from a file column.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, serde::Deserialize)]
pub struct DerivedColumn {
    /// The canonical name it plays (`lat`).
    pub canonical: String,
    /// The file column it is computed from (`INS_LAT`).
    pub from: String,
    /// The conversion.
    pub conversion: Conversion,
    /// For [`Conversion::Difference`], the file column subtracted
    /// (`IGRFMAG1`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub minus: Option<String>,
}

impl DerivedColumn {
    /// How it is computed, for messages: `INS_LAT (rad → deg)`,
    /// `DCMAG1 − IGRFMAG1`.
    pub fn describe(&self) -> String {
        match &self.minus {
            Some(m) => format!("{} − {m}", self.from),
            None => format!("{} ({})", self.from, self.conversion.describe()),
        }
    }
}

/// Derived columns that are the difference of two fields: canonical name,
/// minuend, subtrahend (MagNav names, which find the XYZ export's
/// `DCMAG1`, `IGRFMAG1` too; module docs).
pub const DIFFERENCES: [(&str, &str, &str); 1] = [("igrf", "mag_1_dc", "mag_1_igrf")];

/// The unit of the INS position fields `ins_lat`, `ins_lon` (or
/// `INS_LAT`, `INS_LON`) of `table`: `Some((RadiansToDegrees, _))` when
/// every finite value fits radians, `Some((DegreesAsRecorded, evidence))`
/// when a latitude beyond ±π/2 or a longitude beyond ±π shows degrees
/// (evidence: the field and its value, e.g. `INS_LAT = 39.16`); `None`
/// without either field. One decision for both: one INS records them.
pub fn ins_position_unit(table: &FlightTable) -> Option<(Conversion, String)> {
    let names = table.column_names();
    let mut any = false;
    for (field, limit) in [
        ("ins_lat", std::f64::consts::FRAC_PI_2),
        ("ins_lon", std::f64::consts::PI),
    ] {
        let Some(name) = names.iter().find(|n| n.eq_ignore_ascii_case(field)) else {
            continue;
        };
        let Some(values) = table.column(name) else {
            continue;
        };
        any = true;
        if let Some(v) = values.iter().find(|v| v.is_finite() && v.abs() > limit) {
            return Some((
                Conversion::DegreesAsRecorded,
                format!("{name} = {}", aeromag_core::error::shown(*v)),
            ));
        }
    }
    any.then(|| (Conversion::RadiansToDegrees, String::new()))
}

/// The derivation rules of the module docs: canonical name, source names
/// (compared without regard to case), conversion.
pub const DERIVATIONS: [(&str, &[&str], Conversion); 4] = [
    ("lat", &["ins_lat"], Conversion::RadiansToDegrees),
    ("lon", &["ins_lon"], Conversion::RadiansToDegrees),
    ("ve", &["ins_vw", "ins_vel_w"], Conversion::Negated),
    ("vd", &["ins_vu", "ins_vel_v"], Conversion::Negated),
];

/// The derivation that would give canonical column `canonical` in a file
/// with the columns `names` (when the canonical column itself is absent):
/// `(source file column, conversion)`.
pub fn derivation_for<'a>(
    canonical: &str,
    names: impl Iterator<Item = &'a str> + Clone,
) -> Option<(&'a str, Conversion)> {
    let (_, sources, conversion) = DERIVATIONS.iter().find(|(c, _, _)| *c == canonical)?;
    sources.iter().find_map(|s| {
        names
            .clone()
            .find(|n| n.eq_ignore_ascii_case(s))
            .map(|n| (n, *conversion))
    })
}

/// Adds the derived columns a table lacks (see the module docs). Text
/// sources are left alone (the unit checks and `require` report them).
pub fn derive_columns(table: &mut FlightTable) -> Result<()> {
    let ins_unit = ins_position_unit(table).map(|(c, _)| c);
    for (canonical, _, _) in DERIVATIONS {
        if table.get(canonical).is_some() {
            continue;
        }
        let names: Vec<String> = table.column_names().iter().map(|s| s.to_string()).collect();
        let Some((from, mut conversion)) =
            derivation_for(canonical, names.iter().map(String::as_str))
        else {
            continue;
        };
        if conversion == Conversion::RadiansToDegrees
            && let Some(unit) = ins_unit
        {
            conversion = unit;
        }
        let Some(values) = table.column(from) else {
            continue;
        };
        let values: Vec<f64> = values.iter().map(|&v| conversion.apply(v)).collect();
        let d = DerivedColumn {
            canonical: canonical.to_string(),
            from: from.to_string(),
            conversion,
            minus: None,
        };
        table.add_derived(d, values)?;
    }
    for (canonical, a, b) in DIFFERENCES {
        if table.get(canonical).is_some() {
            continue;
        }
        // Found in either naming and any case (`DCMAG1`, `IGRFMAG1`).
        let (Some(from), Some(minus)) = (table.resolve(a), table.resolve(b)) else {
            continue;
        };
        let (from, minus) = (from.to_string(), minus.to_string());
        let (Some(x), Some(y)) = (table.column(&from), table.column(&minus)) else {
            continue;
        };
        let values: Vec<f64> = x.iter().zip(y).map(|(x, y)| x - y).collect();
        let d = DerivedColumn {
            canonical: canonical.to_string(),
            from,
            conversion: Conversion::Difference,
            minus: Some(minus),
        };
        table.add_derived(d, values)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// MagNav's `get_XYZ20`: `igrf = mag_1_dc - mag_1_igrf` (nT), from the
    /// XYZ export's `DCMAG1`, `IGRFMAG1` too; a file's own `igrf` wins.
    #[test]
    fn igrf_is_derived_as_magnav_does() {
        // Flt1003_sample.xyz, first row: DCMAG1 53624.049, IGRFMAG1 -183.066.
        let mut t = FlightTable::new();
        t.add_column("DCMAG1", vec![53_624.049, 53_623.568])
            .unwrap();
        t.add_column("IGRFMAG1", vec![-183.066, -183.522]).unwrap();
        derive_columns(&mut t).unwrap();
        let igrf = t.column("igrf").unwrap();
        assert!((igrf[0] - 53_807.115).abs() < 1e-9 && (igrf[1] - 53_807.09).abs() < 1e-9);
        let d = &t.derived()[0];
        assert_eq!(d.describe(), "DCMAG1 − IGRFMAG1");
        assert_eq!(d.conversion, Conversion::Difference);
        let mut h5 = FlightTable::new();
        h5.add_column("mag_1_dc", vec![50_010.0]).unwrap();
        h5.add_column("mag_1_igrf", vec![10.0]).unwrap();
        derive_columns(&mut h5).unwrap();
        assert_eq!(h5.column("igrf").unwrap(), &[50_000.0]);
        let mut own_t = FlightTable::new();
        own_t.add_column("igrf", vec![1.0]).unwrap();
        own_t.add_column("mag_1_dc", vec![50_010.0]).unwrap();
        own_t.add_column("mag_1_igrf", vec![10.0]).unwrap();
        derive_columns(&mut own_t).unwrap();
        assert_eq!(own_t.column("igrf").unwrap(), &[1.0]);
        assert!(own_t.derived().is_empty());
        // One of the two is not enough.
        let mut own = FlightTable::new();
        own.add_column("DCMAG1", vec![1.0]).unwrap();
        derive_columns(&mut own).unwrap();
        assert!(own.get("igrf").is_none());
    }

    /// `ins_lat`/`ins_lon` in degrees (MagNav's XYZ0 `xyz.h5`: 39.16,
    /// −95.52) are taken as recorded; radians (SGL) converted as before.
    #[test]
    fn ins_positions_in_degrees_are_told_by_their_values() {
        let table = |lat: f64, lon: f64| {
            let mut t = FlightTable::new();
            t.add_column("ins_lat", vec![lat, lat + 1e-4]).unwrap();
            t.add_column("INS_LON", vec![lon, lon]).unwrap();
            t
        };
        let mut deg = table(39.1607, -95.5207);
        derive_columns(&mut deg).unwrap();
        assert_eq!(deg.column("lat").unwrap(), &[39.1607, 39.1608]);
        assert_eq!(deg.column("lon").unwrap(), &[-95.5207, -95.5207]);
        assert!(
            deg.derived()
                .iter()
                .all(|d| d.conversion == Conversion::DegreesAsRecorded)
        );
        let (unit, why) = ins_position_unit(&deg).unwrap();
        assert_eq!(unit, Conversion::DegreesAsRecorded);
        assert_eq!(why, "ins_lat = 39.1607");
        // A longitude alone beyond π decides for both (one INS).
        let mut deg = table(0.5, 10.0);
        derive_columns(&mut deg).unwrap();
        assert_eq!(deg.column("lat").unwrap()[0], 0.5);
        // Radians: exactly as before.
        let mut rad = table(0.683_5, -1.667_2);
        derive_columns(&mut rad).unwrap();
        assert_eq!(rad.column("lat").unwrap()[0], 0.683_5f64.to_degrees());
        assert_eq!(rad.column("lon").unwrap()[0], (-1.667_2f64).to_degrees());
        assert_eq!(
            ins_position_unit(&rad).unwrap().0,
            Conversion::RadiansToDegrees
        );
    }

    #[test]
    fn present_canonical_columns_are_not_derived_and_text_sources_are_skipped() {
        let mut t = FlightTable::new();
        t.add_column("lat", vec![45.0]).unwrap();
        t.add_column("INS_LAT", vec![0.1]).unwrap();
        t.add_column("INS_LON", vec![-1.3]).unwrap();
        t.add_text_column("INS_VEL_W", vec!["x".into()]).unwrap();
        derive_columns(&mut t).unwrap();
        assert_eq!(t.column("lat").unwrap(), &[45.0]);
        assert_eq!(t.column("lon").unwrap(), &[(-1.3f64).to_degrees()]);
        assert!(t.get("ve").is_none());
        assert_eq!(t.derived().len(), 1);
        assert_eq!(t.derived()[0].from, "INS_LON");
        assert!(t.is_derived("lon") && !t.is_derived("lat"));
        // Writers leave derived columns out.
        let mut out = Vec::new();
        crate::write_csv_to(&t, &mut out).unwrap();
        assert!(
            String::from_utf8(out)
                .unwrap()
                .starts_with("lat,INS_LAT,INS_LON,INS_VEL_W\n")
        );
    }
}
