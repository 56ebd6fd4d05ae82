//! HDF5 reader: `read_hdf5` on the bytes as a `.h5` file (seeds: the h5py
//! files of `crates/io/tests/data/hdf5`), then the derivations, a row
//! selection and the checks on any table that parses. Every malformed file
//! must be an error naming the file, never a panic or a huge allocation.
#![no_main]

use aeromag_io::{Fields, ReadOptions, RowSelection, check_time, check_units, read_table};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let path = aeromag_fuzz::scratch("in.h5", data);
    // Odd lengths read two fields only (the lazy path), even ones all.
    let opts = ReadOptions {
        fields: if data.len() % 2 == 1 {
            Fields::Only(vec!["time".into(), "mag".into()])
        } else {
            Fields::All
        },
        rows: if data.len() % 3 == 0 {
            RowSelection::parse(Some("1001"), None).unwrap()
        } else {
            RowSelection::default()
        },
        ..ReadOptions::default()
    };
    match read_table(&path, &opts) {
        Ok(t) => {
            let _ = check_time(&t);
            let _ = check_units(&t);
        }
        Err(e) => assert!(e.to_string().contains("in.h5"), "{e}"),
    }
});
