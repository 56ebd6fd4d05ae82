//! The magnetic column a survey command takes when none is named
//! (`level`, `grid`, `microlevel`): the most processed, compensated one.
//!
//! Names are compared without regard to case, as every column of a flight
//! file is (a Geosoft export's `MAG_COMP`, a header upper-cased by another
//! program): matched case-sensitively, `MAG_COMP` was passed over for the
//! raw reading `mag` (16.31 nT of crossover RMS before levelling against
//! 13.03 nT with the compensated column, on the simulated survey).

use super::Flight;
use crate::error::{Error, Result};

/// What a survey file's magnetic columns are made of, most wanted first:
/// the single-sensor compensated reading (`aeromag compensate`), then the
/// compensated readings of a multi-sensor `compensate`, `mag_<k>_comp`, in
/// the file's order (the first is the first sensor's, the reference of the
/// others: `tolles_lawson::sensors`), then the reading as recorded,
/// `mag` (or the column mapped onto it, such as SGL's `mag_1_uc`).
pub const UNCOMPENSATED: &str = "mag";

/// The default magnetic column of a flight ([`default_column`]).
#[derive(Debug, Clone, PartialEq)]
pub struct DefaultColumn {
    /// The column's name as the flight has it (`MAG_COMP_level`, `mag`).
    pub name: String,
    /// The warning `[uncompensated-default]` when the column chosen is the
    /// uncompensated reading (or a processed form of it).
    pub warning: Option<String>,
}

/// Whether `name` is a multi-sensor compensated reading `mag_<k>_comp`
/// (without regard to case).
fn is_sensor_compensated(name: &str) -> bool {
    let lower = name.to_ascii_lowercase();
    lower
        .strip_prefix("mag_")
        .and_then(|r| r.strip_suffix("_comp"))
        .is_some_and(|k| !k.is_empty() && k.bytes().all(|b| b.is_ascii_digit()))
}

/// The flight's column named `name` without regard to case: an exact
/// match first, else the one differing only in case; several of those is
/// bad input (taking the first would choose by the order of the columns).
pub(crate) fn find_column(flight: &Flight, name: &str, flag: &str) -> Result<Option<String>> {
    let mapped = || flight.table().mapping().iter().any(|m| m.canonical == name);
    if name == UNCOMPENSATED || aeromag_io::RESULT_COLUMNS.contains(&name) && mapped() {
        // The canonical reading, through the column map and the preset;
        // `mag_comp` mapped onto another processing's column (`--columns
        // mag_comp=COMPMAG1`).
        return Ok(flight.column(name).map(|_| name.to_string()));
    }
    let names = flight.column_names();
    if names.contains(&name) {
        return Ok(Some(name.to_string()));
    }
    let same: Vec<&str> = names
        .into_iter()
        .filter(|c| c.eq_ignore_ascii_case(name))
        .collect();
    match same[..] {
        [] => Ok(None),
        [one] => Ok(Some(one.to_string())),
        _ => Err(Error::bad_file(
            flight.label(),
            format!(
                "has the columns {} that all read as `{name}` without regard to case: choose one with {flag}",
                same.join(", ")
            ),
        )),
    }
}

/// The compensated bases of the flight, in order of preference: `mag_comp`
/// then the `mag_<k>_comp` columns in file order, as the flight spells
/// them.
fn compensated_bases(flight: &Flight) -> Vec<String> {
    let mut bases = vec![crate::compensate::COMPENSATED.to_string()];
    bases.extend(
        flight
            .column_names()
            .into_iter()
            .filter(|c| is_sensor_compensated(c))
            .map(str::to_string),
    );
    bases
}

/// The names a reader must keep for [`default_column`] to see every
/// candidate with the processing `stages` (suffix patterns as
/// [`aeromag_io::ReadOptions`] takes them: `*_comp_level`).
pub fn default_column_fields(stages: &[&str]) -> Vec<String> {
    stages
        .iter()
        .flat_map(|s| {
            [
                format!("{}{s}", crate::compensate::COMPENSATED),
                format!("*_comp{s}"),
                format!("{UNCOMPENSATED}{s}"),
            ]
        })
        .collect()
}

/// The magnetic column a command takes when none is named: for each
/// processing stage in `stages` (suffixes, most processed first; `""` the
/// column itself), the compensated bases (`mag_comp`, then `mag_<k>_comp`
/// in file order) and then the uncompensated `mag`, with the suffix; the
/// first the flight has, without regard to case. `flag` is the option that
/// names a column (`--value`, `--column`), for the messages.
///
/// The warning `[uncompensated-default]` when the column is the
/// uncompensated reading: levelling or gridding the aircraft's own
/// interference is rarely meant, and said so whether the file has
/// compensated columns (named) or none.
///
/// Errors: none of the candidates in the flight (bad input naming them
/// and `flag`), or two columns differing only in case.
pub fn default_column(flight: &Flight, stages: &[&str], flag: &str) -> Result<DefaultColumn> {
    let bases = compensated_bases(flight);
    for stage in stages {
        for base in bases.iter().map(String::as_str).chain([UNCOMPENSATED]) {
            let Some(name) = find_column(flight, &format!("{base}{stage}"), flag)? else {
                continue;
            };
            let warning = (base == UNCOMPENSATED).then(|| {
                let compensated: Vec<String> = stages
                    .iter()
                    .flat_map(|s| bases.iter().map(move |b| format!("{b}{s}")))
                    .filter_map(|c| find_column(flight, &c, flag).ok().flatten())
                    .collect();
                let shown = flight
                    .resolve(&name)
                    .filter(|f| *f != name)
                    .map_or(format!("`{name}`"), |f| format!("`{name}` (`{f}`)"));
                if compensated.is_empty() {
                    format!(
                        "the column taken is {shown}, the uncompensated reading: the file has no compensated column (mag_comp or mag_<k>_comp; `aeromag compensate` writes them); name the column with {flag} if that is meant [uncompensated-default]"
                    )
                } else {
                    format!(
                        "the column taken is {shown}, the uncompensated reading, although the file has the compensated {}: name the column with {flag} [uncompensated-default]",
                        compensated.join(", ")
                    )
                }
            });
            return Ok(DefaultColumn { name, warning });
        }
    }
    let tried: Vec<String> = stages
        .iter()
        .flat_map(|s| {
            [
                format!("{}{s}", crate::compensate::COMPENSATED),
                format!("mag_<k>_comp{s}"),
                format!("{UNCOMPENSATED}{s}"),
            ]
        })
        .collect();
    Err(Error::bad_file(
        flight.label(),
        format!(
            "has none of the magnetic columns {} (choose one with {flag})",
            tried.join(", ")
        ),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use aeromag_io::FlightTable;

    fn flight(names: &[&str]) -> Flight {
        let mut t = FlightTable::new();
        t.add_column("time", vec![0.0, 1.0]).unwrap();
        for n in names {
            t.add_column(n, vec![50_000.0, 50_001.0]).unwrap();
        }
        Flight::from_table(t).unwrap()
    }

    const GRID: [&str; 3] = ["_level_mlev", "_level", ""];

    #[test]
    fn compensated_columns_are_found_in_any_case() {
        let f = flight(&["MAG", "MAG_COMP"]);
        let c = default_column(&f, &[""], "--value").unwrap();
        assert_eq!(c.name, "MAG_COMP");
        assert_eq!(c.warning, None);
        let f = flight(&["MAG", "MAG_COMP", "MAG_COMP_level"]);
        assert_eq!(
            default_column(&f, &GRID, "--column").unwrap().name,
            "MAG_COMP_level"
        );
    }

    #[test]
    fn multi_sensor_compensated_columns_come_before_the_raw_reading() {
        let f = flight(&[
            "mag_1_uc",
            "mag_2_uc",
            "mag_3_comp",
            "mag_1_comp",
            "mag_2_comp",
            "mag_2_grad",
        ]);
        // The first in file order: the first sensor compensate wrote.
        let c = default_column(&f, &[""], "--value").unwrap();
        assert_eq!((c.name.as_str(), c.warning), ("mag_3_comp", None));
        let f = flight(&["mag", "mag_1_comp", "mag_2_comp", "mag_2_comp_level"]);
        assert_eq!(
            default_column(&f, &GRID, "--column").unwrap().name,
            "mag_2_comp_level"
        );
    }

    #[test]
    fn the_raw_reading_is_taken_with_a_named_warning() {
        // Levelled raw beats compensated unlevelled, and says so.
        let f = flight(&["mag", "mag_level", "mag_1_comp"]);
        let c = default_column(&f, &GRID, "--column").unwrap();
        assert_eq!(c.name, "mag_level");
        let w = c.warning.unwrap();
        assert!(
            w.contains("uncompensated") && w.contains("mag_1_comp") && w.contains("--column"),
            "{w}"
        );
        assert!(w.ends_with("[uncompensated-default]"), "{w}");
        let c = default_column(&flight(&["mag"]), &[""], "--value").unwrap();
        let w = c.warning.unwrap();
        assert!(
            w.contains("no compensated column") && w.contains("--value"),
            "{w}"
        );
    }

    #[test]
    fn two_spellings_of_one_name_or_none_are_bad_input() {
        let e = default_column(&flight(&["Mag_Comp", "MAG_COMP"]), &[""], "--value")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("Mag_Comp, MAG_COMP") && e.contains("--value"),
            "{e}"
        );
        let e = default_column(&flight(&["alt"]), &GRID, "--column")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("mag_<k>_comp_level") && e.contains("--column"),
            "{e}"
        );
    }

    #[test]
    fn sensor_compensated_names() {
        assert!(is_sensor_compensated("mag_1_comp"));
        assert!(is_sensor_compensated("MAG_12_COMP"));
        assert!(!is_sensor_compensated("mag_comp"));
        assert!(!is_sensor_compensated("mag_1_comp_level"));
        assert!(!is_sensor_compensated("mag_x_comp"));
    }
}
