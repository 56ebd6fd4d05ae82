//! A MATLAB workspace as a flight: which variables of a MAT-file are the
//! flight's fields, whether the file is a v5 one ([`crate::read_mat5`]) or
//! a v7.3 one, which is HDF5 ([`crate::read_hdf5`]). Both readers describe
//! the file's variables as [`Value`]s, the numbers left where they are
//! (`D`: read already, or an HDF5 dataset read only when asked for), and
//! [`flight_of`] picks the fields:
//!
//! - Numeric vectors (1 × n, n × 1) at the top level: a workspace saved
//!   with `save(file, 'time', 'mag', …)`, as an HDF5 file's root datasets
//!   (or aeromag's `--out X.mat`; a top level of scalars and no struct is a
//!   one-row table).
//! - Without those, the fields of a 1 × 1 struct. MagNav.jl's layout
//!   (`get_XYZ0`'s `traj_field` and `ins_field`, "the standard way the
//!   MATLAB-companion outputs data"): the struct `traj`, and the INS
//!   fields in the struct `ins_data` without their `ins_` prefix, which is
//!   put back (`ins_data.lat` → `ins_lat`, the name in MagNav's HDF5 files).
//!   Otherwise the one struct there is; several structs without `traj` are
//!   an error naming them.
//! - Of those, the numeric vectors of the longest length are the fields
//!   (`double`, `single`, integer classes and `logical`, read exactly as
//!   `f64`; integer classes are written back as integers), and the `char`
//!   matrices of as many rows (text columns, each row's padding spaces
//!   removed). The other variables there (scalars such as a sample rate
//!   `fs`, text, matrices such as MagNav's 1000 × 18 design matrix `A_a` or
//!   its 3 × 3 × n `Cnb`, vectors of another length, complex arrays, cells,
//!   objects) are not fields: they are listed in
//!   [`FlightTable::not_read`](crate::FlightTable::not_read), which
//!   `aeromag inspect` prints, never dropped silently.
//! - A MagNav.jl map (`map`, `xx`, `yy`) is refused as not a flight.

use std::path::Path;

use crate::ReadOptions;
use crate::error::{IoError, Result};
use crate::table::{ColumnData, FlightTable, NotRead};
use crate::wanted::mapped_fields;

/// What a MagNav.jl map file (HDF5 or MAT: `map`, `xx`, `yy`) is, for the
/// messages refusing it as a flight.
pub(crate) const MAGNAV_MAP: &str = "a MagNav.jl map (`map`, `xx`, `yy`), not a flight table; \
     aeromag reads grids from GeoTIFF, GXF, ESRI ASCII, netCDF and Surfer files";

/// A variable of a MAT-file: what a flight table can hold, or what it is.
/// `dims` are MATLAB's (rows first).
#[derive(Debug)]
pub(crate) enum Value<D> {
    /// A real numeric array: its values (`D`), of `dims`' product.
    Numeric {
        dims: Vec<usize>,
        data: D,
        /// An integer class (or `logical`): written back as integers.
        integer: bool,
        /// Its value when it is a scalar (a sample rate `fs`, shown in
        /// [`NotRead`]), if read.
        scalar: Option<f64>,
    },
    /// A 1 × 1 struct: its fields in file order.
    Struct(Variables<D>),
    /// A 2-D `char` array: its rows, the spaces that pad them removed.
    Text { dims: Vec<usize>, rows: Vec<String> },
    /// Anything else, described for [`NotRead`]: a struct array, a cell, a
    /// complex or sparse array, an object, an empty array.
    Other { dims: Vec<usize>, what: String },
}

/// A workspace's (or a struct's) variables: names and values, in order.
pub(crate) type Variables<D> = Vec<(String, Value<D>)>;

/// `dims` as MATLAB writes them: `1000 × 18`.
pub(crate) fn dims_text(dims: &[usize]) -> String {
    dims.iter()
        .map(usize::to_string)
        .collect::<Vec<_>>()
        .join(" × ")
}

/// A 2-D `char` array of `dims` from its UTF-16 code units in MATLAB's
/// column-major order: its rows, each row's padding spaces removed.
/// Errors: not as many units as the dimensions say.
pub(crate) fn text_value<D>(
    dims: Vec<usize>,
    units: &[u16],
) -> std::result::Result<Value<D>, String> {
    let count = dims.iter().try_fold(1usize, |a, &d| a.checked_mul(d));
    if dims.len() != 2 || count != Some(units.len()) {
        return Err(format!(
            "holds {} characters where its dimensions are {}: damaged",
            units.len(),
            dims_text(&dims)
        ));
    }
    // Row i's characters are i, i + n, i + 2n, …
    let n = dims[0];
    let rows = (0..n)
        .map(|i| {
            let row: Vec<u16> = units.iter().skip(i).step_by(n).copied().collect();
            String::from_utf16_lossy(&row)
                .trim_end_matches(' ')
                .to_string()
        })
        .collect();
    Ok(Value::Text { dims, rows })
}

/// The length of a vector (every dimension but one is 1), `None` for a
/// matrix. A scalar is a vector of 1, an empty array of 0.
pub(crate) fn vector_len(dims: &[usize]) -> Option<usize> {
    if dims.contains(&0) {
        return Some(0);
    }
    let mut long = dims.iter().filter(|&&d| d != 1);
    match (long.next(), long.next()) {
        (None, _) => Some(1),
        (Some(&n), None) => Some(n),
        _ => None,
    }
}

impl<D> Value<D> {
    /// The length of a numeric vector, `None` for anything else.
    fn numeric_len(&self) -> Option<usize> {
        match self {
            Value::Numeric { dims, .. } => vector_len(dims),
            _ => None,
        }
    }

    /// What this variable is, for [`NotRead::what`].
    fn describe(&self) -> String {
        match self {
            Value::Numeric { dims, scalar, .. } => match vector_len(dims) {
                Some(1) => match scalar {
                    Some(v) => format!("a scalar, {}", aeromag_core::error::shown(*v)),
                    None => "a scalar".into(),
                },
                Some(n) => format!("a vector of {n} values"),
                None => format!("a {} matrix", dims_text(dims)),
            },
            Value::Struct(_) => "a struct".into(),
            Value::Text { dims, .. } => format!("text ({})", dims_text(dims)),
            Value::Other { dims, what } => format!("{what} ({})", dims_text(dims)),
        }
    }
}

/// A field of the flight: numbers (`D`, and whether integers) or text.
enum Field<D> {
    Numbers(D, bool),
    Text(Vec<String>),
}

/// The flight a workspace holds: its fields named as columns, in file
/// order, their rows, and the variables that are not fields.
pub(crate) struct Workspace<D> {
    fields: Vec<(String, Field<D>)>,
    n_rows: usize,
    not_read: Vec<NotRead>,
}

impl<D> Workspace<D> {
    /// The flight table of the file `path`: its fields mapped like a CSV
    /// header, those [`ReadOptions::fields`] asks for read; `check` sees
    /// the rows and which fields (`true`: read) before any is, `read` gives
    /// a field's numbers (checked to be the rows), errors naming the
    /// variable.
    pub(crate) fn into_table(
        self,
        path: &Path,
        opts: &ReadOptions,
        check: impl FnOnce(usize, &[bool]) -> Result<()>,
        mut read: impl FnMut(D) -> std::result::Result<Vec<f64>, String>,
    ) -> Result<FlightTable> {
        let file = path.display().to_string();
        let mat = |variable: &str, message: String| IoError::Mat {
            file: file.clone(),
            variable: Some(variable.to_string()),
            message,
        };
        let header: Vec<String> = self.fields.iter().map(|f| f.0.clone()).collect();
        let (aliases, wanted) = mapped_fields(&file, &header, opts)?;
        check(self.n_rows, &wanted)?;
        let mut columns = Vec::new();
        for ((name, field), want) in self.fields.into_iter().zip(wanted) {
            if !want {
                continue;
            }
            let (data, integer) = match field {
                Field::Text(rows) => (ColumnData::Text(rows), false),
                Field::Numbers(data, integer) => {
                    let values = read(data).map_err(|m| mat(&name, m))?;
                    if values.len() != self.n_rows {
                        let m = format!(
                            "holds {} values where its dimensions say {}: damaged",
                            values.len(),
                            self.n_rows
                        );
                        return Err(mat(&name, m));
                    }
                    (ColumnData::numeric(values), integer)
                }
            };
            columns.push((name, data, integer));
        }
        let mut table = FlightTable::from_fields(path, self.n_rows, columns, aliases, header);
        table.set_not_read(self.not_read);
        Ok(table)
    }
}

/// An error naming the variable concerned (if one) and what.
pub(crate) type WorkspaceError = (Option<String>, String);

/// The flight in the file's `variables` (module docs).
pub(crate) fn flight_of<D>(
    variables: Variables<D>,
) -> std::result::Result<Workspace<D>, WorkspaceError> {
    let (chosen, mut not_read) = choose(variables).map_err(|m| (None, m))?;
    let has = |name: &str, matrix: bool| {
        chosen.iter().any(|c| {
            c.name == name
                && matches!(&c.value, Value::Numeric { dims, .. }
                    if vector_len(dims).is_none() == matrix)
        })
    };
    if has("map", true) && has("xx", false) && has("yy", false) {
        return Err((None, format!("holds {MAGNAV_MAP}")));
    }
    // The fields: the numeric vectors of the longest length …
    let n_rows = chosen
        .iter()
        .filter_map(|c| c.value.numeric_len())
        .max()
        .unwrap_or(0);
    if n_rows == 0 {
        // A MATLAB table (`readtable`'s) is an object whose layout the
        // format does not document: what to save instead.
        if let Some(c) = chosen.iter().find(|c| {
            matches!(&c.value, Value::Other { what, .. }
                if what.ends_with(" table object") || what.ends_with(" timetable object"))
        }) {
            let n = &c.path;
            return Err((
                Some(n.clone()),
                format!(
                    "is a MATLAB table, an object aeromag does not read from a MAT-file: save \
                     its columns as vectors (`s = table2struct({n}, 'ToScalar', true); \
                     save(file, '-struct', 's')`) or as CSV (`writetable({n}, 'flight.csv')`)"
                ),
            ));
        }
        return Err((
            None,
            "holds no numeric vector (a flight's fields are vectors, 1 × n or n × 1, at the \
             top level or in a struct)"
                .into(),
        ));
    }
    // … and the text of as many rows (an n × k `char` matrix).
    let mut fields: Vec<(String, Field<D>)> = Vec::new();
    for Candidate { name, path, value } in chosen {
        let field = match value {
            Value::Numeric {
                dims,
                data,
                integer,
                ..
            } if vector_len(&dims) == Some(n_rows) => Field::Numbers(data, integer),
            Value::Text { rows, .. } if rows.len() == n_rows => Field::Text(rows),
            other => {
                not_read.push(NotRead {
                    name: path,
                    what: other.describe(),
                });
                continue;
            }
        };
        if fields.iter().any(|f| f.0 == name) {
            return Err((
                Some(name),
                "is given twice (a `traj` field and an `ins_data` field of the same name?)".into(),
            ));
        }
        fields.push((name, field));
    }
    Ok(Workspace {
        fields,
        n_rows,
        not_read,
    })
}

/// A variable the flight's fields are taken from: its name as a field,
/// its path in the file (`traj.lat`) and its value.
struct Candidate<D> {
    name: String,
    path: String,
    value: Value<D>,
}

/// The variables the flight's fields come from (module docs), and the
/// variables passed over.
fn choose<D>(
    variables: Variables<D>,
) -> std::result::Result<(Vec<Candidate<D>>, Vec<NotRead>), String> {
    let is_vector = |v: &Value<D>| v.numeric_len().is_some_and(|n| n > 1);
    let is_struct = |v: &Value<D>| matches!(v, Value::Struct(_));
    let passed_over = |name: String, v: &Value<D>| NotRead {
        name,
        what: v.describe(),
    };
    let mut not_read = Vec::new();
    let mut chosen = Vec::new();
    // The top level: with a vector, or with no struct (a one-row table is
    // a workspace of scalars).
    if variables.iter().any(|(_, v)| is_vector(v)) || !variables.iter().any(|(_, v)| is_struct(v)) {
        // The top level's variables; its structs are not fields.
        for (name, value) in variables {
            if is_struct(&value) {
                not_read.push(passed_over(name, &value));
            } else {
                chosen.push(Candidate {
                    path: name.clone(),
                    name,
                    value,
                });
            }
        }
        return Ok((chosen, not_read));
    }
    let struct_names: Vec<&str> = variables
        .iter()
        .filter(|(_, v)| is_struct(v))
        .map(|(n, _)| n.as_str())
        .collect();
    let picked: Vec<String> = if struct_names.contains(&"traj") {
        ["traj", "ins_data"]
            .into_iter()
            .filter(|n| struct_names.contains(n))
            .map(str::to_string)
            .collect()
    } else if struct_names.len() == 1 {
        vec![struct_names[0].to_string()]
    } else {
        return Err(format!(
            "holds {} structs ({}) and no vector at the top level: save the flight's struct \
             alone (`s = data.flight; save(file, '-struct', 's')`), or name it `traj` as \
             MagNav.jl does",
            struct_names.len(),
            struct_names.join(", ")
        ));
    };
    for (name, value) in variables {
        match value {
            Value::Struct(members) if picked.contains(&name) => {
                let prefix = if name == "ins_data" { "ins_" } else { "" };
                for (field, value) in members {
                    chosen.push(Candidate {
                        name: format!("{prefix}{field}"),
                        path: format!("{name}.{field}"),
                        value,
                    });
                }
            }
            other => not_read.push(passed_over(name, &other)),
        }
    }
    Ok((chosen, not_read))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn vectors_scalars_and_matrices_are_told_apart() {
        assert_eq!(vector_len(&[1, 100]), Some(100));
        assert_eq!(vector_len(&[100, 1]), Some(100));
        assert_eq!(vector_len(&[1, 1, 7]), Some(7));
        assert_eq!(vector_len(&[1, 1]), Some(1));
        assert_eq!(vector_len(&[0, 0]), Some(0));
        assert_eq!(vector_len(&[1000, 18]), None);
        assert_eq!(vector_len(&[3, 3, 100]), None);
    }
}
