//! The texts of a `line` column read as numbers, kept while it is read.
//!
//! Line labels are names, even when they are written as numbers: Geosoft's
//! `LINE.VERSION` labels make `1003.1` (version 1) and `1003.10` (version
//! 10) two lines, and a contractor's `01003` need not be the `1003` of
//! another export. Read as numbers, such pairs would become one line, and
//! levelling would give two tracks one offset without a word. So while a
//! `line` column is read as numbers, the reader notes each distinct text
//! of its cells with the value it reads ([`LabelTexts`]), and when two
//! texts give one value ([`LabelClash`]) the column is read as text
//! instead (the table then holds the labels exactly as written).
//!
//! The cost is one comparison of the cell with the previous row's per row
//! (a line's rows repeat its label) and a hash lookup when the label
//! changes.

use std::collections::HashMap;

/// Distinct labels kept, per piece and in all: a survey has hundreds or
/// thousands of lines, and a column with a new label on every row (a
/// fiducial mapped as `line`) would otherwise keep 10⁷ texts. Beyond, the
/// texts are not compared (a clash among the later labels goes unseen).
pub(crate) const MAX_LABELS: usize = 1 << 16;

/// The distinct texts of a label column's cells, with their values.
#[derive(Debug, Clone)]
pub(crate) struct LabelTexts {
    /// The previous cell when it was up to 8 bytes long and read by
    /// [`Self::note_at`]: its bytes in a word (little-endian, zero above
    /// its length) and its length; `usize::MAX` otherwise.
    last_word: (u64, usize),
    /// The previous cell, untrimmed, when [`Self::note`] read it.
    last: Vec<u8>,
    /// Each distinct text (trimmed) of a cell holding a number other than 0.
    seen: HashMap<Vec<u8>, f64>,
}

impl Default for LabelTexts {
    fn default() -> Self {
        Self {
            last_word: (0, usize::MAX),
            last: Vec::new(),
            seen: HashMap::new(),
        }
    }
}

impl LabelTexts {
    /// [`Self::note`] of the cell `text[p..p + len]`, without a call to
    /// `memcmp` for the short labels of most files (up to 8 bytes, with 8
    /// bytes of `text` to load at `p`): the fast path's per-row cost.
    #[inline(always)]
    pub(crate) fn note_at(&mut self, text: &[u8], p: usize, len: usize, value: f64) {
        if len <= 8
            && let Some(bytes) = text.get(p..p + 8)
        {
            let mask = if len == 8 {
                u64::MAX
            } else {
                (1u64 << (8 * len)) - 1
            };
            let word = u64::from_le_bytes(bytes.try_into().unwrap_or_default()) & mask;
            if (word, len) == self.last_word {
                return;
            }
            self.last_word = (word, len);
            self.last.clear();
            self.changed(&text[p..p + len], value);
        } else {
            self.note(&text[p..p + len], value);
        }
    }

    /// Notes the cell `bytes` read as `value` (NaN: missing; 0: no line).
    #[inline]
    pub(crate) fn note(&mut self, bytes: &[u8], value: f64) {
        if bytes == self.last.as_slice() && self.last_word.1 == usize::MAX {
            return;
        }
        self.last.clear();
        self.last.extend_from_slice(bytes);
        self.last_word = (0, usize::MAX);
        self.changed(bytes, value);
    }

    /// A cell unlike the previous one.
    #[cold]
    #[inline(never)]
    fn changed(&mut self, bytes: &[u8], value: f64) {
        if value.is_nan() || value == 0.0 {
            return;
        }
        let text = bytes.trim_ascii();
        if self.seen.len() < MAX_LABELS && !self.seen.contains_key(text) {
            self.seen.insert(text.to_vec(), value);
        }
    }

    /// Forgets every text (a buffer reused for the next piece of rows).
    pub(crate) fn clear(&mut self) {
        self.last.clear();
        self.last_word = (0, usize::MAX);
        self.seen.clear();
    }

    /// The distinct texts and their values, in no particular order.
    pub(crate) fn texts(&self) -> impl Iterator<Item = (&[u8], f64)> {
        self.seen.iter().map(|(t, v)| (t.as_slice(), *v))
    }
}

/// Across the whole read: the first text of each value, and whether two
/// texts of one value were found.
#[derive(Debug, Default, Clone)]
pub(crate) struct LabelClash {
    by_value: HashMap<u64, Vec<u8>>,
    /// Two texts of one value (`1003.1`, `1003.10`) were found.
    pub clash: bool,
}

impl LabelClash {
    /// Adds the text `text` of the value `value` (not NaN, not 0).
    pub(crate) fn add(&mut self, text: &[u8], value: f64) {
        if self.clash {
            return;
        }
        match self.by_value.get(&value.to_bits()) {
            Some(first) => self.clash = first.as_slice() != text,
            None if self.by_value.len() < MAX_LABELS => {
                self.by_value.insert(value.to_bits(), text.to_vec());
            }
            None => {}
        }
    }

    /// Adds every text of `texts`.
    pub(crate) fn add_all(&mut self, texts: &LabelTexts) {
        for (t, v) in texts.texts() {
            self.add(t, v);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn clash_of(cells: &[&str]) -> bool {
        let mut texts = LabelTexts::default();
        for c in cells {
            let v = crate::cell::parse_cell(c.as_bytes()).map_or(f64::NAN, |c| match c {
                crate::cell::Cell::Value(v) => v,
                crate::cell::Cell::Missing(_) => f64::NAN,
            });
            texts.note(c.as_bytes(), v);
        }
        let mut clash = LabelClash::default();
        clash.add_all(&texts);
        clash.clash
    }

    #[test]
    fn two_texts_of_one_number_clash() {
        assert!(clash_of(&["1003.1", "1003.1", "1003.10"]));
        assert!(clash_of(&["1003", "1003.0"]));
        assert!(clash_of(&["01003", " 1003"]));
        assert!(!clash_of(&["1003.1", "1004.1", "1003.1"]));
        // Spaces around a label are not part of it.
        assert!(!clash_of(&["1003", " 1003 ", "1003"]));
        // Missing and zero labels (turns) are no line at all.
        assert!(!clash_of(&["0", "0.0", "-0", "", "NaN", "*", "7"]));
    }

    /// A new label on every row keeps at most MAX_LABELS texts.
    #[test]
    fn distinct_labels_kept_are_bounded() {
        let mut texts = LabelTexts::default();
        let mut clash = LabelClash::default();
        for k in 1..=(3 * MAX_LABELS) {
            texts.note(k.to_string().as_bytes(), k as f64);
        }
        clash.add_all(&texts);
        assert_eq!(texts.seen.len(), MAX_LABELS);
        assert_eq!(clash.by_value.len(), MAX_LABELS);
        assert!(!clash.clash);
    }
}
