//! MATLAB v5 MAT-files, read without a C library: MATLAB's `save` format
//! of `-v6` and of the default `-v7` (v5 with compressed variables), and
//! what `scipy.io.savemat` writes. (A `-v7.3` file is HDF5, read by
//! [`crate::read_hdf5`].)
//!
//! **Format** (MathWorks, "MAT-File Format", the Level 5 chapter): a
//! 128-byte header (text beginning `MATLAB 5.0 MAT-file`, version 0x0100,
//! `IM` or `MI` for the byte order), then one data element per variable.
//! An element is a tag (type, byte count; or both in 4 bytes with the data
//! in the other 4, the small-element form) and its data, padded to 8
//! bytes; `miCOMPRESSED` holds one zlib-compressed element. A variable is
//! an `miMATRIX`: array flags (class, complex, logical), dimensions, name,
//! then the class's data: the real part of a numeric array, stored in any
//! numeric type (MATLAB stores a `double` of small integers as `uint8`), in
//! column-major order; or a struct's field names and one `miMATRIX` per
//! field and element.
//!
//! **Which variables are the flight's fields**: [`crate::matlab`]'s rules,
//! shared with MATLAB v7.3 files.
//!
//! **Damaged or hostile files** give [`IoError::Mat`] naming the file and
//! the variable, never a panic: every byte count is checked against the
//! bytes there, dimensions against the values, a compressed variable is
//! decompressed only up to the bytes its tag declares and all of them
//! together to [`MAX_READ_BYTES`], and structs nest at most
//! [`MAX_DEPTH`] deep.
//!
//! Rows have no file line: messages name the data row (the index + 1).

use std::io::Read;
use std::path::Path;

use crate::ReadOptions;
use aeromag_core::memory::size_text;

use crate::error::{IoError, Result};
use crate::hdf5::MAX_READ_BYTES;
use crate::matlab::{Value, Variables, dims_text, flight_of, text_value};
use crate::table::FlightTable;

/// The start of a MATLAB v5 MAT-file's header text.
pub(crate) const SIGNATURE: &[u8] = b"MATLAB 5.0 MAT-file";

/// Deepest nesting of structs read (MATLAB itself has no limit;
/// a flight is one or two levels deep).
pub const MAX_DEPTH: usize = 16;

/// Length of the file header.
const HEADER_BYTES: usize = 128;

// Data types of the elements (the format's Table 1-1).
const MI_INT8: u32 = 1;
const MI_UINT8: u32 = 2;
const MI_INT16: u32 = 3;
const MI_UINT16: u32 = 4;
const MI_INT32: u32 = 5;
const MI_UINT32: u32 = 6;
const MI_SINGLE: u32 = 7;
const MI_DOUBLE: u32 = 9;
const MI_INT64: u32 = 12;
const MI_UINT64: u32 = 13;
const MI_MATRIX: u32 = 14;
const MI_COMPRESSED: u32 = 15;
const MI_UTF8: u32 = 16;
const MI_UTF16: u32 = 17;

// Array classes (Table 1-3).
const MX_CELL: u8 = 1;
const MX_STRUCT: u8 = 2;
const MX_OBJECT: u8 = 3;
const MX_CHAR: u8 = 4;
const MX_SPARSE: u8 = 5;
const MX_DOUBLE: u8 = 6;
const MX_SINGLE: u8 = 7;
const MX_UINT64: u8 = 15;
const MX_OPAQUE: u8 = 17;

/// Array flag bits.
const FLAG_COMPLEX: u32 = 0x0800;
const FLAG_LOGICAL: u32 = 0x0200;

/// Whether `head`, a file's first bytes, begins a MATLAB v5 MAT-file.
pub(crate) fn is_mat5(head: &[u8]) -> bool {
    head.starts_with(SIGNATURE)
}

/// Reads a MATLAB v5 MAT-file's flight (module docs): the fields
/// [`ReadOptions::fields`] asks for, mapped like a CSV header.
///
/// Errors: [`IoError::Open`] for a file that cannot be opened,
/// [`IoError::Mat`] for one that is damaged or holds no flight.
pub fn read_mat5(path: &Path, opts: &ReadOptions) -> Result<FlightTable> {
    let file = path.display().to_string();
    let open = |e| IoError::Open {
        file: file.clone(),
        source: e,
    };
    let err = |variable: Option<&str>, message: String| IoError::Mat {
        file: file.clone(),
        variable: variable.map(str::to_string),
        message,
    };
    // The file is read whole, and its values take as much again (more
    // when compressed): refused here rather than aborted by the allocator.
    let size = std::fs::metadata(path).map_err(open)?.len();
    let available = aeromag_core::memory::available_bytes();
    if let Some(available) = available
        && size.saturating_mul(2) > available
    {
        return Err(err(
            None,
            format!(
                "reading it takes at least {} (the file and its values), more than the {} \
                 this process can take",
                size_text(size.saturating_mul(2)),
                size_text(available)
            ),
        ));
    }
    let bytes = std::fs::read(path).map_err(open)?;
    // The values, and the variable being decompressed, in what is left.
    let budget = Budget {
        memory: available.map_or(u64::MAX, |a| a.saturating_sub(size)),
        inflate: MAX_READ_BYTES as u64,
    };
    let variables = parse(&bytes, budget).map_err(|(v, m)| err(v.as_deref(), m))?;
    flight_of(variables)
        .map_err(|(v, m)| err(v.as_deref(), m))?
        // Every value is in memory already.
        .into_table(path, opts, |_, _| Ok(()), Ok)
}

/// An error while parsing: the variable concerned (if known) and what.
type ParseError = (Option<String>, String);

/// The file's named variables, in file order, their values and
/// decompressed bytes within `budget`.
fn parse(bytes: &[u8], mut budget: Budget) -> std::result::Result<Variables<Vec<f64>>, ParseError> {
    if bytes.len() < HEADER_BYTES || !is_mat5(bytes) {
        return Err((
            None,
            "not a MATLAB v5 MAT-file (its 128-byte header is missing or cut short)".into(),
        ));
    }
    let big = match &bytes[126..128] {
        b"IM" => false,
        b"MI" => true,
        other => {
            return Err((
                None,
                format!(
                    "the header's byte-order mark is {:?}, not 'IM' or 'MI': damaged",
                    String::from_utf8_lossy(other)
                ),
            ));
        }
    };
    let mut cursor = Cursor::new(&bytes[HEADER_BYTES..], big);
    let mut variables = Vec::new();
    let mut index = 0usize;
    while !cursor.at_end() {
        index += 1;
        let at = |m: String| (None, format!("variable {index}: {m}"));
        let (kind, data) = cursor.element().map_err(at)?;
        let decompressed;
        let mut decompressed_len = 0;
        let (kind, data) = if kind == MI_COMPRESSED {
            decompressed = inflate(data, big, &mut budget).map_err(at)?;
            decompressed_len = decompressed.len() as u64;
            let mut inner = Cursor::new(&decompressed, big);
            inner.element().map_err(at)?
        } else {
            (kind, data)
        };
        // Anything but a variable (a stray element) holds nothing of the flight.
        let variable = if kind == MI_MATRIX {
            let v = matrix(data, big, 0, "", &mut budget).map_err(|(v, m)| match v {
                Some(v) => (Some(v), m),
                None => (None, format!("variable {index}: {m}")),
            })?;
            Some(v)
        } else {
            None
        };
        // The decompressed bytes are freed with the variable read.
        budget.memory = budget.memory.saturating_add(decompressed_len);
        // The subsystem data (function handles, objects) has no name.
        if let Some((name, value)) = variable.filter(|(name, _)| !name.is_empty()) {
            variables.push((name, value));
        }
    }
    Ok(variables)
}

/// Bytes a read may still take: `memory` for the values and the variable
/// being decompressed together (what the process can take beyond the
/// file; a uint8-stored `double` takes 8 bytes a value), `inflate` for
/// all the decompressed variables ([`MAX_READ_BYTES`]).
struct Budget {
    memory: u64,
    inflate: u64,
}

impl Budget {
    /// Takes `bytes` of memory (and of decompression when `inflated`), or
    /// says why not.
    fn take(&mut self, bytes: u64, inflated: bool) -> std::result::Result<(), String> {
        if inflated && bytes > self.inflate {
            return Err(format!(
                "its variables decompress to more than {} read from one file: damaged, or far \
                 beyond any flight",
                size_text(MAX_READ_BYTES as u64)
            ));
        }
        if bytes > self.memory {
            return Err(format!(
                "its values need more than the {} this process can take",
                size_text(self.memory)
            ));
        }
        self.memory -= bytes;
        if inflated {
            self.inflate -= bytes;
        }
        Ok(())
    }
}

/// Decompresses one `miCOMPRESSED` element: exactly the element its
/// first tag declares, within `budget`.
fn inflate(data: &[u8], big: bool, budget: &mut Budget) -> std::result::Result<Vec<u8>, String> {
    let damaged = |e: std::io::Error| format!("its compressed data is damaged ({e})");
    let mut z = flate2::read::ZlibDecoder::new(data);
    let mut tag = [0u8; 8];
    z.read_exact(&mut tag).map_err(damaged)?;
    let t = Cursor::new(&tag, big);
    let declared = if t.u32_at(0) >> 16 != 0 {
        0 // a small element: all in the tag
    } else {
        t.u32_at(4) as usize
    };
    let want = 8usize.saturating_add(declared);
    budget.take(want as u64, true)?;
    // Within the budget: allocated once (a vector doubling as the data
    // arrived took up to twice the memory).
    let mut out = Vec::with_capacity(want);
    out.extend_from_slice(&tag);
    (&mut z)
        .take((want - 8) as u64)
        .read_to_end(&mut out)
        .map_err(damaged)?;
    if out.len() < want {
        return Err(format!(
            "its compressed data ends after {} of the {want} bytes it declares: damaged or cut short",
            out.len()
        ));
    }
    Ok(out)
}

/// Reads elements from a byte slice in the file's byte order.
struct Cursor<'a> {
    bytes: &'a [u8],
    pos: usize,
    big: bool,
}

impl<'a> Cursor<'a> {
    fn new(bytes: &'a [u8], big: bool) -> Self {
        Cursor { bytes, pos: 0, big }
    }

    /// No element left (the last may be followed by less than a tag of
    /// padding).
    fn at_end(&self) -> bool {
        self.bytes.len().saturating_sub(self.pos) < 8
    }

    fn u32_at(&self, at: usize) -> u32 {
        let b: [u8; 4] = self.bytes[at..at + 4].try_into().expect("4 bytes");
        if self.big {
            u32::from_be_bytes(b)
        } else {
            u32::from_le_bytes(b)
        }
    }

    /// The next element's type and data; the cursor moves past its
    /// padding. A compressed element is not padded.
    fn element(&mut self) -> std::result::Result<(u32, &'a [u8]), String> {
        let left = self.bytes.len() - self.pos.min(self.bytes.len());
        if left < 8 {
            return Err(format!(
                "an element's tag is cut short ({left} of 8 bytes): damaged or cut short"
            ));
        }
        let first = self.u32_at(self.pos);
        if first >> 16 != 0 {
            // Small element: size and type in 4 bytes, data in the next 4.
            let size = (first >> 16) as usize;
            if size > 4 {
                return Err(format!(
                    "a small element declares {size} bytes (at most 4): damaged"
                ));
            }
            let data = &self.bytes[self.pos + 4..self.pos + 4 + size];
            self.pos += 8;
            return Ok((first & 0xffff, data));
        }
        let size = self.u32_at(self.pos + 4) as usize;
        let start = self.pos + 8;
        if size > self.bytes.len() - start {
            return Err(format!(
                "an element declares {size} bytes where {} are left: damaged or cut short",
                self.bytes.len() - start
            ));
        }
        let data = &self.bytes[start..start + size];
        let padded = if first == MI_COMPRESSED {
            size
        } else {
            size.next_multiple_of(8)
        };
        self.pos = (start + padded).min(self.bytes.len());
        Ok((first, data))
    }
}

/// One `miMATRIX` element's data: the variable's name and value. `path`
/// names a struct's field (`traj.lat`, whose own name is empty) in
/// errors; empty for a top-level variable, named by its own name.
fn matrix(
    data: &[u8],
    big: bool,
    depth: usize,
    path: &str,
    budget: &mut Budget,
) -> std::result::Result<(String, Value<Vec<f64>>), ParseError> {
    let known = |name: &str| {
        let shown = if path.is_empty() { name } else { path };
        (!shown.is_empty()).then(|| shown.to_string())
    };
    if data.is_empty() {
        // An empty array (a struct field never set): no flags, no name.
        return Ok((
            String::new(),
            Value::Other {
                dims: vec![0, 0],
                what: "an empty array".into(),
            },
        ));
    }
    if depth > MAX_DEPTH {
        return Err((
            known(""),
            format!("structs nest deeper than {MAX_DEPTH} levels: damaged"),
        ));
    }
    let mut c = Cursor::new(data, big);
    // A header sub-element of type `kind` (4 bytes at least but for the name).
    fn header<'a>(
        c: &mut Cursor<'a>,
        what: &str,
        kind: u32,
    ) -> std::result::Result<&'a [u8], String> {
        c.element()
            .ok()
            .filter(|(k, d)| *k == kind && (kind == MI_INT8 || d.len() >= 4))
            .map(|(_, d)| d)
            .ok_or_else(|| format!("its {what} is missing: damaged"))
    }
    let flags = header(&mut c, "array flags", MI_UINT32).map_err(|m| (known(""), m))?;
    let flag_word = Cursor::new(flags, big).u32_at(0);
    let class = (flag_word & 0xff) as u8;
    if class == MX_OPAQUE {
        // An object (a `table`, `datetime`, `string`): no dimensions; its
        // name, its type system (`MCOS`) and its class name, then data.
        let mut text = |what| {
            header(&mut c, what, MI_INT8)
                .map(|t| String::from_utf8_lossy(t).into_owned())
                .map_err(|m| (known(""), m))
        };
        let name = text("name")?;
        let _type_system = text("type system")?;
        let class_name = text("class name")?;
        return Ok((
            name,
            Value::Other {
                dims: vec![1, 1],
                what: format!("a MATLAB {class_name} object"),
            },
        ));
    }
    let dims_bytes = header(&mut c, "dimensions", MI_INT32).map_err(|m| (known(""), m))?;
    let dc = Cursor::new(dims_bytes, big);
    let dims: Vec<Option<usize>> = (0..dims_bytes.len() / 4)
        .map(|i| usize::try_from(dc.u32_at(4 * i) as i32).ok())
        .collect();
    let name =
        String::from_utf8_lossy(header(&mut c, "name", MI_INT8).map_err(|m| (known(""), m))?)
            .into_owned();
    let named = |m: String| (known(&name), m);
    let Some(dims) = dims.into_iter().collect::<Option<Vec<usize>>>() else {
        return Err(named("has a negative dimension: damaged".into()));
    };
    let count = dims
        .iter()
        .try_fold(1usize, |a, &d| a.checked_mul(d))
        .ok_or_else(|| named("its dimensions overflow: damaged".into()))?;
    let other = |what: &str| {
        Ok((
            name.clone(),
            Value::Other {
                dims: dims.clone(),
                what: what.to_string(),
            },
        ))
    };
    match class {
        MX_DOUBLE..=MX_UINT64 => {
            if flag_word & FLAG_COMPLEX != 0 {
                return other("a complex array");
            }
            let (kind, real) = c.element().map_err(named)?;
            // The values there are, as `f64` (a uint8-stored one takes 8
            // times its bytes); compared with the dimensions below.
            let stored = real.len() / element_bytes(kind).max(1);
            budget
                .take((stored as u64).saturating_mul(8), false)
                .map_err(named)?;
            let values = numbers(kind, real, big).map_err(named)?;
            if values.len() != count {
                return Err(named(format!(
                    "holds {} values where its dimensions {} say {count}: damaged",
                    values.len(),
                    dims_text(&dims)
                )));
            }
            let integer = !matches!(class, MX_DOUBLE | MX_SINGLE) || flag_word & FLAG_LOGICAL != 0;
            let scalar = (values.len() == 1).then(|| values[0]);
            Ok((
                name,
                Value::Numeric {
                    dims,
                    data: values,
                    integer,
                    scalar,
                },
            ))
        }
        MX_STRUCT if count == 1 => {
            let name_len =
                header(&mut c, "field name length", MI_INT32).map_err(|m| (known(&name), m))?;
            let name_len = Cursor::new(name_len, big).u32_at(0) as usize;
            let names = header(&mut c, "field names", MI_INT8).map_err(|m| (known(&name), m))?;
            if name_len == 0 || names.len() % name_len != 0 {
                return Err(named("its field names are damaged".into()));
            }
            let mut fields = Vec::with_capacity(names.len() / name_len);
            for field in names.chunks(name_len) {
                let end = field.iter().position(|&b| b == 0).unwrap_or(field.len());
                let field = String::from_utf8_lossy(&field[..end]).into_owned();
                let inner = format!("{}.{field}", known(&name).unwrap_or_default());
                let (kind, el) = c.element().map_err(|m| (Some(inner.clone()), m))?;
                if kind != MI_MATRIX {
                    return Err((Some(inner), "is not an array: damaged".into()));
                }
                let (_, value) = matrix(el, big, depth + 1, &inner, budget)?;
                fields.push((field, value));
            }
            Ok((name, Value::Struct(fields)))
        }
        MX_STRUCT => other("a struct array"),
        MX_CHAR if dims.len() == 2 => {
            let (kind, data) = c.element().map_err(named)?;
            let units = utf16_units(kind, data, big).map_err(named)?;
            Ok((name.clone(), text_value(dims, &units).map_err(named)?))
        }
        MX_CHAR => other("text"),
        MX_CELL => other("a cell array"),
        MX_SPARSE => other("a sparse matrix"),
        MX_OBJECT => other("an object"),
        _ => other("an array of a class not read here"),
    }
}

/// The bytes of one value of numeric data type `kind` (0 for another type).
fn element_bytes(kind: u32) -> usize {
    match kind {
        MI_INT8 | MI_UINT8 => 1,
        MI_INT16 | MI_UINT16 => 2,
        MI_INT32 | MI_UINT32 | MI_SINGLE => 4,
        MI_DOUBLE | MI_INT64 | MI_UINT64 => 8,
        _ => 0,
    }
}

/// The UTF-16 code units of a `char` array's element of type `kind`
/// (MATLAB writes `uint16` or UTF-16, SciPy UTF-8 for ASCII text; a byte
/// type is one character a byte).
fn utf16_units(kind: u32, data: &[u8], big: bool) -> std::result::Result<Vec<u16>, String> {
    Ok(match kind {
        MI_UINT16 | MI_UTF16 => numbers(MI_UINT16, data, big)?
            .into_iter()
            .map(|u| u as u16)
            .collect(),
        MI_UTF8 => String::from_utf8_lossy(data).encode_utf16().collect(),
        MI_UINT8 | MI_INT8 => data.iter().map(|&b| u16::from(b)).collect(),
        other => return Err(format!("its text is of data type {other}: damaged")),
    })
}

/// The values of a numeric element of type `kind`, as `f64` (exact for
/// every type but 64-bit integers beyond 2⁵³).
fn numbers(kind: u32, data: &[u8], big: bool) -> std::result::Result<Vec<f64>, String> {
    macro_rules! read {
        ($t:ty) => {{
            const N: usize = std::mem::size_of::<$t>();
            if !data.len().is_multiple_of(N) {
                return Err(format!(
                    "its data of {} bytes is not a whole number of {N}-byte values: damaged",
                    data.len()
                ));
            }
            data.chunks_exact(N)
                .map(|b| {
                    let b: [u8; N] = b.try_into().expect("N bytes");
                    (if big {
                        <$t>::from_be_bytes(b)
                    } else {
                        <$t>::from_le_bytes(b)
                    }) as f64
                })
                .collect()
        }};
    }
    Ok(match kind {
        MI_INT8 => read!(i8),
        MI_UINT8 => read!(u8),
        MI_INT16 => read!(i16),
        MI_UINT16 => read!(u16),
        MI_INT32 => read!(i32),
        MI_UINT32 => read!(u32),
        MI_SINGLE => read!(f32),
        MI_DOUBLE => read!(f64),
        MI_INT64 => read!(i64),
        MI_UINT64 => read!(u64),
        other => {
            return Err(format!(
                "its values are of data type {other}, not a number: damaged"
            ));
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_small_element_holds_its_data_in_the_tag() {
        // miINT8 of 3 bytes "abc" in the small form, little-endian.
        let bytes = [1, 0, 3, 0, b'a', b'b', b'c', 0];
        let mut c = Cursor::new(&bytes, false);
        assert_eq!(c.element().unwrap(), (MI_INT8, &b"abc"[..]));
        assert!(c.at_end());
        let bytes = [0, 3, 0, 1, b'a', b'b', b'c', 0];
        let mut c = Cursor::new(&bytes, true);
        assert_eq!(c.element().unwrap(), (MI_INT8, &b"abc"[..]));
    }

    #[test]
    fn an_element_longer_than_the_bytes_left_is_an_error() {
        let mut bytes = vec![9, 0, 0, 0, 0xff, 0xff, 0, 0];
        bytes.extend([0u8; 16]);
        let e = Cursor::new(&bytes, false).element().unwrap_err();
        assert!(e.contains("declares 65535 bytes where 16 are left"), "{e}");
    }

    #[test]
    fn numbers_of_every_type_read_exactly() {
        assert_eq!(numbers(MI_UINT8, &[1, 255], false).unwrap(), [1.0, 255.0]);
        assert_eq!(numbers(MI_INT16, &[0xff, 0xff], false).unwrap(), [-1.0]);
        assert_eq!(numbers(MI_INT16, &[0x01, 0x00], true).unwrap(), [256.0]);
        assert_eq!(
            numbers(MI_DOUBLE, &53064.063f64.to_le_bytes(), false).unwrap(),
            [53064.063]
        );
        assert_eq!(
            numbers(MI_SINGLE, &0.1f32.to_be_bytes(), true).unwrap(),
            [0.1f32 as f64]
        );
        assert!(numbers(MI_DOUBLE, &[0; 7], false).is_err());
        assert!(numbers(MI_MATRIX, &[0; 8], false).is_err());
    }
}
