//! Which fields of a file a read keeps ([`Fields`]): every reader (HDF5,
//! CSV, whitespace and XYZ) reads the same fields of the same header, so a
//! command sees the same columns whatever the file's format.

use crate::derive::{DERIVATIONS, DIFFERENCES};
use crate::{Fields, ReadOptions};

/// The canonical aliases of a binary file's fields `header` (mapped as a
/// CSV header is) and which of them to read ([`wanted_fields`]).
pub(crate) fn mapped_fields(
    file: &str,
    header: &[String],
    opts: &ReadOptions,
) -> crate::Result<(Vec<crate::MappedColumn>, Vec<bool>)> {
    let aliases = crate::columns::resolve(
        file,
        header,
        &opts.columns,
        &opts.sensors,
        opts.magnav_preset,
    )?;
    let wanted = wanted_fields(header, &aliases, opts);
    Ok((aliases, wanted))
}

/// Which of the file's fields to read: all, or those [`Fields::Only`] names
/// (a file name, a canonical name through its alias, the source of a
/// derived canonical column), plus `line`/`time` for a row selection; the
/// first field when none of those is in the file (the readers count rows
/// from a field read).
pub(crate) fn wanted_fields(
    header: &[String],
    aliases: &[crate::MappedColumn],
    opts: &ReadOptions,
) -> Vec<bool> {
    let Fields::Only(names) = &opts.fields else {
        return vec![true; header.len()];
    };
    let mut asked: Vec<&str> = names.iter().map(String::as_str).collect();
    if !opts.rows.lines.is_empty() {
        asked.extend(["line", "line_type"]);
    }
    if opts.rows.time_range.is_some() {
        asked.push("time");
    }
    let mut wanted: Vec<bool> = header
        .iter()
        .map(|h| {
            asked.iter().any(|a| {
                name_matches(h, a)
                    || aliases
                        .iter()
                        .any(|m| m.canonical == *a && m.file_column == *h)
                    || DERIVATIONS.iter().any(|(c, sources, _)| {
                        c == a && sources.iter().any(|s| h.eq_ignore_ascii_case(s))
                    })
                    || DIFFERENCES
                        .iter()
                        .any(|(c, x, y)| c == a && (name_matches(h, x) || name_matches(h, y)))
            })
        })
        .collect();
    if !wanted.contains(&true)
        && let Some(first) = wanted.first_mut()
    {
        *first = true;
    }
    wanted
}

/// `name` against an asked name without regard to case; an asked name
/// ending in `*` is a prefix (`true_*`), one starting with `*` a suffix
/// (`*_level`).
fn name_matches(name: &str, asked: &str) -> bool {
    let same = |a: Option<&str>, b: &str| a.is_some_and(|a| a.eq_ignore_ascii_case(b));
    if let Some(prefix) = asked.strip_suffix('*') {
        same(name.get(..prefix.len()), prefix)
    } else if let Some(suffix) = asked.strip_prefix('*') {
        same(
            name.len()
                .checked_sub(suffix.len())
                .and_then(|i| name.get(i..)),
            suffix,
        )
    } else {
        // The SGL field in either naming (`cur_com_1` reads `CUR_COM1`).
        crate::columns::sensor_names(asked)
            .iter()
            .any(|n| name.eq_ignore_ascii_case(n))
    }
}
