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

use std::collections::HashMap;

use crate::error::{Error, Result};
use crate::flight::Flight;
use aeromag_compensation::levelling::Pairing;
use aeromag_core::error::shown;

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
                        shown(x)
                    }
                })
                .collect(),
            (None, Some(t)) => t.iter().map(|s| s.trim().to_string()).collect(),
            (None, None) => unreachable!("a column is numeric or text"),
        };
        let mut labels: Vec<String> = Vec::new();
        // Label (lower case) → index in `labels`: one lookup per run of
        // equal labels, however many lines the file has.
        let mut index: HashMap<String, usize> = HashMap::new();
        let mut previous: Option<(&str, Option<usize>)> = None;
        let mut ids = Vec::with_capacity(text.len());
        let mut kind_of_row: Vec<Option<usize>> = Vec::with_capacity(text.len());
        for t in &text {
            let kind = match previous {
                Some((p, kind)) if p == t => kind,
                _ => {
                    // A text column's `0`, `0.0`, `-0`: the number 0, no line.
                    let kind = if t.is_empty() || t.parse::<f64>() == Ok(0.0) {
                        None
                    } else {
                        let n = labels.len();
                        let k = *index.entry(t.to_ascii_lowercase()).or_insert(n);
                        if k == n {
                            labels.push(t.clone());
                        }
                        Some(k)
                    };
                    previous = Some((t, kind));
                    kind
                }
            };
            ids.push(kind.map_or(0.0, |k| (k + 1) as f64));
            kind_of_row.push(kind);
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

#[cfg(test)]
mod tests {
    use super::*;
    use aeromag_io::FlightTable;

    fn flight(line: std::result::Result<Vec<f64>, Vec<&str>>) -> Flight {
        let mut t = FlightTable::new();
        let n = match &line {
            Ok(v) => v.len(),
            Err(s) => s.len(),
        };
        t.add_column("time", (0..n).map(|k| k as f64).collect())
            .unwrap();
        match line {
            Ok(v) => t.add_column("line", v).unwrap(),
            Err(s) => t
                .add_text_column("line", s.iter().map(|s| s.to_string()).collect())
                .unwrap(),
        }
        Flight::from_table(t).unwrap()
    }

    /// A text `line` column (one label such as `L7` or `abc` makes the
    /// whole column text) keeps its turns off the lines: `0.0` was a line
    /// of its own, and levelling formed crossovers with the turns.
    #[test]
    fn a_text_zero_is_no_line() {
        let f = flight(Err(vec!["0.0", "1001.0", "1001.0", "-0", "abc", "0", ""]));
        let l = LineLabels::of(&f, &[]).unwrap();
        assert_eq!(l.labels, vec!["1001.0", "abc"]);
        assert_eq!(l.ids, vec![0.0, 1.0, 1.0, 0.0, 2.0, 0.0, 0.0]);
    }

    /// A label near f64's limit is named in exponent form (it was written
    /// with 309 digits in `level`'s line table) and still matches `--ties`.
    #[test]
    fn a_huge_numeric_label_is_named_shortly() {
        let f = flight(Ok(vec![1e308, 1e308, 0.0, 1003.01]));
        let l = LineLabels::of(&f, &["1e308".to_string()]).unwrap();
        assert_eq!(l.labels, vec!["1e308", "1003.01"]);
        assert_eq!(l.number(1), 1e308);
        assert_eq!(l.ties, Some(vec![true, false]));
    }

    /// Labels are found by a map, not by a search of all labels per row:
    /// 200 000 rows with a label each took 42 s in `aeromag level`. Case
    /// does not make a new label.
    #[test]
    fn many_labels_in_one_pass() {
        let n = 200_000;
        let v: Vec<String> = (0..n).map(|k| format!("L{k}")).collect();
        let mut s: Vec<&str> = v.iter().map(String::as_str).collect();
        s.push("l7");
        let t0 = std::time::Instant::now();
        let l = LineLabels::of(&flight(Err(s)), &[]).unwrap();
        assert_eq!(l.labels.len(), n);
        assert_eq!(l.ids[n], 8.0);
        assert!(t0.elapsed().as_secs_f64() < 10.0, "{:?}", t0.elapsed());
    }
}
