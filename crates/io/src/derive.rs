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
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Conversion {
    /// Radians to degrees.
    RadiansToDegrees,
    /// Sign flipped (west → east, up → down).
    Negated,
}

impl Conversion {
    /// Applies the conversion to one value.
    pub fn apply(self, v: f64) -> f64 {
        match self {
            Conversion::RadiansToDegrees => v.to_degrees(),
            Conversion::Negated => -v,
        }
    }

    /// Short description for `inspect` (`rad → deg`, `× −1`).
    pub fn describe(self) -> &'static str {
        match self {
            Conversion::RadiansToDegrees => "rad → deg",
            Conversion::Negated => "× −1",
        }
    }
}

/// A canonical column computed from a file column.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct DerivedColumn {
    /// The canonical name it plays (`lat`).
    pub canonical: String,
    /// The file column it is computed from (`INS_LAT`).
    pub from: String,
    /// The conversion.
    pub conversion: Conversion,
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
    for (canonical, _, _) in DERIVATIONS {
        if table.get(canonical).is_some() {
            continue;
        }
        let names: Vec<String> = table.column_names().iter().map(|s| s.to_string()).collect();
        let Some((from, conversion)) = derivation_for(canonical, names.iter().map(String::as_str))
        else {
            continue;
        };
        let Some(values) = table.column(from) else {
            continue;
        };
        let values: Vec<f64> = values.iter().map(|&v| conversion.apply(v)).collect();
        let d = DerivedColumn {
            canonical: canonical.to_string(),
            from: from.to_string(),
            conversion,
        };
        table.add_derived(d, values)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

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
