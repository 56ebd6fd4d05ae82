//! HDF5 writer: a flight table in the MagNav/SGL layout that
//! [`crate::read_hdf5`], h5py and MagNav.jl's `get_XYZ20` read: one 1-D
//! dataset per column at the file's root, named as the column, in the
//! table's order.
//!
//! - Numbers are IEEE float64, little-endian: every value (NaN for a
//!   missing one, ±inf) reads back bit for bit.
//! - A column read as integers (`line` 1003, a flag column) whose values
//!   are all whole and within ±2⁵³ is a signed 64-bit integer dataset, as
//!   SGL's files hold such fields, and reads back as integers.
//! - A text column (line labels such as `L1020`) is a fixed-length UTF-8
//!   string dataset, padded with NULs to its longest cell.
//!
//! The file is the HDF5 format's "latest" form, as h5py writes it with
//! `libver="latest"` (HDF5 File Format Specification version 3, §II–IV):
//! a version-2 superblock, version-2 object headers with their Jenkins
//! lookup3 checksums, the root group's links held in its own header
//! (compact storage: a Link Info, a Group Info and one Link message per
//! dataset), and each dataset's header with its Dataspace (version 2),
//! Datatype (version 1), Fill Value (version 3) and contiguous Data Layout
//! (version 3) messages, its data after all the headers. No time stamps
//! and no attributes: the same table gives the same bytes.
//!
//! ```text
//! 0        superblock (48 bytes)
//! 48       root group header: links "time" → A, "mag" → B, …
//! A, B, …  dataset headers
//! …        the columns' data, one after the other (8-byte aligned)
//! ```
//!
//! What HDF5 cannot hold as a link name is refused before anything is
//! written ([`IoError::CannotWrite`], bad input): an empty name, `.`, or a
//! name containing `/` (a path separator in HDF5) or a NUL.

use std::io::Write;
use std::path::Path;

use hdf5_reader::checksum::jenkins_lookup3;

use crate::csv_write::written_columns;
use crate::error::Result;
use crate::table::{Column, FlightTable};

/// "Undefined address" of the format: all bits set.
const UNDEFINED: u64 = u64::MAX;

/// The version-2 superblock's length: signature 8, version, offset and
/// length sizes and flags 4, four addresses 32, checksum 4.
const SUPERBLOCK_BYTES: u64 = 48;

/// The longest link name written (a Link message is at most 65 535 bytes).
const MAX_NAME_BYTES: usize = 65_000;

/// Writes `table` as HDF5 to the file `path` (created or replaced,
/// atomically as [`crate::write_csv`]). Errors: [`IoError::CannotWrite`]
/// (bad input) for a column name HDF5 cannot hold, before anything is
/// written; [`IoError::Write`] when the file cannot be written.
pub fn write_hdf5(table: &FlightTable, path: &Path) -> Result<()> {
    crate::table_file::write_checked(table, path, check_hdf5, |t, w| write_hdf5_to(t, w))
}

/// Whether HDF5 can hold `table`'s column names (module docs); `file`
/// names the output in the error.
pub fn check_hdf5(table: &FlightTable, file: &str) -> Result<()> {
    crate::table_file::refuse_column(table, file, "CSV (.csv) instead", |c| {
        let name = c.name();
        let reason = if name.is_empty() || name == "." {
            "an HDF5 dataset cannot be named '' or '.'"
        } else if name.contains('/') {
            "'/' separates groups in an HDF5 name, so a dataset name cannot hold one"
        } else if name.contains('\0') {
            "the HDF5 library ends a name at a NUL character"
        } else if name.len() > MAX_NAME_BYTES {
            "the name is longer than an HDF5 link can hold"
        } else {
            return None;
        };
        Some(reason.to_string())
    })
}

/// Writes `table` as HDF5 to any writer, without the checks of
/// [`write_hdf5`] (call [`check_hdf5`] first).
pub fn write_hdf5_to<W: Write>(table: &FlightTable, mut out: W) -> std::io::Result<()> {
    let columns = written_columns(table);
    let rows = table.n_rows() as u64;
    let kinds: Vec<Kind> = columns.iter().map(|c| Kind::of(c)).collect();
    // Every header's length is known before any address: lay them out,
    // then the data.
    let dataset_header_bytes: Vec<u64> = kinds
        .iter()
        .map(|k| object_header_bytes(&dataset_messages(*k, rows, UNDEFINED)))
        .collect();
    let names: Vec<&str> = columns.iter().map(|c| c.name()).collect();
    let root_bytes = object_header_bytes(&root_messages(&names, &vec![0; names.len()]));
    let mut at = SUPERBLOCK_BYTES + root_bytes;
    let mut header_addresses = Vec::with_capacity(columns.len());
    for bytes in &dataset_header_bytes {
        header_addresses.push(at);
        at += bytes;
    }
    let headers_end = at;
    let mut at = headers_end.next_multiple_of(8);
    let mut data_addresses = Vec::with_capacity(columns.len());
    for k in &kinds {
        let bytes = rows * k.element_bytes();
        data_addresses.push(if bytes == 0 { UNDEFINED } else { at });
        at += bytes;
    }
    let end_of_file = at.max(headers_end);

    out.write_all(&superblock(SUPERBLOCK_BYTES, end_of_file))?;
    out.write_all(&object_header(&root_messages(&names, &header_addresses)))?;
    for (k, address) in kinds.iter().zip(&data_addresses) {
        out.write_all(&object_header(&dataset_messages(*k, rows, *address)))?;
    }
    out.write_all(&vec![
        0;
        (headers_end.next_multiple_of(8) - headers_end)
            as usize
    ])?;
    for (c, k) in columns.iter().zip(&kinds) {
        write_data(c, *k, &mut out)?;
    }
    Ok(())
}

/// How a column is stored.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Kind {
    /// IEEE float64, little-endian.
    Float,
    /// Signed 64-bit integers, little-endian.
    Integer,
    /// Fixed-length UTF-8 strings of this many bytes, NUL-padded.
    Text(usize),
}

impl Kind {
    /// The storage of column `c` (module docs).
    fn of(c: &Column) -> Self {
        if let Some(text) = c.text() {
            return Kind::Text(text.iter().map(String::len).max().unwrap_or(0).max(1));
        }
        if c.stores_integers() {
            Kind::Integer
        } else {
            Kind::Float
        }
    }

    fn element_bytes(self) -> u64 {
        match self {
            Kind::Float | Kind::Integer => 8,
            Kind::Text(n) => n as u64,
        }
    }

    /// The Datatype message's body (version 1; spec §IV.A.2.d).
    fn datatype(self) -> Vec<u8> {
        let mut d = Vec::with_capacity(20);
        match self {
            Kind::Float => {
                // Class 1, little-endian, mantissa's leading 1 implied
                // (normalisation 2), sign at bit 63.
                d.extend([0x11, 0x20, 63, 0]);
                d.extend(8u32.to_le_bytes());
                d.extend(0u16.to_le_bytes()); // bit offset
                d.extend(64u16.to_le_bytes()); // precision
                d.extend([52, 11, 0, 52]); // exponent at 52, 11 bits; mantissa at 0, 52 bits
                d.extend(1023u32.to_le_bytes()); // exponent bias
            }
            Kind::Integer => {
                // Class 0, little-endian, signed.
                d.extend([0x10, 0x08, 0, 0]);
                d.extend(8u32.to_le_bytes());
                d.extend(0u16.to_le_bytes());
                d.extend(64u16.to_le_bytes());
            }
            Kind::Text(n) => {
                // Class 3, NUL-padded (1), UTF-8 (1 << 4).
                d.extend([0x13, 0x11, 0, 0]);
                d.extend((n as u32).to_le_bytes());
            }
        }
        d
    }
}

/// One header message: its type, flags and body.
type Message = (u8, u8, Vec<u8>);

/// The root group's messages: Link Info and Group Info (compact storage:
/// no fractal heap, no name index), then a hard link per dataset.
fn root_messages(names: &[&str], addresses: &[u64]) -> Vec<Message> {
    let mut link_info = vec![0, 0]; // version 0, no creation order
    link_info.extend(UNDEFINED.to_le_bytes()); // fractal heap
    link_info.extend(UNDEFINED.to_le_bytes()); // name index v2 B-tree
    let mut messages = vec![(0x02, 0, link_info), (0x0A, 0, vec![0, 0])];
    for (name, address) in names.iter().zip(addresses) {
        messages.push((0x06, 0, link(name, *address)));
    }
    messages
}

/// A Link message (version 1) for a hard link named `name` to the object
/// header at `address`.
fn link(name: &str, address: u64) -> Vec<u8> {
    let long = name.len() > 255;
    // Bits 0–1: the name length's size (1 or 2 bytes); bit 4: a character
    // set follows (UTF-8) for a name that is not ASCII.
    let utf8 = !name.is_ascii();
    let flags = u8::from(long) | (u8::from(utf8) << 4);
    let mut l = vec![1, flags];
    if utf8 {
        l.push(1);
    }
    if long {
        l.extend((name.len() as u16).to_le_bytes());
    } else {
        l.push(name.len() as u8);
    }
    l.extend(name.as_bytes());
    l.extend(address.to_le_bytes());
    l
}

/// A dataset's messages: a 1-D dataspace of `rows`, its datatype, the fill
/// value's settings (storage allocated early, no fill value) and its
/// contiguous data at `address`.
fn dataset_messages(kind: Kind, rows: u64, address: u64) -> Vec<Message> {
    let mut dataspace = vec![2, 1, 0, 1]; // version 2, rank 1, no maxima, simple
    dataspace.extend(rows.to_le_bytes());
    let mut layout = vec![3, 1]; // version 3, contiguous
    layout.extend(address.to_le_bytes());
    layout.extend((rows * kind.element_bytes()).to_le_bytes());
    vec![
        (0x01, 0, dataspace),
        (0x03, 1, kind.datatype()),
        // Version 3; allocation early (1), written if set (2 << 2).
        (0x05, 1, vec![3, 0x09]),
        (0x08, 0, layout),
    ]
}

/// Bytes of the version-2 object header of `messages`.
fn object_header_bytes(messages: &[Message]) -> u64 {
    // "OHDR", version, flags, chunk size (4 bytes), messages, checksum.
    10 + messages.iter().map(|m| 4 + m.2.len() as u64).sum::<u64>() + 4
}

/// A version-2 object header (spec §IV.A.1.b): one chunk of `messages`,
/// each with a 4-byte prefix (type, size, flags), and the checksum.
fn object_header(messages: &[Message]) -> Vec<u8> {
    let body: usize = messages.iter().map(|m| 4 + m.2.len()).sum();
    let mut h = Vec::with_capacity(body + 14);
    h.extend(b"OHDR");
    h.push(2); // version
    h.push(0b10); // the chunk size in 4 bytes; no times, no attribute phase change
    h.extend((body as u32).to_le_bytes());
    for (kind, flags, data) in messages {
        h.push(*kind);
        h.extend((data.len() as u16).to_le_bytes());
        h.push(*flags);
        h.extend(data);
    }
    let checksum = jenkins_lookup3(&h);
    h.extend(checksum.to_le_bytes());
    h
}

/// The version-2 superblock (spec §II.A.2): 8-byte offsets and lengths,
/// base address 0, no extension, the end of the file and the root group's
/// header at `root`.
fn superblock(root: u64, end_of_file: u64) -> Vec<u8> {
    let mut s = Vec::with_capacity(SUPERBLOCK_BYTES as usize);
    s.extend(crate::hdf5::SIGNATURE);
    s.extend([2, 8, 8, 0]); // version, offset size, length size, flags
    s.extend(0u64.to_le_bytes()); // base address
    s.extend(UNDEFINED.to_le_bytes()); // superblock extension
    s.extend(end_of_file.to_le_bytes());
    s.extend(root.to_le_bytes());
    let checksum = jenkins_lookup3(&s);
    s.extend(checksum.to_le_bytes());
    s
}

/// Writes column `c`'s data as `kind`, in blocks.
fn write_data<W: Write>(c: &Column, kind: Kind, out: &mut W) -> std::io::Result<()> {
    const BLOCK: usize = 8192;
    let mut buf = Vec::with_capacity(BLOCK * 8);
    match (kind, c.values(), c.text()) {
        (Kind::Float, Some(values), _) => {
            for block in values.chunks(BLOCK) {
                buf.clear();
                buf.extend(block.iter().flat_map(|v| v.to_le_bytes()));
                out.write_all(&buf)?;
            }
        }
        (Kind::Integer, Some(values), _) => {
            for block in values.chunks(BLOCK) {
                buf.clear();
                buf.extend(block.iter().flat_map(|&v| (v as i64).to_le_bytes()));
                out.write_all(&buf)?;
            }
        }
        (Kind::Text(n), _, Some(text)) => {
            for block in text.chunks(BLOCK) {
                buf.clear();
                for t in block {
                    buf.extend(t.as_bytes());
                    buf.resize(buf.len() + n - t.len(), 0);
                }
                out.write_all(&buf)?;
            }
        }
        _ => unreachable!("Kind::of gives a column its own kind"),
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ReadOptions;

    fn table() -> FlightTable {
        let mut t = FlightTable::new();
        t.add_column("time", vec![0.0, 0.1, 0.2]).unwrap();
        t.add_column("mag", vec![53210.4, f64::NAN, -1e-300])
            .unwrap();
        t.add_integer_column("comp_flag", vec![0.0, 1.0, 0.0])
            .unwrap();
        t.add_integer_column("half", vec![0.0, 0.5, 1.0]).unwrap();
        t.add_text_column("line", vec!["L1020".into(), String::new(), "T901 é".into()])
            .unwrap();
        t.add_column("énergie", vec![f64::INFINITY, -0.0, 1.0])
            .unwrap();
        t
    }

    fn written(t: &FlightTable) -> (tempfile::TempDir, std::path::PathBuf) {
        let d = tempfile::tempdir().unwrap();
        let p = d.path().join("t.h5");
        write_hdf5(t, &p).unwrap();
        (d, p)
    }

    #[test]
    fn reads_back_to_the_same_table() {
        let t = table();
        let (_d, p) = written(&t);
        let back = crate::read_hdf5(&p, &ReadOptions::default()).unwrap();
        assert_eq!(back.column_names(), t.column_names());
        for c in t.columns() {
            let b = back.get(c.name()).unwrap();
            match (c.values(), b.values()) {
                (Some(x), Some(y)) => {
                    let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                    assert_eq!(bits(x), bits(y), "{}", c.name());
                }
                _ => assert_eq!(c.text(), b.text(), "{}", c.name()),
            }
        }
        // Whole numbers read as integers come back as integers; a column
        // with a fraction is stored as floats.
        assert!(back.get("comp_flag").unwrap().integer_text());
        assert!(!back.get("half").unwrap().integer_text());
    }

    #[test]
    fn the_same_table_gives_the_same_bytes_and_the_file_is_laid_out_as_documented() {
        let t = table();
        let (_d, p) = written(&t);
        let (_e, q) = written(&t);
        let bytes = std::fs::read(&p).unwrap();
        assert_eq!(bytes, std::fs::read(&q).unwrap());
        assert_eq!(&bytes[..8], &crate::hdf5::SIGNATURE);
        let eof = u64::from_le_bytes(bytes[28..36].try_into().unwrap());
        assert_eq!(eof, bytes.len() as u64);
        assert_eq!(&bytes[48..52], b"OHDR");
    }

    #[test]
    fn an_empty_table_and_long_or_odd_names_are_written() {
        let mut t = FlightTable::new();
        t.add_column("time", Vec::new()).unwrap();
        let (_d, p) = written(&t);
        // No rows: the column, empty.
        let back = crate::read_hdf5(&p, &ReadOptions::default()).unwrap();
        assert_eq!((back.n_rows(), back.column_names()), (0, vec!["time"]));
        let long = "x".repeat(300);
        let mut t = FlightTable::new();
        t.add_column(&long, vec![1.0, 2.0]).unwrap();
        t.add_column("a b,c", vec![3.0, 4.0]).unwrap();
        let (_d, p) = written(&t);
        let back = crate::read_hdf5(&p, &ReadOptions::default()).unwrap();
        assert_eq!(back.column_names(), [long.as_str(), "a b,c"]);
    }

    #[test]
    fn names_hdf5_cannot_hold_are_refused_before_writing() {
        for name in ["a/b", ".", "a\0b"] {
            let mut t = FlightTable::new();
            t.add_column(name, vec![1.0]).unwrap();
            let d = tempfile::tempdir().unwrap();
            let p = d.path().join("t.h5");
            let e = write_hdf5(&t, &p).unwrap_err();
            assert!(e.is_bad_input(), "{e}");
            assert!(
                e.to_string().contains(name) && e.to_string().contains("CSV"),
                "{e}"
            );
            assert!(!p.exists());
        }
    }
}
