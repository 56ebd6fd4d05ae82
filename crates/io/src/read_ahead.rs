//! Reading ahead on a second thread: the tokenizer of a text reader (CSV or
//! whitespace/XYZ, any [`RowSource`]) runs on one thread while the
//! [`TableBuilder`] parses the cells of the rows already split on the
//! calling thread.
//!
//! The source's rows are copied in order into batches of at most
//! [`BATCH_ROWS`] rows (or [`BATCH_BYTES`] bytes of field text) and handed
//! over through a channel that holds at most [`BATCHES_IN_FLIGHT`] batches,
//! so memory stays bounded whatever the file's size. The builder sees the
//! same rows with the same line numbers and byte counts, in the same order,
//! as without the second thread, so the table, the warnings and every error
//! (with its file, line, row and column) are identical. An error of the
//! source (a short row, a line over the limit, an I/O error) arrives after
//! the rows before it; an error of the builder (a bad cell) stops the
//! source at its next batch.
//!
//! Splitting the rows and parsing the numbers cost about the same, so on
//! two cores reading takes about half the time (measured with
//! `examples/read_time.rs`, see the README's benchmark section).

use std::sync::mpsc::{Receiver, sync_channel};

use crate::builder::{RowFields, RowSource, TableBuilder};
use crate::error::{IoError, Result};

/// Most rows in one batch.
pub(crate) const BATCH_ROWS: usize = 4096;
/// A batch is handed over once its field text exceeds this many bytes
/// (wide rows), whatever its number of rows.
pub(crate) const BATCH_BYTES: usize = 1 << 20;
/// Batches the source may run ahead of the builder.
pub(crate) const BATCHES_IN_FLIGHT: usize = 4;

/// Rows copied out of a source: the fields of row `r` are
/// `text[ends[r·n + i − 1]..ends[r·n + i]]`.
#[derive(Default)]
struct Batch {
    text: Vec<u8>,
    ends: Vec<usize>,
    lines: Vec<u64>,
    bytes_read: Vec<u64>,
    /// How the source went on after the batch's rows.
    end: End,
}

#[derive(Default)]
enum End {
    #[default]
    More,
    Done,
    Failed(IoError),
}

/// One row of a batch, as the builder reads it.
struct BatchRow<'a> {
    batch: &'a Batch,
    n_fields: usize,
    row: usize,
}

impl RowFields for BatchRow<'_> {
    fn line(&self) -> u64 {
        self.batch.lines[self.row]
    }

    #[inline]
    fn field(&self, i: usize) -> &[u8] {
        let k = self.row * self.n_fields + i;
        let a = if k == 0 { 0 } else { self.batch.ends[k - 1] };
        &self.batch.text[a..self.batch.ends[k]]
    }

    fn bytes_read(&self) -> u64 {
        self.batch.bytes_read[self.row]
    }
}

/// Fills one batch from `src` (rows of `n_fields` fields).
fn fill<S: RowSource>(src: &mut S, n_fields: usize) -> Batch {
    let mut b = Batch::default();
    while b.lines.len() < BATCH_ROWS && b.text.len() < BATCH_BYTES {
        match src.next_row() {
            Ok(true) => {
                for i in 0..n_fields {
                    b.text.extend_from_slice(src.field(i));
                    b.ends.push(b.text.len());
                }
                b.lines.push(src.line());
                b.bytes_read.push(src.bytes_read());
            }
            Ok(false) => {
                b.end = End::Done;
                return b;
            }
            Err(e) => {
                b.end = End::Failed(e);
                return b;
            }
        }
    }
    b
}

/// Pushes every row of `src` (whose rows have the builder's number of
/// fields) into `builder`, reading `src` ahead on a second thread, and
/// returns the source once it is exhausted (see the module docs).
pub(crate) fn push_rows<S: RowSource + Send>(builder: &mut TableBuilder, src: S) -> Result<S> {
    let n_fields = builder.names().len();
    std::thread::scope(|scope| {
        let (tx, rx) = sync_channel::<Batch>(BATCHES_IN_FLIGHT);
        let producer = scope.spawn(move || {
            let mut src = src;
            loop {
                let batch = fill(&mut src, n_fields);
                let last = !matches!(batch.end, End::More);
                // A closed channel: the builder stopped at an error.
                if tx.send(batch).is_err() || last {
                    return src;
                }
            }
        });
        let pushed = consume(builder, rx, n_fields);
        let src = producer
            .join()
            .unwrap_or_else(|panic| std::panic::resume_unwind(panic));
        pushed.map(|()| src)
    })
}

/// The builder's side: every row of every batch, then the source's end.
fn consume(builder: &mut TableBuilder, rx: Receiver<Batch>, n_fields: usize) -> Result<()> {
    // `rx` is dropped on return, which stops the source at an error.
    for batch in rx.iter() {
        for row in 0..batch.lines.len() {
            builder.push_row(&BatchRow {
                batch: &batch,
                n_fields,
                row,
            })?;
        }
        match batch.end {
            End::More => {}
            End::Done => return Ok(()),
            End::Failed(e) => return Err(e),
        }
    }
    Ok(())
}
