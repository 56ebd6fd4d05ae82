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
//! Rows with no label (missing, empty text, `NaN`, `*`, or the number 0:
//! turns and transits) are on no line.
//!
//! For levelling ([`LineLabels::per_pass`]), a label flown in separate
//! passes (another line's rows between them: a re-flight exported under
//! the first flight's label) is one line per pass, `1003`, `1003 (pass
//! 2)`, …: each pass has its own level error, and with one offset for the
//! label a re-flight kept its own.
//!
//! Labels are names: `1003.1` and `1003.10` (Geosoft line 1003, versions 1
//! and 10) are two lines, as the readers keep them (a `line` column with
//! such a pair is read as text).

use crate::error::{Error, Result};
use crate::flight::Flight;
use aeromag_compensation::levelling::Pairing;
use aeromag_core::error::shown;

/// Ids (1, 2, …, in order of first appearance) of a flight's line labels.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct LineLabels {
    /// Per row: the id of its line, `0.0` for rows on no line. The labels
    /// have ids 1, 2, … in order of first appearance; per pass
    /// ([`LineLabels::per_pass`]) the later passes of a label flown more
    /// than once follow, in order of their start.
    pub ids: Vec<f64>,
    /// The label of id `k` at index `k − 1`, as text (`1003.01`, `L1020`;
    /// a later pass `1003.01 (pass 2)`).
    pub labels: Vec<String>,
    /// The label of id `k` as a number, when the `line` column is numeric
    /// (a later pass has its label's).
    pub numbers: Option<Vec<f64>>,
    /// Per id, whether it is a tie line; `None` when not known.
    pub ties: Option<Vec<bool>>,
    /// Rows whose label is missing (empty, `NaN`, `*`; not the 0 of a
    /// turn), and the first of them: on no line, which a file seldom means
    /// ([`LineLabels::missing_warning`]).
    pub missing: (usize, Option<usize>),
    /// Labels flown in more than one pass (their rows interrupted by
    /// another line's): `(id of the first pass, passes, first row of the
    /// second pass)` ([`LineLabels::repeated_warning`]).
    pub repeated: Vec<(i64, usize, usize)>,
}

impl LineLabels {
    /// The labels of `flight`'s `line` column; `ties` are labels the caller
    /// declares tie lines (see the module docs for the order of the rules).
    /// Errors: no `line` column, a `ties` label that matches no line, or a
    /// `line_type` that is not 0 or 1.
    ///
    /// A label flown in separate passes is one line here (gridding and
    /// micro-levelling see a track, and a line re-flown on the same track
    /// must not halve the line spacing); [`LineLabels::per_pass`] parts it.
    pub fn of(flight: &Flight, ties: &[String]) -> Result<Self> {
        Self::build(flight, ties, false)
    }

    /// [`LineLabels::of`] with each later pass of a label flown more than
    /// once a line of its own (`1003 (pass 2)`), as levelling needs: each
    /// pass has its own level error.
    pub fn per_pass(flight: &Flight, ties: &[String]) -> Result<Self> {
        Self::build(flight, ties, true)
    }

    fn build(flight: &Flight, ties: &[String], per_pass: bool) -> Result<Self> {
        let column = flight.get("line").ok_or_else(|| {
            Error::bad_file(
                flight.label(),
                "has no `line` column (map one with --columns line=NAME)",
            )
        })?;
        // Per row the label's number (NaN missing, 0 no line, k the k-th
        // distinct label), and the labels; a number as it is shown.
        let number_labels = aeromag_io::select::number_labels;
        let (numbered, labels) = match (column.values(), column.text()) {
            (Some(v), _) => {
                let text: Vec<String> = v
                    .iter()
                    .map(|&x| match x {
                        x if x.is_nan() => String::new(),
                        0.0 => "0".to_string(),
                        x => shown(x),
                    })
                    .collect();
                number_labels(text.iter().map(String::as_str))
            }
            (None, Some(t)) => number_labels(t.iter().map(String::as_str)),
            (None, None) => unreachable!("a column is numeric or text"),
        };
        let mut ids = Vec::with_capacity(numbered.len());
        let mut kind_of_row: Vec<Option<usize>> = Vec::with_capacity(numbered.len());
        let mut missing = (0, None);
        // Per label: its passes and the first row of its second; the label
        // of the last row on a line; the later passes, each `(label, pass,
        // first row)`, in order of their start.
        let mut passes: Vec<(usize, usize)> = Vec::new();
        let mut last_on_line: Option<usize> = None;
        let mut later_passes: Vec<(usize, usize, usize)> = Vec::new();
        for (row, &id) in numbered.iter().enumerate() {
            let kind = (id > 0.0).then(|| id as usize - 1);
            if id.is_nan() {
                missing.0 += 1;
                missing.1.get_or_insert(row);
            }
            if let Some(k) = kind
                && last_on_line != Some(k)
            {
                if k == passes.len() {
                    passes.push((1, 0));
                } else {
                    let (n, second) = &mut passes[k];
                    *n += 1;
                    if *n == 2 {
                        *second = row;
                    }
                    later_passes.push((k, *n, row));
                }
                last_on_line = Some(k);
            }
            // A later pass of label `k` is the line of its own appended
            // below; the id is set there.
            let pass_id = match (kind, later_passes.last()) {
                (Some(k), Some(&(l, _, _))) if per_pass && l == k && passes[k].0 > 1 => {
                    (labels.len() + later_passes.len()) as f64
                }
                _ => kind.map_or(0.0, |k| (k + 1) as f64),
            };
            ids.push(pass_id);
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
                // The label as written; else as a number (`901` for `T901`),
                // unless labels differ as text only (`1003.1`, `1003.10`).
                let as_text = labels.iter().any(|l| l.eq_ignore_ascii_case(t));
                let hit = labels.iter().enumerate().filter(|(_, l)| {
                    l.eq_ignore_ascii_case(t)
                        || (!as_text
                            && aeromag_io::label_number(t)
                                .is_some_and(|x| aeromag_io::label_number(l) == Some(x)))
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
        let repeated = passes
            .iter()
            .enumerate()
            .filter(|(_, p)| p.0 > 1)
            .map(|(k, &(n, second))| (k as i64 + 1, n, second))
            .collect();
        // Each later pass is a line of its own, of its label's kind.
        let mut labels = labels;
        let mut numbers = numbers;
        let mut ties = ties;
        for &(k, pass, _) in later_passes.iter().filter(|_| per_pass) {
            labels.push(format!("{} (pass {pass})", labels[k]));
            if let Some(n) = &mut numbers {
                n.push(n[k]);
            }
            if let Some(t) = &mut ties {
                t.push(t[k]);
            }
        }
        Ok(LineLabels {
            ids,
            labels,
            numbers,
            ties,
            missing,
            repeated,
        })
    }

    /// The warning for labels flown in more than one pass (`None` when
    /// there are none), named `[line-repeated]`: each pass is a line of its
    /// own (`7 (pass 2)`), which the file may not mean. A pass ends where
    /// another line's rows begin (turns, labelled 0, and rows without a
    /// label do not end it).
    pub fn repeated_warning(&self, flight: &Flight) -> Option<String> {
        const SHOWN: usize = 5;
        let first = self.repeated.first()?;
        let n = self.repeated.len();
        let listed: Vec<String> = self.repeated[..n.min(SHOWN)]
            .iter()
            .map(|&(id, passes, second)| {
                format!(
                    "{} ({passes} passes, the second from data row {})",
                    self.label(id).unwrap_or_default(),
                    flight.file_row(second) + 1
                )
            })
            .collect();
        let more = if n > SHOWN {
            format!(" and {} more", n - SHOWN)
        } else {
            String::new()
        };
        let example = self.label(first.0).unwrap_or_default();
        Some(format!(
            "{} of '{}' {} flown in separate passes, another line's rows between them: {}{more}; each pass is taken as a line of its own ('{example} (pass 2)'), as a re-flight has its own level error: label re-flights apart ({example}.01, as Geosoft's LINE.VERSION) to name them [line-repeated]",
            if n == 1 { "a line" } else { "lines" },
            flight.label(),
            if n == 1 { "is" } else { "are" },
            listed.join(", "),
        ))
    }

    /// The warning for rows whose label is missing (`None` when there are
    /// none), named `[line-missing]`: levelling and gridding leave them
    /// out as they leave turns out, so a line whose labels were lost
    /// would go unlevelled and ungridded without a word.
    pub fn missing_warning(&self, flight: &Flight) -> Option<String> {
        let (n, first) = self.missing;
        let first = first?;
        Some(format!(
            "{n} {} of '{}' {} no line label (empty, NaN or *; the first at data row {}): {} on no line, as turns are, and left out; label {} (0 for turns) [line-missing]",
            if n == 1 { "row" } else { "rows" },
            flight.label(),
            if n == 1 { "has" } else { "have" },
            flight.file_row(first) + 1,
            if n == 1 { "it is" } else { "they are" },
            if n == 1 { "it" } else { "them" },
        ))
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
        assert_eq!(l.missing, (1, Some(6)));
        let numeric = LineLabels::of(&flight(Ok(vec![0.0, 7.0, f64::NAN, f64::NAN])), &[]).unwrap();
        assert_eq!(numeric.missing, (2, Some(2)));
        let none = LineLabels::of(&flight(Ok(vec![0.0, 7.0, -0.0])), &[]).unwrap();
        assert_eq!(none.missing_warning(&flight(Ok(vec![0.0]))), None);
    }

    /// Labels that are one number in two texts, read from a file: two
    /// lines (they were one, levelled with one offset), `--ties` picks the
    /// one written so, and missing markers are no line.
    #[test]
    fn one_number_in_two_texts_is_two_lines() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("v.csv");
        let mut text = String::from("time,line\n");
        for (k, l) in ["1003.1", "1003.1", "NaN", "1003.10", "*", "901", "0"]
            .iter()
            .enumerate()
        {
            text.push_str(&format!("{k},{l}\n"));
        }
        std::fs::write(&path, text).unwrap();
        let f = Flight::read(&path).unwrap();
        let l = LineLabels::of(&f, &["1003.1".to_string()]).unwrap();
        assert_eq!(l.labels, vec!["1003.1", "1003.10", "901"]);
        assert_eq!(l.ids, vec![1.0, 1.0, 0.0, 2.0, 0.0, 3.0, 0.0]);
        assert_eq!(l.ties, Some(vec![true, false, false]));
        // `NaN` and `*` are missing labels, the `0` a turn.
        assert_eq!(l.missing, (2, Some(2)));
        let w = l.missing_warning(&f).unwrap();
        assert!(w.contains("2 rows of") && w.contains("data row 3"), "{w}");
        assert!(w.ends_with("[line-missing]"), "{w}");
        // A label given as a number still finds its text (`901`, `T901`).
        let by_number = LineLabels::of(&f, &["T901".to_string()]).unwrap();
        assert_eq!(by_number.ties, Some(vec![false, false, true]));
    }

    /// A label whose rows another line's interrupt is flown twice (the
    /// re-flight kept the first flight's level error, silently): each pass
    /// is a line, and the warning names them; turns (0) and rows without a
    /// label between its rows do not part it.
    #[test]
    fn a_label_flown_twice_is_named_and_parted() {
        let once = flight(Ok(vec![7.0, 7.0, 0.0, 7.0, f64::NAN, 7.0, 8.0, 8.0]));
        let l = LineLabels::of(&once, &[]).unwrap();
        assert!(l.repeated.is_empty());
        assert_eq!(l.repeated_warning(&once), None);
        let twice = flight(Ok(vec![7.0, 7.0, 0.0, 8.0, 8.0, 0.0, 7.0, 9.0, 8.0, 7.0]));
        // One line per label, as gridding sees them.
        let whole = LineLabels::of(&twice, &[]).unwrap();
        assert_eq!(whole.labels, ["7", "8", "9"]);
        assert_eq!(whole.ids[9], 1.0);
        assert_eq!(whole.repeated, vec![(1, 3, 6), (2, 2, 8)]);
        let l = LineLabels::per_pass(&twice, &[]).unwrap();
        assert_eq!(l.repeated, vec![(1, 3, 6), (2, 2, 8)]);
        // Each later pass is a line of its own, after the labels.
        assert_eq!(
            l.ids,
            vec![1.0, 1.0, 0.0, 2.0, 2.0, 0.0, 4.0, 3.0, 5.0, 6.0]
        );
        assert_eq!(
            l.labels,
            ["7", "8", "9", "7 (pass 2)", "8 (pass 2)", "7 (pass 3)"]
        );
        assert_eq!(l.numbers, Some(vec![7.0, 8.0, 9.0, 7.0, 8.0, 7.0]));
        let w = l.repeated_warning(&twice).unwrap();
        assert!(
            w.contains("7 (3 passes, the second from data row 7), 8 (2 passes"),
            "{w}"
        );
        assert!(
            w.contains("a line of its own ('7 (pass 2)')")
                && w.ends_with("(7.01, as Geosoft's LINE.VERSION) to name them [line-repeated]"),
            "{w}"
        );
        // A pass of a tie is a tie.
        let tie = LineLabels::per_pass(&twice, &["8".to_string()]).unwrap();
        assert_eq!(tie.ties, Some(vec![false, true, false, false, true, false]));
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
    /// does not make a new label: `l7` at the end is `L7`'s second pass.
    #[test]
    fn many_labels_in_one_pass() {
        let n = 200_000;
        let v: Vec<String> = (0..n).map(|k| format!("L{k}")).collect();
        let mut s: Vec<&str> = v.iter().map(String::as_str).collect();
        s.push("l7");
        let t0 = std::time::Instant::now();
        let l = LineLabels::per_pass(&flight(Err(s)), &[]).unwrap();
        assert_eq!(l.labels.len(), n + 1);
        assert_eq!(l.ids[n], (n + 1) as f64);
        assert_eq!(l.label(l.ids[n] as i64), Some("L7 (pass 2)"));
        assert!(t0.elapsed().as_secs_f64() < 10.0, "{:?}", t0.elapsed());
    }
}
