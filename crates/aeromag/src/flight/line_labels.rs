//! Line labels as levelling sees them: every distinct label of the `line`
//! column (a number such as `1003.01` or `1020`, or text such as `L1020`,
//! `T901`) gets an integer id, and each line is a survey line or a tie
//! line when that is known.
//!
//! Whether a line is a tie comes from
//! 1. the `line_type` column (0 line, 1 tie; the Geosoft XYZ reader writes
//!    it from `Line`/`Tie` records) when it marks at least one tie: an
//!    export that labels every line `Line` (tie lines too) says nothing
//!    about ties;
//! 2. otherwise the labels themselves when every label starts with `L` or
//!    `T` (any case: `L1020` line, `T901` tie) and one is a tie;
//! 3. and in either case the labels given as ties by the caller (`level
//!    --ties 901,902`), which are ties whatever the file says.
//!
//! When it is known, crossovers are formed only between a line and a tie;
//! otherwise between any two lines that cross.
//!
//! Rows with no label (missing, empty text, or the number 0: turns and
//! transits) are on no line.

use crate::error::{Error, Result};
use crate::flight::Flight;
use aeromag_compensation::levelling::Pairing;

/// Ids (1, 2, …, in order of first appearance) of a flight's line labels.
#[derive(Debug, Clone, PartialEq)]
pub struct LineLabels {
    /// Per row: the id of its label, `0.0` for rows on no line.
    pub ids: Vec<f64>,
    /// The label of id `k` at index `k − 1`, as text (`1003.01`, `L1020`).
    pub labels: Vec<String>,
    /// The label of id `k` as a number, when the `line` column is numeric.
    pub numbers: Option<Vec<f64>>,
    /// Per id, whether it is a tie line; `None` when not known.
    pub ties: Option<Vec<bool>>,
}

impl LineLabels {
    /// The labels of `flight`'s `line` column; `ties` are labels the caller
    /// declares tie lines (see the module docs for the order of the rules).
    /// Errors: no `line` column, a `ties` label that matches no line, or a
    /// `line_type` that is not 0 or 1.
    pub fn of(flight: &Flight, ties: &[String]) -> Result<Self> {
        let column = flight.get("line").ok_or_else(|| {
            Error::bad_file(
                flight.label(),
                "has no `line` column (map one with --columns line=NAME)",
            )
        })?;
        let text: Vec<String> = match (column.values(), column.text()) {
            (Some(v), _) => v
                .iter()
                .map(|&x| {
                    if x.is_nan() || x == 0.0 {
                        String::new()
                    } else {
                        x.to_string()
                    }
                })
                .collect(),
            (None, Some(t)) => t.iter().map(|s| s.trim().to_string()).collect(),
            (None, None) => unreachable!("a column is numeric or text"),
        };
        let mut labels: Vec<String> = Vec::new();
        let mut ids = Vec::with_capacity(text.len());
        let mut kind_of_row: Vec<Option<usize>> = Vec::with_capacity(text.len());
        for t in &text {
            if t.is_empty() || t == "0" {
                ids.push(0.0);
                kind_of_row.push(None);
                continue;
            }
            let k = match labels.iter().position(|l| l.eq_ignore_ascii_case(t)) {
                Some(k) => k,
                None => {
                    labels.push(t.clone());
                    labels.len() - 1
                }
            };
            ids.push((k + 1) as f64);
            kind_of_row.push(Some(k));
        }
        let numbers: Option<Vec<f64>> = column
            .values()
            .and_then(|_| labels.iter().map(|l| l.parse::<f64>().ok()).collect());
        let marked = if let Some(types) = flight.column("line_type") {
            let mut tie = vec![None; labels.len()];
            for (i, k) in kind_of_row.iter().enumerate() {
                let Some(k) = *k else { continue };
                let t = types[i];
                if !(t == 0.0 || t == 1.0) {
                    return Err(flight.bad_value(
                        i,
                        "line_type",
                        format!("{t} is not 0 (line) or 1 (tie)"),
                    ));
                }
                tie[k].get_or_insert(t == 1.0);
            }
            Some(tie.into_iter().map(|t| t.unwrap_or(false)).collect())
        } else {
            None
        };
        let prefixed = || -> Option<Vec<bool>> {
            labels
                .iter()
                .all(|l| matches!(l.as_bytes()[0], b'L' | b'l' | b'T' | b't'))
                .then(|| {
                    labels
                        .iter()
                        .map(|l| matches!(l.as_bytes()[0], b'T' | b't'))
                        .collect()
                })
        };
        // A file that marks no tie says nothing about ties.
        let some_tie = |t: &Vec<bool>| t.contains(&true);
        let marked = marked
            .filter(some_tie)
            .or_else(|| prefixed().filter(some_tie));
        let ties = if ties.is_empty() {
            marked
        } else {
            let mut tie = marked.unwrap_or_else(|| vec![false; labels.len()]);
            for t in ties {
                let hit = labels.iter().enumerate().filter(|(_, l)| {
                    l.eq_ignore_ascii_case(t)
                        || aeromag_io::label_number(t)
                            .is_some_and(|x| aeromag_io::label_number(l) == Some(x))
                });
                let mut any = false;
                for (k, _) in hit {
                    tie[k] = true;
                    any = true;
                }
                if !any {
                    return Err(Error::bad_input(format!(
                        "--ties: no line is labelled '{t}'; labels present: {}",
                        labels.join(", ")
                    )));
                }
            }
            Some(tie)
        };
        Ok(LineLabels {
            ids,
            labels,
            numbers,
            ties,
        })
    }

    /// Which crossings levelling uses: line with tie when the ties are
    /// known, else any two lines.
    pub fn pairing(&self) -> Pairing {
        match &self.ties {
            Some(t) => Pairing::LineWithTie {
                tie_ids: (1..=t.len() as i64)
                    .filter(|k| t[*k as usize - 1])
                    .collect(),
            },
            None => Pairing::AnyTwoLines,
        }
    }

    /// The label of id `id` (`None` for 0 or out of range).
    pub fn label(&self, id: i64) -> Option<&str> {
        let k = usize::try_from(id).ok()?.checked_sub(1)?;
        self.labels.get(k).map(String::as_str)
    }

    /// The label of id `id` as a number (NaN when it has none).
    pub fn number(&self, id: i64) -> f64 {
        let k = usize::try_from(id).ok().and_then(|k| k.checked_sub(1));
        match (&self.numbers, k) {
            (Some(n), Some(k)) => n.get(k).copied().unwrap_or(f64::NAN),
            _ => f64::NAN,
        }
    }
}
