//! Grid an `x y z` text file by minimum curvature and print `x y z` of
//! every node (for comparisons with GMT `surface` and `grd2xyz`):
//! `cargo run --release -p aeromag-grid --example grid_xyz -- FILE XMIN XMAX YMIN YMAX CELL TENSION [MAX_SWEEPS [LIMIT [as-is]]]`
//! (`as-is`: solve on exactly the requested region, GMT's `-Qr`).

use aeromag_grid::GridGeometry;
use aeromag_grid::gridding::{MinCurvature, Points};

fn main() {
    let a: Vec<String> = std::env::args().collect();
    let num = |k: usize| a[k].parse::<f64>().expect("a number");
    let text = std::fs::read_to_string(&a[1]).expect("the points file");
    let (mut x, mut y, mut z) = (vec![], vec![], vec![]);
    for line in text.lines() {
        let v: Vec<f64> = line
            .split_whitespace()
            .map(|s| s.parse().unwrap())
            .collect();
        x.push(v[0]);
        y.push(v[1]);
        z.push(v[2]);
    }
    let g = GridGeometry::covering(num(2), num(3), num(4), num(5), num(6)).unwrap();
    let s = MinCurvature {
        tension: num(7),
        max_iterations: a.get(8).map_or(500, |s| s.parse().unwrap()),
        convergence: a.get(9).map(|s| s.parse().unwrap()),
        enlarge: a.get(10).is_none_or(|s| s != "as-is"),
        ..Default::default()
    };
    let t = std::time::Instant::now();
    let (values, report) = s.grid(Points::new(&x, &y, &z).unwrap(), g).unwrap();
    eprintln!("{:.3} s, {report:?}", t.elapsed().as_secs_f64());
    for j in (0..g.ny).rev() {
        for i in 0..g.nx {
            println!("{} {} {}", g.x(i), g.y(j), values[g.index(i, j)]);
        }
    }
}
