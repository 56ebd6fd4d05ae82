//! MATLAB v7.3 MAT-files: HDF5 after a 512-byte user block beginning
//! `MATLAB 7.3 MAT-file`, as MATLAB's `save(file, '-v7.3')` writes them
//! (needed for variables over 2 GB) and `hdf5storage` in Python. Their
//! flight is the one [`crate::matlab`] finds in a v5 file of the same
//! workspace; the numbers of a field are read only when the field is asked
//! for.
//!
//! The layout MATLAB gives them: a variable is a dataset at the root, its
//! class in the attribute `MATLAB_class` (`double`, `uint8`, `logical`,
//! `char`, …), its dimensions the dataset's reversed (a 1 × n vector is an
//! n × 1 dataset), its values in MATLAB's column-major order; `char` is
//! UTF-16 code units; an empty array has `MATLAB_empty` set (its data are
//! its dimensions); a struct is a group of its fields; `#refs#` and
//! `#subsystem#` (cells' and objects' data) are not variables. HDF5 does
//! not keep MATLAB's order of variables and fields: they come in name
//! order.

use hdf5_reader::{Dataset, Datatype, group::Group};

use crate::matlab::{Value, Variables, WorkspaceError, text_value};

/// The start of a MATLAB v7.3 MAT-file (its user block's text).
pub(crate) const SIGNATURE: &[u8] = b"MATLAB 7.3 MAT-file";

/// The variables of `group` (the file's root, or a struct), in name
/// order; `path` names it in errors (`""` for the root).
pub(crate) fn variables(
    group: &Group,
    path: &str,
    depth: usize,
) -> Result<Variables<Dataset>, WorkspaceError> {
    let at = |name: &str| {
        if path.is_empty() {
            name.to_string()
        } else {
            format!("{path}.{name}")
        }
    };
    if depth > crate::mat5::MAX_DEPTH {
        return Err((
            Some(path.to_string()),
            format!(
                "structs nest deeper than {} levels: damaged",
                crate::mat5::MAX_DEPTH
            ),
        ));
    }
    let h5 = |name: Option<String>| move |e: hdf5_reader::error::Error| (name, e.to_string());
    let (groups, datasets) = group.member_names().map_err(h5(None))?;
    let mut names: Vec<(String, bool)> = groups
        .into_iter()
        .map(|g| (g, true))
        .chain(datasets.into_iter().map(|d| (d, false)))
        .filter(|(n, _)| !n.starts_with('#'))
        .collect();
    names.sort();
    let mut out = Vec::with_capacity(names.len());
    for (name, is_group) in names {
        let path = at(&name);
        let value = if is_group {
            let g = group.group(&name).map_err(h5(Some(path.clone())))?;
            Value::Struct(variables(&g, &path, depth + 1)?)
        } else {
            let ds = group.dataset(&name).map_err(h5(Some(path.clone())))?;
            value(ds).map_err(|m| (Some(path.clone()), m))?
        };
        out.push((name, value));
    }
    Ok(out)
}

/// The variable a dataset holds (module docs).
fn value(ds: Dataset) -> Result<Value<Dataset>, String> {
    let attr = |name: &str| ds.attribute(name).ok();
    let class = attr("MATLAB_class").and_then(|a| a.read_string().ok());
    let mut dims: Vec<usize> = ds.shape().iter().rev().map(|&d| d as usize).collect();
    if dims.len() == 1 {
        // Not MATLAB's (h5py's 1-D): a column.
        dims.push(1);
    }
    let empty = attr("MATLAB_empty")
        .and_then(|a| a.read_as_f64().ok())
        .is_some_and(|e| e != 0.0);
    let other = |dims: Vec<usize>, what: &str| {
        Ok(Value::Other {
            dims,
            what: what.to_string(),
        })
    };
    if empty {
        return other(vec![0, 0], "an empty array");
    }
    match class.as_deref() {
        Some("char") => {
            let units = ds
                .read_array::<u16>()
                .map_err(|e| e.to_string())?
                .into_raw_vec_and_offset()
                .0;
            text_value(dims, &units)
        }
        Some("cell") => other(dims, "a cell array"),
        Some("struct") => other(dims, "a struct array"),
        Some(
            "double" | "single" | "int8" | "uint8" | "int16" | "uint16" | "int32" | "uint32"
            | "int64" | "uint64" | "logical",
        )
        | None => match ds.dtype() {
            Datatype::FloatingPoint { .. } | Datatype::FixedPoint { .. } => {
                let integer = match class.as_deref() {
                    Some(c) => !matches!(c, "double" | "single"),
                    None => matches!(ds.dtype(), Datatype::FixedPoint { .. }),
                };
                // A scalar's one value is read to be shown.
                let one = dims.iter().try_fold(1usize, |a, &d| a.checked_mul(d)) == Some(1);
                let scalar = one
                    .then(|| crate::hdf5::read_f64(&ds).ok())
                    .flatten()
                    .and_then(|(v, _)| v.first().copied());
                Ok(Value::Numeric {
                    dims,
                    data: ds,
                    integer,
                    scalar,
                })
            }
            Datatype::Compound { .. } => other(dims, "a complex array"),
            _ => other(dims, "an array of a type not read here"),
        },
        Some(c) => other(dims, &format!("a MATLAB {c} object")),
    }
}
