//! Grid readers: `read_grid` on the bytes as a grid file whose extension
//! the first byte chooses (`.tif`, `.asc`, `.nc`, `.grd`: GMT's netCDF,
//! Surfer's or Geosoft's by the content, `.gxf`; seeds: Oasis montaj's
//! Geosoft grids of `crates/grid/tests/data/geosoft`, netCDF-4 grids of
//! `crates/grid/tests/data` and grids aeromag writes), then the grid's
//! statistics. Every malformed file must be an error naming the file,
//! never a panic or a huge allocation.
#![no_main]

use aeromag::grid::format::read_grid;
use libfuzzer_sys::fuzz_target;

/// The extensions the first byte chooses from.
const EXTENSIONS: [&str; 5] = ["tif", "asc", "nc", "grd", "gxf"];

fuzz_target!(|data: &[u8]| {
    let Some((&kind, bytes)) = data.split_first() else {
        return;
    };
    let ext = EXTENSIONS[usize::from(kind) % EXTENSIONS.len()];
    let path = aeromag_fuzz::scratch(&format!("in.{ext}"), bytes);
    match read_grid(&path) {
        Ok(g) => {
            let _ = g.stats();
        }
        Err(e) => assert!(e.to_string().contains("in."), "{e}"),
    }
});
