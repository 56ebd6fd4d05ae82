//! Read some fields of a flight file and print their sums: the unit of the
//! HDF5-against-CSV benchmark (`scripts/bench-hdf5.sh`), which times this
//! program on the same fields of an HDF5 file and of the equivalent CSV.
//!
//! Usage: `cargo run --release -p aeromag-io --example read_fields -- FILE FIELD...`

use aeromag_io::{Fields, ReadOptions, read_table};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let path = args.next().ok_or("usage: read_fields FILE FIELD...")?;
    let names: Vec<String> = args.collect();
    let opts = ReadOptions {
        fields: Fields::Only(names.clone()),
        magnav_preset: false,
        ..ReadOptions::default()
    };
    let table = read_table(path.as_ref(), &opts)?;
    for n in &names {
        let v = table.require(n)?;
        println!("{n}: {} values, sum {}", v.len(), v.iter().sum::<f64>());
    }
    Ok(())
}
