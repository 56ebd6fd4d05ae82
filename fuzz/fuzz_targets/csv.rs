//! CSV (and whitespace table) reader: `read_csv` / `read_table` on the bytes
//! as a file, then the checks and the summary on any table that parses.
//! The reading options depend on the input length (`len % 4`): default, the
//! format sniffed from content (`.txt`), a forced `;` delimiter, no preset.
#![no_main]

use aeromag_io::{Format, ReadOptions, check_time, check_units, read_csv, read_table, summarize};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let (name, opts) = match data.len() % 4 {
        0 => ("in.csv", ReadOptions::default()),
        1 => ("in.txt", ReadOptions::default()),
        2 => (
            "in.csv",
            ReadOptions {
                delimiter: Some(b';'),
                ..ReadOptions::default()
            },
        ),
        _ => (
            "in.csv",
            ReadOptions {
                magnav_preset: false,
                format: Format::Csv,
                ..ReadOptions::default()
            },
        ),
    };
    let path = aeromag_fuzz::scratch(name, data);
    let table = if name.ends_with(".txt") {
        read_table(&path, &opts)
    } else {
        read_csv(&path, &opts)
    };
    match table {
        Ok(t) => {
            let _ = check_time(&t);
            let _ = check_units(&t);
            let s = summarize(&t);
            let _ = format!("{s:?}");
            let _ = aeromag::Flight::from_table(t);
        }
        Err(e) => {
            // Every reader error is the user's input, with a message.
            assert!(!e.to_string().is_empty());
        }
    }
});
