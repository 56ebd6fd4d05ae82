//! MAT-file readers: `read_table` on the bytes as a `.mat` file, a MATLAB
//! v5 file read by aeromag's own reader or a v7.3 one (HDF5) as a MATLAB
//! workspace (seeds: the files of `crates/io/tests/data/mat5`, SciPy's,
//! hdf5storage's and hand-made ones), then the checks on any table that
//! parses. Every malformed file must be an error naming the file, never a
//! panic or a huge allocation.
#![no_main]

use aeromag_io::{Fields, ReadOptions, check_time, check_units, read_table};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let path = aeromag_fuzz::scratch("in.mat", data);
    // Odd lengths read two fields only, even ones all.
    let opts = ReadOptions {
        fields: if data.len() % 2 == 1 {
            Fields::Only(vec!["time".into(), "mag".into()])
        } else {
            Fields::All
        },
        ..ReadOptions::default()
    };
    match read_table(&path, &opts) {
        Ok(t) => {
            let _ = check_time(&t);
            let _ = check_units(&t);
        }
        Err(e) => assert!(e.to_string().contains("in.mat"), "{e}"),
    }
});
