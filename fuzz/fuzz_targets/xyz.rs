//! Geosoft XYZ reader: `read_xyz` on the bytes as a file (odd lengths go
//! through `read_table`'s content sniffing instead), then the checks and the
//! summary on any table that parses.
#![no_main]

use aeromag_io::{ReadOptions, check_time, check_units, read_table, read_xyz, summarize};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let opts = ReadOptions::default();
    let table = if data.len() % 2 == 0 {
        read_xyz(&aeromag_fuzz::scratch("in.xyz", data), &opts)
    } else {
        read_table(&aeromag_fuzz::scratch("in.dat", data), &opts)
    };
    match table {
        Ok(t) => {
            let _ = check_time(&t);
            let _ = check_units(&t);
            let s = summarize(&t);
            let _ = format!("{s:?}");
            let _ = aeromag::Flight::from_table(t);
        }
        Err(e) => assert!(!e.to_string().is_empty()),
    }
});
