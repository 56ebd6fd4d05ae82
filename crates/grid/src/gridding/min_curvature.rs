//! Minimum-curvature gridding with tension (Smith & Wessel 1990).
//!
//! The surface `z(x, y)` solves `(1 − T) ∇⁴z − T ∇²z = 0` away from the
//! data, passes through the data, and meets at the grid's edges
//! `(1 − T) ∂²z/∂n² + T ∂z/∂n = 0`, `∂(∇²z)/∂n = 0` and, at the corners,
//! `∂²z/∂x∂y = 0` (Smith, W. H. F. & Wessel, P., 1990, *Gridding with
//! continuous curvature splines in tension*, Geophysics 55, 293–305; the
//! method of GMT `surface`). `T = 0` is the minimum-curvature (biharmonic)
//! spline of Briggs (1974), which overshoots between widely spaced lines;
//! `T = 1` is the harmonic (Laplace) surface, which has no overshoot but
//! cusps at the data; 0.25–0.35 is usual for potential-field data.
//!
//! **Discretisation** (unit node spacing `h`): at a node without data,
//! `(1 − T)(20 z₀ − 8 S₁ + 2 S₂ + S₃) − T (S₁ − 4 z₀) = 0`, with `S₁` the
//! sum of the four nearest nodes, `S₂` of the four diagonal ones and `S₃`
//! of the four at distance 2; this is `(1 − T)(Σₖ Cₖ − 4 C₀) − T C₀ = 0`
//! with `C` the five-point Laplacian (curvature) at the node and its four
//! neighbours. Data enter as in Briggs (1974, *Machine contouring using
//! minimum curvature*, Geophysics 39, 39–48) and Smith & Wessel: the
//! block mean `z_d` of the data nearest a node, at the offset `(δx, δy)`
//! (|δ| ≤ ½ node), replaces the two neighbours on its side in the node's
//! own curvature `C₀`. `C₀ = Σₚ aₚ (zₚ − z₀)` over the data point, the two
//! neighbours on the far side and the two diagonal nodes beside them; the
//! weights `aₚ` make `C₀` the exact Laplacian of every quadratic surface
//! (the second-order Taylor expansion about the node through those five
//! points, solved for `z_xx + z_yy`). The node then obeys the same
//! equation with this `C₀`: it is not pinned to the data, which keeps
//! inconsistent neighbouring data (mis-ties at crossings) from forcing
//! overshoots. Data within 0.05 node of a node fix it to the data's value.
//! The edge conditions fill two rows of ghost nodes outside the grid before
//! each sweep.
//!
//! **Solution**: a least-squares plane is removed from the data (and added
//! back); successive over-relaxation (Gauss–Seidel, rows from the north,
//! factor 1.4) on the sequence of grids GMT `surface` uses (Smith & Wessel
//! 1990, appendix): node spacings from the greatest common divisor of the
//! two interval counts down by its prime factors, largest first
//! ([`super::good_size`]). The coarsest grid starts at the plane. Each
//! finer grid starts from the bilinear interpolation of the coarser one,
//! is first relaxed with the coarser nodes held, then with the data: on
//! every grid the block nearest each node constrains it. Sweeps stop when
//! the largest change of a sweep is at most the convergence limit (default
//! 10⁻⁴ of the data's RMS about the plane, GMT's default) or after the
//! sweep limit, both scaled by the spacing on the coarser grids (limit ÷,
//! sweeps ×), as GMT. As GMT does by default, the solve runs on the
//! slightly larger grid whose dimensions have more common factors and is
//! cropped: the edge conditions hold at its edges, so this is also what
//! keeps the two agreeing near the requested edges.
//!
//! **Order**: every node reads the values it reads in the plain
//! Gauss–Seidel order, row after row from the north, so the result is the
//! same bits from run to run and for any number of threads. A node's update
//! waits on its west neighbour's (about 60 cycles), so a sweep works on
//! groups of four rows, each row two nodes behind the one north of it, and
//! the four rows' updates overlap in the processor; on grids of 2¹⁷ nodes
//! or more the groups are shared among up to four threads as a pipeline,
//! each group two nodes behind the last row of the group north of it. On a
//! 1738 × 2039-node grid (a 2 m cell on a small survey): 40.5 s with the
//! former row-after-row sweep, 10.8 s in groups on one thread, 6.9 s on two.
//!
//! **Against GMT**: converged, the result equals a direct sparse solve of
//! the finite-difference system (tools/validate/surface_direct.py) to
//! 10⁻⁶ nT. GMT iterates in single precision (values and data
//! coordinates), so on strongly inconsistent data (mis-ties at crossings)
//! its own tightly converged grid can stall nT away from that solution;
//! at the default limits both stop short of it, by similar amounts.

use super::good_size::{Enlargement, enlargement, strides};
use super::points::{BlockMeans, Points};
use crate::error::{GridError, Result};
use crate::grid::GridGeometry;
use aeromag_core::cancel::{Cancelled, check};
use std::sync::atomic::{AtomicUsize, Ordering};

/// Settings of minimum-curvature gridding (module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MinCurvature {
    /// Tension `T`, 0–1 (default 0.25).
    pub tension: f64,
    /// Most sweeps of each relaxation on the final grid, 1 to
    /// [`MAX_ITERATIONS`] (default 500, as GMT's `-N`); a coarser grid of
    /// spacing `s` cells gets `s` times as many.
    pub max_iterations: usize,
    /// Convergence limit: the largest change of a sweep, in the data's
    /// unit; `None` = 10⁻⁴ × the data's RMS about their plane.
    pub convergence: Option<f64>,
    /// Over-relaxation factor, 1–2 (default 1.4, as GMT).
    pub relaxation: f64,
    /// Solve on the slightly larger grid GMT `surface` would use and crop
    /// ([`super::good_size`]; default true, GMT's default; false is GMT's
    /// `-Qr`).
    pub enlarge: bool,
}

/// Most sweeps [`MinCurvature::max_iterations`] may ask for: 200 times
/// GMT's default. A limit of 10⁹ (accepted before) would keep a grid of
/// 10⁶ nodes sweeping for days; a solve that has not converged after 10⁵
/// sweeps needs a larger cell or a looser limit, not more sweeps.
pub const MAX_ITERATIONS: usize = 100_000;

impl Default for MinCurvature {
    fn default() -> Self {
        Self {
            tension: 0.25,
            max_iterations: 500,
            convergence: None,
            relaxation: 1.4,
            enlarge: true,
        }
    }
}

/// How a grid of the sequence converged.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct LevelReport {
    /// Node spacing of this grid, in cells of the final grid.
    pub spacing_cells: usize,
    /// Nodes along x.
    pub nx: usize,
    /// Nodes along y.
    pub ny: usize,
    /// Sweeps run.
    pub iterations: usize,
    /// Largest change of the last sweep, data unit.
    pub max_change: f64,
    /// The factor by which the largest change shrank per sweep over the
    /// last [`DECAY_WINDOW`] sweeps with the data (their geometric mean;
    /// NaN with fewer than two sweeps).
    pub decay_per_sweep: f64,
}

/// Sweeps over which [`LevelReport::decay_per_sweep`] is taken: the largest
/// change of one sweep jitters (it is one node's), its trend over 50
/// sweeps does not.
pub const DECAY_WINDOW: usize = 50;

impl LevelReport {
    /// How far the grid may still be from the converged one, data unit:
    /// the sum of the changes still to come if they keep shrinking by
    /// [`Self::decay_per_sweep`] a sweep, `max_change · r / (1 − r)`
    /// (infinite when they do not shrink, NaN when unknown). Over-relaxation
    /// converges geometrically once the slowest mode dominates, which it
    /// does by the sweep limit, so this is the order of the error and on
    /// the safe side: on the simulated survey stopped at 516 sweeps it is
    /// 2.99 nT, and the grid differs from the one converged with
    /// `--max-sweeps 5000` (1101 sweeps) by at most 1.36 nT (std 0.055).
    pub fn remaining_estimate(&self) -> f64 {
        let r = self.decay_per_sweep;
        if r.is_nan() {
            f64::NAN
        } else if r >= 1.0 {
            f64::INFINITY
        } else {
            self.max_change * r / (1.0 - r)
        }
    }
}

/// What the gridding did ([`MinCurvature::grid`]).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct MinCurvatureReport {
    /// The grids of the sequence, coarsest first.
    pub levels: Vec<LevelReport>,
    /// True when the final grid met the convergence limit.
    pub converged: bool,
    /// The convergence limit used, data unit.
    pub convergence_limit: f64,
    /// Nodes holding data (block means).
    pub constrained_nodes: usize,
    /// Finite points used.
    pub points_used: usize,
    /// Points skipped for a non-finite value or coordinate.
    pub points_non_finite: usize,
    /// Points more than half a cell outside the grid that was solved.
    pub points_outside: usize,
    /// Intervals added on each side for the solve, when enlarged.
    pub enlarged: Option<Enlargement>,
}

impl MinCurvatureReport {
    /// Sweeps run on the final grid (0 when none ran).
    pub fn final_sweeps(&self) -> usize {
        self.levels.last().map_or(0, |l| l.iterations)
    }

    /// The report of a grid made otherwise (no sweeps; the data counts of
    /// `means`).
    pub fn not_run(means: &BlockMeans) -> Self {
        Self {
            levels: Vec::new(),
            converged: true,
            convergence_limit: 0.0,
            constrained_nodes: means.blocks.len(),
            points_used: means.used,
            points_non_finite: means.non_finite,
            points_outside: means.outside,
            enlarged: None,
        }
    }
}

impl MinCurvature {
    /// The default settings with tension `tension`.
    pub fn with_tension(tension: f64) -> Self {
        Self {
            tension,
            ..Self::default()
        }
    }

    /// Check the settings.
    pub fn validate(&self) -> Result<()> {
        if !(0.0..=1.0).contains(&self.tension) {
            return Err(GridError::OutOfRange {
                name: "tension",
                value: self.tension,
                expected: "0 to 1",
            });
        }
        if !(self.relaxation >= 1.0 && self.relaxation < 2.0) {
            return Err(GridError::OutOfRange {
                name: "relaxation",
                value: self.relaxation,
                expected: "1 to 2 (exclusive)",
            });
        }
        if let Some(c) = self.convergence {
            crate::error::positive("convergence limit", c)?;
        }
        if !(1..=MAX_ITERATIONS).contains(&self.max_iterations) {
            return Err(GridError::OutOfRange {
                name: "max sweeps",
                value: self.max_iterations as f64,
                expected: "1 to 100000",
            });
        }
        Ok(())
    }

    /// Grid `points` on the nodes of `geometry` (at least 4 × 4 nodes):
    /// the node values (row by row from the south; no node is blank) and
    /// the report. Fewer than 3 nodes with data is an error.
    pub fn grid(
        &self,
        points: Points,
        geometry: GridGeometry,
    ) -> Result<(Vec<f64>, MinCurvatureReport)> {
        self.grid_cancellable(points, geometry, &mut aeromag_core::cancel::never)
    }

    /// [`Self::grid`], asking `cancel` ([`aeromag_core::cancel`]) before
    /// every sweep: [`GridError::Cancelled`] as soon as it says to stop.
    /// The same values as [`Self::grid`] when it never does.
    pub fn grid_cancellable(
        &self,
        points: Points,
        geometry: GridGeometry,
        cancel: &mut dyn FnMut() -> bool,
    ) -> Result<(Vec<f64>, MinCurvatureReport)> {
        self.validate()?;
        if geometry.nx < 4 || geometry.ny < 4 {
            return Err(GridError::Data(format!(
                "a {} × {} grid is too small for minimum curvature (at least 4 × 4 nodes)",
                geometry.nx, geometry.ny
            )));
        }
        let grown = self
            .enlarge
            .then(|| enlargement(geometry.nx - 1, geometry.ny - 1))
            .flatten();
        let Some(e) = grown else {
            return self.solve(points, geometry, cancel);
        };
        let big = GridGeometry {
            x0: geometry.x0 - e.west as f64 * geometry.cell,
            y0: geometry.y0 - e.south as f64 * geometry.cell,
            cell: geometry.cell,
            nx: geometry.nx + e.west + e.east,
            ny: geometry.ny + e.south + e.north,
        };
        let (all, mut report) = self.solve(points, big, cancel)?;
        report.enlarged = Some(e);
        let mut values = vec![0.0; geometry.len()];
        for j in 0..geometry.ny {
            for i in 0..geometry.nx {
                values[geometry.index(i, j)] = all[big.index(i + e.west, j + e.south)];
            }
        }
        Ok((values, report))
    }

    /// [`Self::grid`] on exactly `geometry`.
    fn solve(
        &self,
        points: Points,
        geometry: GridGeometry,
        cancel: &mut dyn FnMut() -> bool,
    ) -> Result<(Vec<f64>, MinCurvatureReport)> {
        let means = BlockMeans::of(points, &geometry);
        if means.blocks.len() < 3 {
            return Err(GridError::Data(format!(
                "{} grid nodes hold data ({} finite points inside the grid); at least 3 are needed",
                means.blocks.len(),
                means.used
            )));
        }
        let plane = Plane::fit(&means);
        let rms = (means
            .blocks
            .iter()
            .map(|b| (b.z - plane.at(b.u, b.v)).powi(2))
            .sum::<f64>()
            / means.blocks.len() as f64)
            .sqrt();
        // Residuals at the values' rounding are none: data on a plane gave a
        // limit of 10⁻¹⁶ nT that no sweep reached ("NOT converged").
        let scale = means.blocks.iter().fold(0.0f64, |m, b| m.max(b.z.abs()));
        let rms = if rms <= PLANE_ROUNDING * scale {
            0.0
        } else {
            rms
        };
        let limit = self.convergence.unwrap_or(1e-4 * rms);
        let mut report = MinCurvatureReport {
            levels: Vec::new(),
            converged: true,
            convergence_limit: limit,
            constrained_nodes: means.blocks.len(),
            points_used: means.used,
            points_non_finite: means.non_finite,
            points_outside: means.outside,
            enlarged: None,
        };
        let mut values = vec![0.0; geometry.len()];
        if rms > 0.0 {
            let strides = strides(geometry.nx - 1, geometry.ny - 1);
            let mut level: Option<Level> = None;
            for &stride in &strides {
                let mut next = Level::new(&geometry, stride, &means, &plane);
                // Coarse grids are cheap: more sweeps and a tighter limit
                // (× and ÷ the stride, as GMT).
                let (sweeps, limit_here) = (self.max_iterations * stride, limit / stride as f64);
                let mut iterations = 0;
                if let Some(coarse) = &level {
                    next.start_from(coarse);
                    let held = coarse.spacing / stride;
                    iterations += next
                        .solve(self, Phase::Between(held), limit_here, sweeps, cancel)?
                        .0;
                }
                let (data_sweeps, max_change, decay_per_sweep) =
                    next.solve(self, Phase::Data, limit_here, sweeps, cancel)?;
                iterations += data_sweeps;
                report.levels.push(LevelReport {
                    spacing_cells: stride,
                    nx: next.nx,
                    ny: next.ny,
                    iterations,
                    max_change,
                    decay_per_sweep,
                });
                if stride == 1 {
                    report.converged = max_change <= limit;
                    for j in 0..geometry.ny {
                        for i in 0..geometry.nx {
                            values[geometry.index(i, j)] = next.z[next.p(i as isize, j as isize)];
                        }
                    }
                }
                level = Some(next);
            }
        }
        for j in 0..geometry.ny {
            for i in 0..geometry.nx {
                values[geometry.index(i, j)] += plane.at(i as f64, j as f64);
            }
        }
        Ok((values, report))
    }
}

/// The RMS of the block means about their plane, relative to their
/// largest magnitude, below which they are taken as the plane itself (the
/// grid is the plane; no sweep): a few hundred times the rounding of one
/// value (2.2·10⁻¹⁶), as the plane's fit and the block means round.
const PLANE_ROUNDING: f64 = 1e-13;

/// The least-squares plane `z = a + b (u − ū) + c (v − v̄)` of the block
/// means (node units).
#[derive(Debug, Clone, Copy)]
struct Plane {
    a: f64,
    b: f64,
    c: f64,
    u0: f64,
    v0: f64,
}

impl Plane {
    fn fit(m: &BlockMeans) -> Self {
        let n = m.blocks.len() as f64;
        let u0 = m.blocks.iter().map(|b| b.u).sum::<f64>() / n;
        let v0 = m.blocks.iter().map(|b| b.v).sum::<f64>() / n;
        let a = m.blocks.iter().map(|b| b.z).sum::<f64>() / n;
        let (mut suu, mut suv, mut svv, mut suz, mut svz) = (0.0, 0.0, 0.0, 0.0, 0.0);
        for b in &m.blocks {
            let (du, dv, dz) = (b.u - u0, b.v - v0, b.z - a);
            suu += du * du;
            suv += du * dv;
            svv += dv * dv;
            suz += du * dz;
            svz += dv * dz;
        }
        let det = suu * svv - suv * suv;
        // Collinear data (one line) do not determine a plane: the mean only.
        let (b, c) = if det > 1e-12 * (suu * svv).max(f64::MIN_POSITIVE) {
            ((svv * suz - suv * svz) / det, (suu * svz - suv * suz) / det)
        } else {
            (0.0, 0.0)
        };
        Self { a, b, c, u0, v0 }
    }

    fn at(&self, u: f64, v: f64) -> f64 {
        self.a + self.b * (u - self.u0) + self.c * (v - self.v0)
    }
}

/// A node's data: block mean minus the plane, at the offset `(dx, dy)`
/// from the node (node units of its level), and `z_node`: the data moved
/// onto the node, i.e. the same value minus the plane at the node (what a
/// node fixed by the data takes, as GMT does).
#[derive(Debug, Clone, Copy)]
struct Constraint {
    dx: f64,
    dy: f64,
    z: f64,
    z_node: f64,
}

/// How a node with data is updated (module docs).
#[derive(Debug, Clone, Copy)]
enum NodeData {
    /// The data sit on the node: its value.
    Fixed(f64),
    /// The node's curvature `C₀ = Σₚ a[p] (z_p − z₀)` over the four nodes
    /// at the padded-index offsets `at` and the data value `z` (weight
    /// `a[4]`).
    Curvature { at: [isize; 4], a: [f64; 5], z: f64 },
}

/// Data closer than this to a node (in node units, each axis) fix it.
const ON_NODE: f64 = 0.05;

impl NodeData {
    /// The update rule of a node with the data `c`, for padded rows of
    /// `width` values.
    fn of(c: Constraint, width: usize) -> Self {
        if c.dx.abs() < ON_NODE && c.dy.abs() < ON_NODE {
            return NodeData::Fixed(c.z_node);
        }
        let (sx, sy) = (
            if c.dx >= 0.0 { 1isize } else { -1 },
            if c.dy >= 0.0 { 1isize } else { -1 },
        );
        // The far-side neighbours and the diagonals beside them, then the data.
        let nodes = [(-sx, 0), (0, -sy), (sx, -sy), (-sx, sy)];
        let mut pts = [(0.0, 0.0); 5];
        for (q, &(i, j)) in pts.iter_mut().zip(&nodes) {
            *q = (i as f64, j as f64);
        }
        pts[4] = (c.dx, c.dy);
        match laplacian_weights(&pts) {
            Some(a) => NodeData::Curvature {
                at: nodes.map(|(i, j)| j * width as isize + i),
                a,
                z: c.z,
            },
            None => NodeData::Fixed(c.z_node),
        }
    }
}

/// Weights `a` with `Σₚ a[p] (z(pₚ) − z(0)) = z_xx + z_yy` for every
/// quadratic surface `z`, through the five points `p` (node units about
/// the node): `Mᵀ a = e`, `M`'s rows `(x, y, x²/2, y²/2, xy)`, `e` picking
/// `z_xx + z_yy`. `None` when the points do not determine it.
fn laplacian_weights(p: &[(f64, f64); 5]) -> Option<[f64; 5]> {
    // Augmented Mᵀ: row r = monomial r over the points, then e[r].
    let mut m = [[0.0f64; 6]; 5];
    for (k, &(x, y)) in p.iter().enumerate() {
        let mono = [x, y, 0.5 * x * x, 0.5 * y * y, x * y];
        for r in 0..5 {
            m[r][k] = mono[r];
        }
    }
    m[2][5] = 1.0;
    m[3][5] = 1.0;
    // Gaussian elimination with partial pivoting.
    for col in 0..5 {
        let piv = (col..5).max_by(|&a, &b| m[a][col].abs().total_cmp(&m[b][col].abs()))?;
        if m[piv][col].abs() < 1e-9 {
            return None;
        }
        m.swap(col, piv);
        let pivot_row = m[col];
        for (r, row) in m.iter_mut().enumerate() {
            if r != col {
                let f = row[col] / pivot_row[col];
                for (x, p) in row[col..].iter_mut().zip(&pivot_row[col..]) {
                    *x -= f * p;
                }
            }
        }
    }
    let mut a = [0.0; 5];
    for (r, v) in a.iter_mut().enumerate() {
        *v = m[r][5] / m[r][r];
    }
    Some(a)
}

/// One grid of the sequence, with two ghost rows and columns on each side.
struct Level {
    nx: usize,
    ny: usize,
    spacing: usize,
    /// Padded values, `(ny + 4) × (nx + 4)`.
    z: Vec<f64>,
    /// Per node, unpadded, row by row: [`FREE`], or the index in `nodes`
    /// of its data (4 bytes a node: the data themselves, 88 bytes, took
    /// 5 GB on a grid of 56 million nodes).
    slot: Vec<u32>,
    /// The data of the nodes that have them.
    nodes: Vec<NodeData>,
    /// Rows a sweep works on together ([`WAVE_ROWS`]; 1 is the plain order
    /// of one row after another, which the tests compare with).
    wave_rows: usize,
    /// Threads of a sweep; `None`: chosen by the grid's size.
    threads: Option<usize>,
}

/// The slot of a node without data.
const FREE: u32 = u32::MAX;

/// Rows a sweep works on together, each two nodes behind the one north of
/// it ([`Level::solve`]).
const WAVE_ROWS: usize = 4;

const PAD: usize = 2;

impl Level {
    fn new(g: &GridGeometry, spacing: usize, m: &BlockMeans, plane: &Plane) -> Self {
        let nx = (g.nx - 1) / spacing + 1;
        let ny = (g.ny - 1) / spacing + 1;
        let s = spacing as f64;
        // The block nearest each node of this grid constrains it (as GMT
        // keeps the nearest point); on the final grid every block has its
        // own node (a block mean can sit exactly halfway, on the even side).
        let mut nearest: Vec<Option<(f64, usize)>> = vec![None; nx * ny];
        for (k, b) in m.blocks.iter().enumerate() {
            let (u, v) = (b.u / s, b.v / s);
            let (i, j) = if spacing == 1 {
                (b.i, b.j)
            } else {
                ((u + 0.5).floor() as usize, (v + 0.5).floor() as usize)
            };
            if i < nx && j < ny {
                let d2 = (u - i as f64).powi(2) + (v - j as f64).powi(2);
                let e = &mut nearest[j * nx + i];
                if e.is_none_or(|(d, _)| d2 < d) {
                    *e = Some((d2, k));
                }
            }
        }
        let width = nx + 2 * PAD;
        let mut nodes = Vec::new();
        let slot = nearest
            .iter()
            .enumerate()
            .map(|(n, e)| match e {
                None => FREE,
                Some((_, k)) => {
                    let b = &m.blocks[*k];
                    let (dx, dy) = (b.u / s - (n % nx) as f64, b.v / s - (n / nx) as f64);
                    let z = b.z - plane.at(b.u, b.v);
                    nodes.push(NodeData::of(
                        Constraint {
                            dx,
                            dy,
                            z,
                            z_node: z + s * (plane.b * dx + plane.c * dy),
                        },
                        width,
                    ));
                    (nodes.len() - 1) as u32
                }
            })
            .collect();
        Self {
            nx,
            ny,
            spacing,
            z: vec![0.0; (nx + 2 * PAD) * (ny + 2 * PAD)],
            slot,
            nodes,
            wave_rows: WAVE_ROWS,
            threads: None,
        }
    }

    /// The data of node `n` (unpadded index), if any.
    fn data(&self, n: usize) -> Option<NodeData> {
        let k = self.slot[n];
        (k != FREE).then(|| self.nodes[k as usize])
    }

    fn width(&self) -> usize {
        self.nx + 2 * PAD
    }

    /// Index of node `(i, j)` in the padded values (−2 ≤ i ≤ nx + 1).
    fn p(&self, i: isize, j: isize) -> usize {
        ((j + PAD as isize) as usize) * self.width() + (i + PAD as isize) as usize
    }

    /// Start from the bilinear interpolation of the next coarser grid (its
    /// nodes are every `coarse.spacing / self.spacing` nodes of this one).
    fn start_from(&mut self, coarse: &Level) {
        let r = coarse.spacing as f64 / self.spacing as f64;
        for j in 0..self.ny {
            for i in 0..self.nx {
                let (u, v) = (i as f64 / r, j as f64 / r);
                let (ci, cj) = (
                    (u.floor() as usize).min(coarse.nx - 2),
                    (v.floor() as usize).min(coarse.ny - 2),
                );
                let (fu, fv) = (u - ci as f64, v - cj as f64);
                let at = |a: usize, b: usize| coarse.z[coarse.p(a as isize, b as isize)];
                let val = (1.0 - fv) * ((1.0 - fu) * at(ci, cj) + fu * at(ci + 1, cj))
                    + fv * ((1.0 - fu) * at(ci, cj + 1) + fu * at(ci + 1, cj + 1));
                let p = self.p(i as isize, j as isize);
                self.z[p] = val;
            }
        }
    }

    /// Fill the ghost nodes from the edge conditions (module docs).
    fn fill_ghosts(&mut self, t: f64) {
        let (nx, ny) = (self.nx as isize, self.ny as isize);
        let w = self.width() as isize;
        // First ghost row/column: (1−T)(z₁ − 2z₀ + z₋₁) − T (z₁ − z₋₁)/2 = 0.
        let ghost1 =
            |z0: f64, z1: f64| ((1.0 - t) * (2.0 * z0 - z1) + 0.5 * t * z1) / (1.0 - 0.5 * t);
        // (edge node, inward step, outward step) for the four edges.
        for j in 0..ny {
            for (i0, inward) in [(0, 1), (nx - 1, -1)] {
                let p0 = self.p(i0, j) as isize;
                let (z0, z1) = (self.z[p0 as usize], self.z[(p0 + inward) as usize]);
                self.z[(p0 - inward) as usize] = ghost1(z0, z1);
            }
        }
        for i in 0..nx {
            for (j0, inward) in [(0, w), (ny - 1, -w)] {
                let p0 = self.p(i, j0) as isize;
                let (z0, z1) = (self.z[p0 as usize], self.z[(p0 + inward) as usize]);
                self.z[(p0 - inward) as usize] = ghost1(z0, z1);
            }
        }
        // Corners: ∂²z/∂x∂y = 0 ⇒ z(−1,−1) = z(−1,1) + z(1,−1) − z(1,1).
        for (ci, si) in [(0, 1), (nx - 1, -1)] {
            for (cj, sj) in [(0, 1), (ny - 1, -1)] {
                let v = self.z[self.p(ci - si, cj + sj)] + self.z[self.p(ci + si, cj - sj)]
                    - self.z[self.p(ci + si, cj + sj)];
                let p = self.p(ci - si, cj - sj);
                self.z[p] = v;
            }
        }
        // Second ghost: ∂(∇²z)/∂n = 0 ⇒ ∇²z(−1) = ∇²z(1) across the edge.
        let lap = |z: &[f64], p: isize, dx: isize, dy: isize| {
            z[(p + dx) as usize]
                + z[(p - dx) as usize]
                + z[(p + dy) as usize]
                + z[(p - dy) as usize]
                - 4.0 * z[p as usize]
        };
        for j in 0..ny {
            for (i0, inward) in [(0isize, 1isize), (nx - 1, -1)] {
                let p0 = self.p(i0, j) as isize;
                let l1 = lap(&self.z, p0 + inward, 1, w);
                let m1 = p0 - inward;
                let v = l1
                    - self.z[p0 as usize]
                    - self.z[(m1 + w) as usize]
                    - self.z[(m1 - w) as usize]
                    + 4.0 * self.z[m1 as usize];
                self.z[(p0 - 2 * inward) as usize] = v;
            }
        }
        for i in 0..nx {
            for (j0, inward) in [(0isize, w), (ny - 1, -w)] {
                let p0 = self.p(i, j0) as isize;
                let l1 = lap(&self.z, p0 + inward, 1, w);
                let m1 = p0 - inward;
                let v = l1
                    - self.z[p0 as usize]
                    - self.z[(m1 + 1) as usize]
                    - self.z[(m1 - 1) as usize]
                    + 4.0 * self.z[m1 as usize];
                self.z[(p0 - 2 * inward) as usize] = v;
            }
        }
    }

    /// Over-relaxed sweeps, rows from the north as GMT, until the largest
    /// change of a sweep is at most `limit` or after `max_sweeps`: (sweeps,
    /// largest change of the last one, the factor it shrank by per sweep
    /// over the last [`DECAY_WINDOW`] sweeps).
    ///
    /// A node's update waits for the one before it (its west neighbour,
    /// just updated), about 60 cycles of latency. So [`WAVE_ROWS`] rows are
    /// worked on together, each two nodes behind the row north of it: the
    /// node then reads exactly the values it reads when the rows are swept
    /// one after another (its north neighbours already updated, its south
    /// ones not yet), so the result is the same to the bit, and the rows'
    /// updates overlap in the processor.
    ///
    /// `cancel` is asked before every sweep; when it says to stop, the
    /// level is left as it is and [`Cancelled`] returned.
    fn solve(
        &mut self,
        s: &MinCurvature,
        phase: Phase,
        limit: f64,
        max_sweeps: usize,
        cancel: &mut dyn FnMut() -> bool,
    ) -> std::result::Result<(usize, f64, f64), Cancelled> {
        let t = s.tension;
        let (nx, ny, w) = (self.nx, self.ny, self.width());
        let denom = 20.0 * (1.0 - t) + 4.0 * t;
        if phase == Phase::Data {
            for n in 0..nx * ny {
                if let Some(NodeData::Fixed(v)) = self.data(n) {
                    let p = self.p((n % nx) as isize, (n / nx) as isize);
                    self.z[p] = v;
                }
            }
        }
        // Per column and per row, whether it holds the coarser grid's nodes.
        let held_in = |n: usize| match phase {
            Phase::Between(held) => (0..n).map(|i| i.is_multiple_of(held)).collect(),
            Phase::Data => Vec::new(),
        };
        let (held_columns, held_rows): (Vec<bool>, Vec<bool>) = (held_in(nx), held_in(ny));
        // Taken for the sweeps, which change only `z` (and its ghosts).
        let (nodes, slot) = (
            std::mem::take(&mut self.nodes),
            std::mem::take(&mut self.slot),
        );
        let sweep = Sweep {
            phase,
            t,
            relaxation: s.relaxation,
            denom,
            nx,
            w,
            held_rows: &held_rows,
            held_columns: &held_columns,
            slot: &slot,
            nodes: &nodes,
        };
        // Groups of rows from the north: (top row + 1, rows).
        let mut groups = Vec::new();
        let mut top = ny;
        while top > 0 {
            let rows = top.min(self.wave_rows);
            groups.push((top, rows));
            top -= rows;
        }
        let threads = match self.threads {
            Some(n) => n,
            None if nx * ny >= THREADED_NODES && nx >= 64 => {
                aeromag_core::parallel::threads().min(MAX_SWEEP_THREADS)
            }
            None => 1,
        }
        .clamp(1, groups.len());
        let done: Vec<AtomicUsize> = groups.iter().map(|_| AtomicUsize::new(0)).collect();
        let mut change = f64::INFINITY;
        let mut sweeps = 0;
        // The last DECAY_WINDOW + 1 changes, a ring.
        let mut recent = [f64::NAN; DECAY_WINDOW + 1];
        while sweeps < max_sweeps {
            if let Err(c) = check(cancel) {
                (self.nodes, self.slot) = (nodes, slot);
                return Err(c);
            }
            self.fill_ghosts(t);
            let z = Padded(self.z.as_mut_ptr());
            done.iter().for_each(|d| d.store(0, Ordering::Relaxed));
            // Thread k sweeps groups k, k + threads, …; its largest change.
            let part = |k: usize| -> f64 {
                let z = &z;
                // Should this thread panic, its groups are marked done, so
                // that the others do not wait for them for ever (the panic
                // then ends the sweep).
                let _unblock = Unblock {
                    done: &done,
                    first: k,
                    every: threads,
                };
                let mut change = 0.0f64;
                for g in (k..groups.len()).step_by(threads) {
                    let before = g.checked_sub(1).map(|h| (&done[h], groups[h].1));
                    // SAFETY: `z` is the padded grid, each node written by
                    // the one thread sweeping its group; see `Sweep::group`.
                    change = change.max(unsafe { sweep.group(z, groups[g], before, &done[g]) });
                }
                change
            };
            change = if threads == 1 {
                part(0)
            } else {
                std::thread::scope(|scope| {
                    let others: Vec<_> =
                        (1..threads).map(|k| scope.spawn(move || part(k))).collect();
                    others
                        .into_iter()
                        .map(|h| h.join().expect("a sweep thread panicked"))
                        .fold(part(0), f64::max)
                })
            };
            recent[sweeps % recent.len()] = change;
            sweeps += 1;
            if change <= limit {
                break;
            }
        }
        (self.nodes, self.slot) = (nodes, slot);
        let span = (sweeps.saturating_sub(1)).min(DECAY_WINDOW);
        let decay = if span == 0 {
            f64::NAN
        } else {
            let first = recent[(sweeps - 1 - span) % recent.len()];
            (change / first).powf(1.0 / span as f64)
        };
        Ok((sweeps, change, decay))
    }
}

/// Nodes from which a sweep's rows are shared among threads.
const THREADED_NODES: usize = 1 << 17;

/// Most threads a sweep takes: the groups of rows form a pipeline, each
/// waiting on the one north of it.
const MAX_SWEEP_THREADS: usize = 4;

/// Completed steps a group publishes at once.
const PUBLISH_EVERY: usize = 16;

/// On a panic of a sweep's thread, its groups' counters set past any
/// step (see `Level::solve`).
struct Unblock<'a> {
    done: &'a [AtomicUsize],
    first: usize,
    every: usize,
}

impl Drop for Unblock<'_> {
    fn drop(&mut self) {
        if std::thread::panicking() {
            for d in self.done.iter().skip(self.first).step_by(self.every) {
                d.store(usize::MAX, Ordering::Release);
            }
        }
    }
}

/// The padded values of a level, written by the threads of a sweep.
#[derive(Clone, Copy)]
struct Padded(*mut f64);

// SAFETY: the threads of a sweep write disjoint rows (their groups) and read
// another thread's rows only as the progress counters allow
// (`Sweep::group`).
unsafe impl Send for Padded {}
unsafe impl Sync for Padded {}

/// What one sweep of a level needs to update its nodes.
struct Sweep<'a> {
    phase: Phase,
    t: f64,
    relaxation: f64,
    denom: f64,
    nx: usize,
    /// Padded row width.
    w: usize,
    held_rows: &'a [bool],
    held_columns: &'a [bool],
    slot: &'a [u32],
    nodes: &'a [NodeData],
}

impl Sweep<'_> {
    /// Update node (i, j) at padded index `p`; the size of its step.
    ///
    /// # Safety
    /// `z` is the padded grid of this level and (i, j) a node of it (so
    /// `p ± 2w ± 2` lie inside), and no other thread writes the nodes it
    /// reads meanwhile.
    #[inline(always)]
    unsafe fn update(&self, z: Padded, i: usize, j: usize, p: usize) -> f64 {
        let (t, w) = (self.t, self.w);
        let data = match self.phase {
            Phase::Between(_) if self.held_rows[j] && self.held_columns[i] => return 0.0,
            Phase::Between(_) => None,
            Phase::Data => match self.slot[j * self.nx + i] {
                FREE => None,
                k => Some(self.nodes[k as usize]),
            },
        };
        // SAFETY: as the caller promises.
        let at = |q: usize| unsafe { *z.0.add(q) };
        let s1 = at(p + 1) + at(p - 1) + at(p + w) + at(p - w);
        let s2 = at(p + w + 1) + at(p + w - 1) + at(p - w + 1) + at(p - w - 1);
        let s3 = at(p + 2) + at(p - 2) + at(p + 2 * w) + at(p - 2 * w);
        let around = (1.0 - t) * (4.0 * s1 - 2.0 * s2 - s3);
        let target = match data {
            None => (around + (4.0 - 3.0 * t) * s1) / self.denom,
            Some(NodeData::Fixed(_)) => return 0.0,
            // (1 − T)(Σₖ Cₖ − 4 C₀) − T C₀ = 0 with
            // C₀ = Σ aₚ zₚ − A z₀ (module docs), solved for z₀.
            Some(NodeData::Curvature { at: o, a, z: zd }) => {
                let q = |k: usize| at(p.wrapping_add_signed(o[k]));
                let sum = a[0] * q(0) + a[1] * q(1) + a[2] * q(2) + a[3] * q(3) + a[4] * zd;
                let big_a = a.iter().sum::<f64>();
                (around + (4.0 - 3.0 * t) * sum) / (4.0 * (1.0 - t) * (1.0 + big_a) + t * big_a)
            }
        };
        let step = self.relaxation * (target - at(p));
        // SAFETY: as the caller promises.
        unsafe { *z.0.add(p) += step };
        step.abs()
    }

    /// Sweep the group of `rows` rows below row `top` (exclusive), row r
    /// (from the group's north) at node `step − 2r`, publishing its
    /// completed steps in `done`; `before` is the group north of it (its
    /// counter and rows), on another thread. Its largest step.
    ///
    /// The group's first row at node i reads the row north of it at
    /// i + 1, which that group's last row updates at its step
    /// i + 1 + 2 (rows − 1): so the group waits until the one before has
    /// completed step i + 2·rows. The group before reads this group's rows
    /// only at nodes this group reaches later (the same two-node lag), so
    /// every node reads the values of the plain order, row after row.
    ///
    /// # Safety
    /// `z` is the padded grid; every group is swept by one thread, after
    /// `done` of every group was reset to 0.
    unsafe fn group(
        &self,
        z: &Padded,
        (top, rows): (usize, usize),
        before: Option<(&AtomicUsize, usize)>,
        done: &AtomicUsize,
    ) -> f64 {
        let nx = self.nx;
        let lag = 2 * (rows - 1);
        let row_start = |j: usize| (j + PAD) * self.w + PAD;
        let mut change = 0.0f64;
        let mut known = 0;
        for step in 0..nx + lag {
            if let Some((counter, rows_before)) = before {
                let need = (step + 2 * rows_before).min(nx + 2 * (rows_before - 1));
                let mut spins = 0u32;
                while known < need {
                    known = counter.load(Ordering::Acquire);
                    if known < need {
                        spins += 1;
                        if spins < 1 << 10 {
                            std::hint::spin_loop();
                        } else {
                            std::thread::yield_now();
                        }
                    }
                }
            }
            // Rows 0..rows at nodes step, step − 2, …, inside the grid.
            let first = step.saturating_sub(nx - 1).div_ceil(2);
            let last = (step / 2).min(rows - 1);
            for r in first..=last {
                let (i, j) = (step - 2 * r, top - 1 - r);
                // SAFETY: (i, j) is a node; see above for the threads.
                change = change.max(unsafe { self.update(*z, i, j, row_start(j) + i) });
            }
            if (step + 1).is_multiple_of(PUBLISH_EVERY) {
                done.store(step + 1, Ordering::Release);
            }
        }
        done.store(nx + lag, Ordering::Release);
        change
    }
}

/// What a sweep solves for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Phase {
    /// Refine a grid just interpolated from the coarser one, whose nodes
    /// (every `held` nodes) stay fixed; no data.
    Between(usize),
    /// The data constraints of this grid; every other node free.
    Data,
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Points along north–south lines every `line_cells` cells, a point
    /// every 0.3 cell, of `f(x, y)`.
    fn lines(
        g: &GridGeometry,
        line_cells: usize,
        f: impl Fn(f64, f64) -> f64,
    ) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
        let (mut x, mut y, mut z) = (vec![], vec![], vec![]);
        let mut i = 0;
        while i < g.nx {
            let xl = g.x(i) + 0.2 * g.cell;
            let mut yl = g.y0;
            while yl <= g.y_max() {
                x.push(xl);
                y.push(yl);
                z.push(f(xl, yl));
                yl += 0.3 * g.cell;
            }
            i += line_cells;
        }
        (x, y, z)
    }

    fn rms(a: &[f64]) -> f64 {
        (a.iter().map(|v| v * v).sum::<f64>() / a.len() as f64).sqrt()
    }

    #[test]
    fn curvature_weights_are_exact_for_quadratic_surfaces() {
        let q = |x: f64, y: f64| 3.0 + 2.0 * x - y + 1.5 * x * x - 0.7 * y * y + 0.4 * x * y;
        for (dx, dy) in [
            (0.3, 0.2),
            (-0.45, 0.1),
            (0.0, -0.3),
            (-0.2, -0.49),
            (0.5, 0.5),
        ] {
            let c = Constraint {
                dx,
                dy,
                z: q(dx, dy),
                z_node: f64::NAN,
            };
            let NodeData::Curvature { at, a, z } = NodeData::of(c, 100) else {
                panic!("({dx}, {dy}) fixed");
            };
            let pos = |o: isize| {
                let (j, i) = (o.div_euclid(100), o.rem_euclid(100));
                let (i, j) = if i > 50 { (i - 100, j + 1) } else { (i, j) };
                (i as f64, j as f64)
            };
            let mut lap = a[4] * (z - q(0.0, 0.0));
            for k in 0..4 {
                let (x, y) = pos(at[k]);
                lap += a[k] * (q(x, y) - q(0.0, 0.0));
            }
            assert!((lap - (3.0 - 1.4)).abs() < 1e-9, "({dx}, {dy}): {lap}");
        }
        let on = NodeData::of(
            Constraint {
                dx: 0.01,
                dy: -0.04,
                z: 7.0,
                z_node: 7.5,
            },
            100,
        );
        assert!(matches!(on, NodeData::Fixed(7.5)));
    }

    #[test]
    fn a_plane_is_reproduced_exactly() {
        let g = GridGeometry::covering(0.0, 2000.0, 0.0, 1500.0, 50.0).unwrap();
        let f = |x: f64, y: f64| 3.0 + 0.01 * x - 0.02 * y;
        let (x, y, z) = lines(&g, 8, f);
        let (v, rep) = MinCurvature::default()
            .grid(Points::new(&x, &y, &z).unwrap(), g)
            .unwrap();
        assert!(rep.converged);
        for j in 0..g.ny {
            for i in 0..g.nx {
                assert!((v[g.index(i, j)] - f(g.x(i), g.y(j))).abs() < 1e-9);
            }
        }
    }

    /// Points off the nodes on a plane far from zero (a field of 50 000
    /// nT): the block means' residuals are the rounding's, the grid is the
    /// plane, converged without a sweep (it ran 580 sweeps to a limit of
    /// 10⁻¹⁶ nT and said "NOT converged"); a residual of 10⁻⁶ nT is solved.
    #[test]
    fn points_on_a_plane_far_from_zero_give_the_plane_converged() {
        let g = GridGeometry::covering(0.0, 2000.0, 0.0, 1500.0, 50.0).unwrap();
        let f = |x: f64, y: f64| 50_000.0 + 0.01 * x - 0.02 * y;
        let (x, y, _) = lines(&g, 8, f);
        let (x, y): (Vec<f64>, Vec<f64>) =
            x.iter().zip(&y).map(|(x, y)| (x + 7.3, y + 3.1)).unzip();
        let z: Vec<f64> = x.iter().zip(&y).map(|(&x, &y)| f(x, y)).collect();
        let (v, rep) = MinCurvature::default()
            .grid(Points::new(&x, &y, &z).unwrap(), g)
            .unwrap();
        assert!(rep.converged && rep.levels.is_empty(), "{rep:?}");
        for j in 0..g.ny {
            for i in 0..g.nx {
                assert!((v[g.index(i, j)] - f(g.x(i), g.y(j))).abs() < 1e-8);
            }
        }
        let bumped: Vec<f64> = z
            .iter()
            .enumerate()
            .map(|(k, z)| z + if k % 97 == 0 { 1e-6 } else { 0.0 })
            .collect();
        let (_, rep) = MinCurvature::default()
            .grid(Points::new(&x, &y, &bumped).unwrap(), g)
            .unwrap();
        assert!(!rep.levels.is_empty(), "{rep:?}");
    }

    #[test]
    fn a_smooth_field_between_lines_is_interpolated_for_every_tension() {
        // An anomaly of wavelength ≫ the line spacing (8 cells).
        let g = GridGeometry::covering(0.0, 6000.0, 0.0, 4000.0, 50.0).unwrap();
        let f = |x: f64, y: f64| {
            100.0
                * (-((x - 3000.0).powi(2) + (y - 2000.0).powi(2)) / (2.0 * 900.0f64.powi(2))).exp()
        };
        let (x, y, z) = lines(&g, 8, f);
        let mut std = 0.0;
        let mut errors = vec![];
        for t in [0.0, 0.25, 0.5, 1.0] {
            let s = MinCurvature {
                tension: t,
                ..Default::default()
            };
            let (v, rep) = s.grid(Points::new(&x, &y, &z).unwrap(), g).unwrap();
            assert!(rep.converged, "T = {t}: {rep:?}");
            let err: Vec<f64> = (0..g.len())
                .map(|k| v[k] - f(g.x(k % g.nx), g.y(k / g.nx)))
                .collect();
            let truth: Vec<f64> = (0..g.len())
                .map(|k| f(g.x(k % g.nx), g.y(k / g.nx)))
                .collect();
            std = rms(&truth);
            errors.push(rms(&err) / std);
        }
        eprintln!("relative RMS errors for T = 0, 0.25, 0.5, 1: {errors:?}");
        assert!(std > 10.0);
        // The splines in tension interpolate the smooth field to 2 %; the
        // harmonic surface (T = 1) has cusps at the lines and does worse.
        assert!(errors[..3].iter().all(|&e| e < 0.02), "{errors:?}");
        assert!(errors[3] > errors[1] && errors[3] < 0.05, "{errors:?}");
    }

    #[test]
    fn the_result_is_bit_identical_from_run_to_run() {
        let g = GridGeometry::covering(0.0, 3000.0, 0.0, 2000.0, 50.0).unwrap();
        let (x, y, z) = lines(&g, 6, |x, y| (x / 700.0).sin() * (y / 500.0).cos());
        let p = Points::new(&x, &y, &z).unwrap();
        let a = MinCurvature::default().grid(p, g).unwrap().0;
        let b = MinCurvature::default().grid(p, g).unwrap().0;
        assert!(a.iter().zip(&b).all(|(a, b)| a.to_bits() == b.to_bits()));
    }

    /// Sweeping several rows together, each two nodes behind the one
    /// north of it, on one thread or with the groups of rows shared among
    /// threads, gives the plain order's values to the bit, in both
    /// phases, on a grid whose data include nodes fixed and nodes with a
    /// curvature rule, with a group of rows left over at the south edge.
    #[test]
    fn rows_swept_together_give_the_plain_order_to_the_bit() {
        let g = GridGeometry::covering(0.0, 1500.0, 0.0, 1050.0, 50.0).unwrap();
        assert_eq!(g.ny % WAVE_ROWS, 2);
        let f = |x: f64, y: f64| (x / 300.0).sin() * (y / 200.0).cos();
        let (mut x, mut y, mut z) = lines(&g, 4, f);
        // A few data on nodes, which fix them.
        for k in 1..6 {
            let (xk, yk) = (
                g.x0 + 5.0 * g.cell * k as f64,
                g.y0 + 3.0 * g.cell * k as f64,
            );
            x.push(xk);
            y.push(yk);
            z.push(f(xk, yk));
        }
        let means = BlockMeans::of(Points::new(&x, &y, &z).unwrap(), &g);
        let plane = Plane::fit(&means);
        let kinds = |l: &Level| {
            let fixed = l.nodes.iter().filter(|d| matches!(d, NodeData::Fixed(_)));
            (fixed.count(), l.nodes.len())
        };
        let s = MinCurvature::default();
        let coarse = {
            let mut c = Level::new(&g, 2, &means, &plane);
            c.solve(&s, Phase::Data, 0.0, 5, &mut aeromag_core::cancel::never)
                .unwrap();
            c
        };
        for phase in [Phase::Between(2), Phase::Data] {
            let run = |rows: usize, threads: usize| {
                let mut l = Level::new(&g, 1, &means, &plane);
                let (fixed, all) = kinds(&l);
                assert!(fixed > 0 && all > fixed, "{fixed} of {all}");
                l.start_from(&coarse);
                l.wave_rows = rows;
                l.threads = Some(threads);
                let (sweeps, change, _) = l
                    .solve(&s, phase, 0.0, 7, &mut aeromag_core::cancel::never)
                    .unwrap();
                assert_eq!(sweeps, 7);
                (l.z, change)
            };
            let (plain, c1) = run(1, 1);
            for (rows, threads) in [
                (2, 1),
                (WAVE_ROWS, 1),
                (7, 1),
                (1, 2),
                (WAVE_ROWS, 2),
                (WAVE_ROWS, 3),
                (2, 4),
            ] {
                let (wave, c) = run(rows, threads);
                let case = format!("{phase:?}, {rows} rows, {threads} threads");
                assert_eq!(c.to_bits(), c1.to_bits(), "{case}");
                assert!(
                    plain
                        .iter()
                        .zip(&wave)
                        .all(|(a, b)| a.to_bits() == b.to_bits()),
                    "{case}"
                );
            }
        }
    }

    #[test]
    fn bad_settings_and_too_few_data_are_errors() {
        let g = GridGeometry::covering(0.0, 1000.0, 0.0, 1000.0, 50.0).unwrap();
        let (x, y, z) = (vec![100.0, 500.0], vec![100.0, 500.0], vec![1.0, 2.0]);
        let p = Points::new(&x, &y, &z).unwrap();
        assert!(matches!(
            MinCurvature::default().grid(p, g),
            Err(GridError::Data(_))
        ));
        for s in [
            MinCurvature {
                tension: 1.5,
                ..Default::default()
            },
            MinCurvature {
                relaxation: 2.0,
                ..Default::default()
            },
            MinCurvature {
                convergence: Some(0.0),
                ..Default::default()
            },
        ] {
            assert!(s.grid(p, g).unwrap_err().is_bad_input());
        }
        assert!(Points::new(&x, &y, &z[..1]).is_err());
        let small = GridGeometry::covering(0.0, 100.0, 0.0, 100.0, 50.0).unwrap();
        assert!(MinCurvature::default().grid(p, small).is_err());
    }

    #[test]
    fn non_finite_and_outside_points_are_counted_not_used() {
        let g = GridGeometry::covering(0.0, 2000.0, 0.0, 1500.0, 50.0).unwrap();
        let (mut x, mut y, mut z) = lines(&g, 8, |x, _| x / 100.0);
        x.push(f64::NAN);
        y.push(0.0);
        z.push(1.0);
        x.push(0.0);
        y.push(0.0);
        z.push(f64::INFINITY);
        x.push(-500.0);
        y.push(0.0);
        z.push(1.0);
        let (_, rep) = MinCurvature::default()
            .grid(Points::new(&x, &y, &z).unwrap(), g)
            .unwrap();
        assert_eq!(rep.points_non_finite, 2);
        assert_eq!(rep.points_outside, 1);
        assert_eq!(rep.points_used, x.len() - 3);
    }

    #[test]
    fn a_cancelled_grid_stops_at_the_next_sweep_and_an_uncancelled_one_is_unchanged() {
        let g = GridGeometry::covering(0.0, 2000.0, 0.0, 1500.0, 50.0).unwrap();
        let (x, y, z) = lines(&g, 8, |x, y| (x / 300.0).sin() * (y / 200.0).cos());
        let points = Points::new(&x, &y, &z).unwrap();
        let s = MinCurvature::default();
        let (plain, _) = s.grid(points, g).unwrap();
        let mut asked = 0usize;
        let (probed, _) = s
            .grid_cancellable(points, g, &mut || {
                asked += 1;
                false
            })
            .unwrap();
        assert!(asked > 10, "{asked}");
        assert_eq!(plain, probed);
        let mut after = 0usize;
        let e = s
            .grid_cancellable(points, g, &mut || {
                after += 1;
                after > 5
            })
            .unwrap_err();
        assert!(matches!(e, GridError::Cancelled(_)), "{e}");
        assert!(!e.is_bad_input());
        assert_eq!(e.to_string(), "cancelled");
        assert_eq!(after, 6, "asked again after it said to stop");
    }
}
