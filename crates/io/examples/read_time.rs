//! Times `read_table` on a file: best of `N` reads (default 5).
//! Run: `cargo run --release -p aeromag-io --example read_time -- FILE [N]`.
//! `python tools/bench/peers.py read FILE.csv READ_TIME` runs it against pandas' `read_csv` on the same file.

use std::time::Instant;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let path = args.next().ok_or("usage: read_time FILE [N]")?;
    let n: usize = args.next().map_or(Ok(5), |a| a.parse())?;
    let mut best = f64::INFINITY;
    let mut rows = 0;
    for _ in 0..n.max(1) {
        let t = Instant::now();
        let table = aeromag_io::read_table(path.as_ref(), &aeromag_io::ReadOptions::default())?;
        best = best.min(t.elapsed().as_secs_f64());
        rows = table.n_rows();
    }
    println!("{best:.4} s best of {n} ({rows} rows)");
    Ok(())
}
