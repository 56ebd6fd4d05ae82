//! The grid: regularly spaced nodes in a projected coordinate system.
//!
//! Node `(i, j)` sits at `x = x0 + i·cell` (east, m) and `y = y0 + j·cell`
//! (north, m): node ("gridline") registration, as GMT's default and
//! Geosoft's grids. Values are stored row by row from the southern row
//! (`j = 0`), west to east; a blank node (no data near it) is NaN.

use crate::error::{GridError, Result, positive};
use crate::projection::Crs;
use aeromag_core::error::shown;
use aeromag_core::memory::size_text;

/// Where the nodes of a grid are (module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GridGeometry {
    /// Easting of the western column of nodes, m.
    pub x0: f64,
    /// Northing of the southern row of nodes, m.
    pub y0: f64,
    /// Node spacing, m (the same east and north).
    pub cell: f64,
    /// Nodes along x (columns).
    pub nx: usize,
    /// Nodes along y (rows).
    pub ny: usize,
}

/// Most nodes of one grid (2.5·10⁸: 2 GB of f64), so that a wrong cell
/// size is an error and not an out-of-memory abort.
pub const MAX_NODES: usize = 250_000_000;

/// Peak memory per node while a grid is made and written, bytes: the
/// slope of `aeromag grid`'s peak resident size over grids of 2.7·10⁵ to
/// 4.3·10⁶ nodes of one survey (41, 70 and 177 MB at cells of 20, 10 and
/// 5 m: 33.4 bytes a node), rounded up.
pub const GRIDDING_BYTES_PER_NODE: f64 = 34.0;

/// A grid of `fx × fy` nodes at `cell` m is refused when it needs more
/// memory than the process can take (`available`, bytes;
/// [`aeromag_core::memory`]): an allocation failure aborts the process.
/// Before, Python's `grid_flight` with a 1 m cell over 15 km (2.4·10⁸
/// nodes, under [`MAX_NODES`]) under a 6 GB address-space limit died
/// with "memory allocation of 7590105632 bytes failed".
fn check_memory(fx: f64, fy: f64, cell: f64, available: Option<u64>) -> Result<()> {
    let need = fx * fy * GRIDDING_BYTES_PER_NODE;
    let Some(available) = available.map(|a| a as f64) else {
        return Ok(());
    };
    if need <= available {
        return Ok(());
    }
    // The cell that fits, with room to spare (the nodes go as 1/cell²).
    let fits = cell * (need / (0.8 * available)).sqrt();
    Err(GridError::Data(format!(
        "{} × {} nodes at a {} m cell need about {} while gridding ({GRIDDING_BYTES_PER_NODE} \
         bytes a node), more than the {} this process can take: choose a larger cell (about \
         {} m) or a smaller area",
        shown(fx),
        shown(fy),
        shown(cell),
        size_text(need as u64),
        size_text(available as u64),
        shown((fits * 100.0).ceil() / 100.0)
    )))
}

/// Smallest cell size of a grid read from a file, m (1 µm). Survey grids
/// have cells of decimetres (drone, ground) to kilometres (compilations);
/// a smaller "cell" is a corrupt header, and would put wavenumbers of
/// order 1/cell beyond what the derivative products can multiply by.
pub const MIN_CELL: f64 = 1e-6;

/// Largest cell size of a grid read from a file, m (1000 km: forty cells
/// go round the Earth).
pub const MAX_CELL: f64 = 1e6;

/// Largest magnitude of a node coordinate of a grid read from a file, m
/// (10⁹ m, 25 times the Earth's circumference: far beyond the easting or
/// northing of any projection of the Earth).
pub const MAX_COORDINATE: f64 = 1e9;

/// Largest magnitude of a node value of a grid read from a file: that of
/// float32 (3.4·10³⁸). Every grid file this crate writes stores float32,
/// so a larger value could not be written back, and no field (nT, the
/// Earth's at most 7·10⁴ nT), gradient or other survey quantity comes
/// near it: it is a corrupt file. The bound keeps every product finite in
/// f64: a spectral product sums at most 4·[`MAX_NODES`] values times at
/// most π√2/[`MIN_CELL`], about 10⁵⁴ in all, far from f64's 10³⁰⁸ (a
/// result beyond float32 is then refused when written).
pub const MAX_VALUE: f64 = f32::MAX as f64;

impl GridGeometry {
    /// The smallest grid of spacing `cell` whose nodes cover
    /// `[x_min, x_max] × [y_min, y_max]`, with its western and southern
    /// nodes on multiples of `cell` (so grids of one survey line up). The
    /// cell must lie within [`MIN_CELL`]–[`MAX_CELL`], as in the grid files
    /// read back (a grid of 2.5·10⁻⁷ m cells, from lines half a millimetre
    /// apart, was written and then refused by `derive`).
    pub fn covering(x_min: f64, x_max: f64, y_min: f64, y_max: f64, cell: f64) -> Result<Self> {
        let cell = positive("cell size", cell)?;
        if !(MIN_CELL..=MAX_CELL).contains(&cell) {
            return Err(GridError::OutOfRange {
                name: "cell size",
                value: cell,
                expected: "1e-6 to 1e6 m",
            });
        }
        if !(x_min.is_finite() && x_max.is_finite() && y_min.is_finite() && y_max.is_finite())
            || x_max < x_min
            || y_max < y_min
        {
            return Err(GridError::Data(format!(
                "the extent [{}, {}] × [{}, {}] m is not a finite area",
                shown(x_min),
                shown(x_max),
                shown(y_min),
                shown(y_max)
            )));
        }
        let x0 = (x_min / cell).floor() * cell;
        let y0 = (y_min / cell).floor() * cell;
        // Counted in f64 first: an extent of 10³⁰⁰ m would overflow the
        // integers (and did: "a 0 × 2 grid").
        let nodes = |lo: f64, hi: f64| ((hi - lo) / cell).ceil() + 1.0;
        let (fx, fy) = (nodes(x0, x_max), nodes(y0, y_max));
        let n = fx * fy;
        if n.is_nan() || n > MAX_NODES as f64 {
            return Err(GridError::Data(format!(
                "{} × {} nodes at a {} m cell is more than {MAX_NODES}: choose a larger cell",
                shown(fx),
                shown(fy),
                shown(cell)
            )));
        }
        check_memory(fx, fy, cell, aeromag_core::memory::available_bytes())?;
        Ok(Self {
            x0,
            y0,
            cell,
            nx: fx as usize,
            ny: fy as usize,
        })
    }

    /// Why this is not the geometry of a grid, if it is not: a cell
    /// outside [`MIN_CELL`]–[`MAX_CELL`] (or not finite), no node or more
    /// than [`MAX_NODES`], a node beyond ±[`MAX_COORDINATE`]. Grid files
    /// read, pickled grids and [`Grid::from_axes`] are checked with it.
    pub fn problem(&self) -> Option<String> {
        let g = self;
        if !(MIN_CELL..=MAX_CELL).contains(&g.cell) {
            return Some(format!(
                "cell size {} m is out of range: {}–{} m",
                shown(g.cell),
                shown(MIN_CELL),
                shown(MAX_CELL)
            ));
        }
        if g.nx == 0 || g.ny == 0 || g.nx.saturating_mul(g.ny) > MAX_NODES {
            return Some(format!("{} × {} nodes (at most {MAX_NODES})", g.nx, g.ny));
        }
        let inside = |v: f64| v.abs() <= MAX_COORDINATE;
        if !(inside(g.x0) && inside(g.y0) && inside(g.x_max()) && inside(g.y_max())) {
            return Some(format!(
                "nodes from ({}, {}) to ({}, {}) m: coordinates must be within ±{} m",
                shown(g.x0),
                shown(g.y0),
                shown(g.x_max()),
                shown(g.y_max()),
                shown(MAX_COORDINATE)
            ));
        }
        None
    }

    /// Number of nodes.
    pub fn len(&self) -> usize {
        self.nx * self.ny
    }

    /// True for a grid without nodes.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Easting of column `i`, m.
    pub fn x(&self, i: usize) -> f64 {
        self.x0 + i as f64 * self.cell
    }

    /// Northing of row `j`, m.
    pub fn y(&self, j: usize) -> f64 {
        self.y0 + j as f64 * self.cell
    }

    /// Easting of the eastern column, m.
    pub fn x_max(&self) -> f64 {
        self.x(self.nx.saturating_sub(1))
    }

    /// Northing of the northern row, m.
    pub fn y_max(&self) -> f64 {
        self.y(self.ny.saturating_sub(1))
    }

    /// Index into the values of node `(i, j)`.
    pub fn index(&self, i: usize, j: usize) -> usize {
        j * self.nx + i
    }

    /// The node of value index `k` as messages and grid files' readers
    /// count it: (row from the northern row, column from the western
    /// column), both 1-based.
    pub fn row_column(&self, k: usize) -> (usize, usize) {
        (self.ny - k / self.nx, k % self.nx + 1)
    }

    /// Fractional node coordinates `(u, v)` of a point: `u = (x − x0)/cell`.
    pub fn to_node(&self, x: f64, y: f64) -> (f64, f64) {
        ((x - self.x0) / self.cell, (y - self.y0) / self.cell)
    }
}

/// The spacing of an axis of node coordinates (negative when it runs
/// backwards; `None` for fewer than two nodes), each coordinate within
/// 10⁻⁶ of a spacing of where the spacing puts it: [`Grid::from_axes`]
/// and the netCDF reader.
pub(crate) fn axis_spacing(axis: &[f64], name: &str) -> Result<Option<f64>> {
    if axis.len() < 2 {
        return Ok(None);
    }
    let (first, last) = (axis[0], axis[axis.len() - 1]);
    let step = (last - first) / (axis.len() - 1) as f64;
    if !(step.is_finite() && step != 0.0) {
        return Err(GridError::Unusable(format!(
            "the {name} coordinates run from {} to {}: not a grid axis",
            shown(first),
            shown(last)
        )));
    }
    for (k, &v) in axis.iter().enumerate() {
        let expected = first + k as f64 * step;
        // NaN fails the comparison too.
        let off = (v - expected).abs();
        if off.is_nan() || off > 1e-6 * step.abs() {
            return Err(GridError::Unusable(format!(
                "the {name} coordinates are not evenly spaced: {name}[{k}] is {}, {} from a \
                 spacing of {}",
                shown(v),
                shown(expected),
                shown(step)
            )));
        }
    }
    Ok(Some(step))
}

/// `71 × 40 nodes of 50 m from (1000, -50)` (the south-western node's
/// easting and northing, m).
impl std::fmt::Display for GridGeometry {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} × {} nodes of {} m from ({}, {})",
            self.nx,
            self.ny,
            shown(self.cell),
            shown(self.x0),
            shown(self.y0)
        )
    }
}

/// A gridded quantity (module docs for the node layout).
#[derive(Debug, Clone, PartialEq)]
pub struct Grid {
    /// Node positions.
    pub geometry: GridGeometry,
    /// Node values, row by row from the south; NaN = blank.
    pub values: Vec<f64>,
    /// The coordinate system of `x`, `y` (`None`: projected metres of an
    /// unknown system).
    pub crs: Option<Crs>,
    /// What is gridded (the column name), for the file's metadata.
    pub name: String,
    /// Its unit (e.g. `nT`).
    pub unit: String,
}

impl Grid {
    /// A grid of `geometry` with every node blank.
    pub fn blank(geometry: GridGeometry, name: &str, unit: &str) -> Self {
        Self {
            geometry,
            values: vec![f64::NAN; geometry.len()],
            crs: None,
            name: name.to_string(),
            unit: unit.to_string(),
        }
    }

    /// A grid in the layout array libraries give one (NumPy, xarray):
    /// `x` the nodes' eastings, one per column (m), `y` their northings,
    /// one per row (m), `values` row after row in the order of `y`, each
    /// row in the order of `x` (a C-ordered `(ny, nx)` array; NaN is a
    /// blank node). Either axis may run backwards, as a north-up raster's
    /// `y` does: the values are put in this crate's order (rows from the
    /// south, west to east). No coordinate system (`crs` is `None`).
    ///
    /// Errors, all bad input: `values` not `ny × nx`
    /// ([`GridError::LengthMismatch`]); and ([`GridError::Unusable`])
    /// neither axis with two nodes (no spacing), an axis not evenly spaced
    /// to 10⁻⁶ of its spacing, x and y spacings that differ by more than
    /// 10⁻⁶ relative (cells are square; as the netCDF reader), a geometry
    /// [`GridGeometry::problem`] refuses, a value that is infinite or
    /// beyond float32's range (its row and column named as the grid files'
    /// readers name them).
    ///
    /// ```
    /// use aeromag_grid::Grid;
    /// // Two rows, the northern one first (y descending), three columns.
    /// let g = Grid::from_axes(&[0.0, 10.0, 20.0], &[110.0, 100.0], &[4.0, 5.0, 6.0, 1.0, 2.0, 3.0], "tmi", "nT")?;
    /// assert_eq!((g.geometry.x0, g.geometry.y0, g.geometry.cell), (0.0, 100.0, 10.0));
    /// assert_eq!(g.values, [1.0, 2.0, 3.0, 4.0, 5.0, 6.0]);
    /// # Ok::<(), aeromag_grid::GridError>(())
    /// ```
    pub fn from_axes(x: &[f64], y: &[f64], values: &[f64], name: &str, unit: &str) -> Result<Grid> {
        let (nx, ny) = (x.len(), y.len());
        if values.len() != nx.saturating_mul(ny) {
            return Err(GridError::LengthMismatch {
                what: "grid values (ny × nx)",
                got: values.len(),
                expected: nx.saturating_mul(ny),
            });
        }
        let (sx, sy) = (axis_spacing(x, "x")?, axis_spacing(y, "y")?);
        let cell = match (sx, sy) {
            (Some(a), Some(b)) if (a.abs() - b.abs()).abs() <= 1e-6 * a.abs() => a.abs(),
            (Some(a), Some(b)) => {
                return Err(GridError::Unusable(format!(
                    "nodes {} apart in x and {} in y: aeromag's grids have square cells",
                    shown(a.abs()),
                    shown(b.abs())
                )));
            }
            (Some(a), None) | (None, Some(a)) => a.abs(),
            (None, None) => {
                return Err(GridError::Unusable(format!(
                    "{nx} × {ny} nodes have no spacing: a grid needs two nodes along x or y"
                )));
            }
        };
        let (flip_x, flip_y) = (sx.is_some_and(|s| s < 0.0), sy.is_some_and(|s| s < 0.0));
        let first = |axis: &[f64], flip: bool| {
            (if flip { axis.last() } else { axis.first() })
                .copied()
                .unwrap_or(0.0)
        };
        let geometry = GridGeometry {
            x0: first(x, flip_x),
            y0: first(y, flip_y),
            cell,
            nx,
            ny,
        };
        if let Some(problem) = geometry.problem() {
            return Err(GridError::Unusable(format!("not a grid: {problem}")));
        }
        let mut ordered = Vec::with_capacity(values.len());
        for j in 0..ny {
            let row = &values[if flip_y { ny - 1 - j } else { j } * nx..][..nx];
            if flip_x {
                ordered.extend(row.iter().rev());
            } else {
                ordered.extend(row);
            }
        }
        let mut grid = Grid::blank(geometry, name, unit);
        grid.values = ordered;
        if let Some((row, column, value)) = crate::format::beyond_float32(&grid) {
            return Err(GridError::Unusable(format!(
                "the value at row {row}, column {column} (from the north-west corner, 1-based) \
                 is {}: grid values must be finite and within float32's range",
                shown(value)
            )));
        }
        Ok(grid)
    }

    /// The value of node `(i, j)` (NaN when blank).
    pub fn get(&self, i: usize, j: usize) -> f64 {
        self.values[self.geometry.index(i, j)]
    }

    /// Bilinear interpolation at `(x, y)` (m); NaN outside the grid or
    /// next to a blank node.
    pub fn sample(&self, x: f64, y: f64) -> f64 {
        let g = &self.geometry;
        let (u, v) = g.to_node(x, y);
        if !(u >= 0.0 && v >= 0.0) || g.nx < 2 || g.ny < 2 {
            return f64::NAN;
        }
        let (i, j) = (
            (u.floor() as usize).min(g.nx - 2),
            (v.floor() as usize).min(g.ny - 2),
        );
        let (fu, fv) = (u - i as f64, v - j as f64);
        if fu > 1.0 || fv > 1.0 {
            return f64::NAN;
        }
        let z00 = self.get(i, j);
        let z10 = self.get(i + 1, j);
        let z01 = self.get(i, j + 1);
        let z11 = self.get(i + 1, j + 1);
        (1.0 - fv) * ((1.0 - fu) * z00 + fu * z10) + fv * ((1.0 - fu) * z01 + fu * z11)
    }

    /// Mean, standard deviation, minimum and maximum of the non-blank
    /// nodes, and their count (NaN figures for an all-blank grid).
    pub fn stats(&self) -> GridStats {
        let mut n = 0usize;
        let (mut sum, mut min, mut max) = (0.0, f64::INFINITY, f64::NEG_INFINITY);
        for &v in self.values.iter().filter(|v| v.is_finite()) {
            n += 1;
            sum += v;
            min = min.min(v);
            max = max.max(v);
        }
        if n == 0 {
            return GridStats {
                count: 0,
                mean: f64::NAN,
                std: f64::NAN,
                min: f64::NAN,
                max: f64::NAN,
            };
        }
        let mean = sum / n as f64;
        let var = self
            .values
            .iter()
            .filter(|v| v.is_finite())
            .map(|v| (v - mean).powi(2))
            .sum::<f64>()
            / n as f64;
        GridStats {
            count: n,
            mean,
            std: var.sqrt(),
            min,
            max,
        }
    }

    /// `self − other` node by node (blank where either is blank); the two
    /// grids must have the same geometry and, when both record one, the
    /// same coordinate system: equal node coordinates in two UTM zones are
    /// places some 400 km apart (two grids of one survey pattern in zones
    /// 37N and 38N were differenced node by node). A grid without a CRS
    /// (an ESRI ASCII grid without its `.prj`, a `.prj` this crate cannot
    /// read) is taken to be in the other's, the usual case of a sidecar
    /// left behind: its coordinates still have to match node for node, and
    /// the difference carries the CRS that is known.
    pub fn difference(&self, other: &Grid) -> Result<Grid> {
        if let (Some(a), Some(b)) = (self.crs, other.crs)
            && a != b
        {
            return Err(GridError::Unusable(format!(
                "the grids' coordinate systems differ: {} (EPSG:{}) against {} (EPSG:{}); \
                 their nodes are not the same places",
                a.name(),
                a.epsg(),
                b.name(),
                b.epsg()
            )));
        }
        if self.geometry != other.geometry {
            return Err(GridError::Unusable(format!(
                "the grids' nodes differ: {} against {}",
                self.geometry, other.geometry
            )));
        }
        let values: Vec<f64> = self
            .values
            .iter()
            .zip(&other.values)
            .map(|(a, b)| a - b)
            .collect();
        // Grids read from files hold values within MAX_VALUE, whose
        // differences are finite; one built in memory may not.
        if let Some(k) = (0..values.len()).find(|&k| {
            !values[k].is_finite() && !self.values[k].is_nan() && !other.values[k].is_nan()
        }) {
            let (row, column) = self.geometry.row_column(k);
            return Err(GridError::Unusable(format!(
                "the difference at row {row}, column {column} (from the north-west corner, \
                 1-based) is not finite: {} − {}",
                shown(self.values[k]),
                shown(other.values[k])
            )));
        }
        Ok(Grid {
            values,
            crs: self.crs.or(other.crs),
            name: format!("{} - {}", self.name, other.name),
            ..self.clone()
        })
    }
}

/// Summary figures of a grid's non-blank nodes ([`Grid::stats`]).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct GridStats {
    /// Non-blank nodes.
    pub count: usize,
    /// Mean.
    pub mean: f64,
    /// Standard deviation (population).
    pub std: f64,
    /// Smallest value.
    pub min: f64,
    /// Largest value.
    pub max: f64,
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        /// Any axis direction gives the same grid: the values reversed
        /// along a reversed axis.
        #[test]
        fn from_axes_takes_either_direction(
            nx in 1usize..6,
            ny in 2usize..6,
            x0 in -1e6f64..1e6,
            y0 in -1e6f64..1e6,
            cell in 0.5f64..100.0,
            flip_x in any::<bool>(),
            flip_y in any::<bool>(),
        ) {
            let axis = |o: f64, n: usize, flip: bool| -> Vec<f64> {
                let a: Vec<f64> = (0..n).map(|k| o + k as f64 * cell).collect();
                if flip { a.into_iter().rev().collect() } else { a }
            };
            let plain: Vec<f64> = (0..nx * ny).map(|k| k as f64).collect();
            let (x, y) = (axis(x0, nx, flip_x), axis(y0, ny, flip_y));
            let mut given = Vec::new();
            for j in 0..ny {
                let j = if flip_y { ny - 1 - j } else { j };
                for i in 0..nx {
                    let i = if flip_x { nx - 1 - i } else { i };
                    given.push(plain[j * nx + i]);
                }
            }
            let g = Grid::from_axes(&x, &y, &given, "v", "nT").unwrap();
            // The cell is the x spacing (the y spacing with one column).
            let cell = if nx > 1 {
                (x[nx - 1] - x[0]).abs() / (nx - 1) as f64
            } else {
                (y[ny - 1] - y[0]).abs() / (ny - 1) as f64
            };
            prop_assert_eq!(g.geometry, GridGeometry { x0, y0, cell, nx, ny });
            prop_assert_eq!(g.values, plain);
        }
    }

    /// What is not a grid's layout is refused, saying why.
    #[test]
    fn from_axes_refuses_what_is_not_a_grid() {
        let v6 = [0.0; 6];
        for (x, y, values, needle) in [
            (
                &[0.0, 1.0, 2.0][..],
                &[0.0, 1.0][..],
                &v6[..5],
                "has 5 values, expected 6",
            ),
            (
                &[0.0, 1.0, 2.5],
                &[0.0, 1.25],
                &v6[..],
                "not evenly spaced: x[1] is 1, 1.25 from",
            ),
            (
                &[0.0, 1.0, 2.0],
                &[0.0, 2.0],
                &v6[..],
                "1 apart in x and 2 in y",
            ),
            (
                &[0.0, 0.0, 0.0],
                &[0.0, 1.0],
                &v6[..],
                "x coordinates run from 0 to 0",
            ),
            (&[0.0], &[0.0], &v6[..1], "no spacing"),
            (
                &[0.0, 1e-9, 2e-9],
                &[0.0, 1e-9],
                &v6[..],
                "cell size 0.000000001 m is out of range",
            ),
            (&[0.0, f64::NAN, 2.0], &[0.0, 1.0], &v6[..], "x[1] is NaN"),
        ] {
            let e = Grid::from_axes(x, y, values, "v", "nT").unwrap_err();
            assert!(e.is_bad_input(), "{needle}: {e}");
            assert!(e.to_string().contains(needle), "{needle}: {e}");
        }
        let mut values = v6;
        values[1] = f64::INFINITY;
        let e = Grid::from_axes(&[0.0, 1.0, 2.0], &[5.0, 6.0], &values, "v", "nT").unwrap_err();
        assert!(e.to_string().contains("row 2, column 2"), "{e}");
        // One row: its spacing is the cell.
        let g = Grid::from_axes(&[3.0, 5.0], &[7.0], &[1.0, 2.0], "v", "nT").unwrap();
        assert_eq!(
            (g.geometry.cell, g.geometry.ny, g.geometry.y0),
            (2.0, 1, 7.0)
        );
    }

    /// A grid needing more memory than the process can take is refused
    /// with the cell that fits; one that fits, or an unknown amount of
    /// memory, passes.
    #[test]
    fn a_grid_beyond_the_memory_available_is_refused_with_a_cell_that_fits() {
        // The campaign's grid: 15 401² nodes at 1 m, 6 GB.
        let e = check_memory(15_401.0, 15_401.0, 1.0, Some(6_000_000_000))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("need about 8.1 GB") && e.contains("6.0 GB") && e.contains("about 1.3 m"),
            "{e}"
        );
        let fits: f64 = 1.3;
        let n = (15_400.0 / fits).ceil() + 1.0;
        assert!(check_memory(n, n, fits, Some(6_000_000_000)).is_ok());
        assert!(check_memory(15_401.0, 15_401.0, 1.0, None).is_ok());
    }

    #[test]
    fn covering_aligns_nodes_to_the_cell_and_covers_the_extent() {
        let g = GridGeometry::covering(1013.0, 2990.0, -40.0, 460.0, 50.0).unwrap();
        assert_eq!((g.x0, g.y0), (1000.0, -50.0));
        assert!(g.x_max() >= 2990.0 && g.x_max() - 2990.0 < 50.0);
        assert!(g.y_max() >= 460.0 && g.y_max() - 460.0 < 50.0);
        assert!(GridGeometry::covering(0.0, 1.0, 0.0, 1.0, 0.0).is_err());
        assert!(GridGeometry::covering(0.0, 1e9, 0.0, 1e9, 1.0).is_err());
        assert!(GridGeometry::covering(f64::NAN, 1.0, 0.0, 1.0, 1.0).is_err());
        // Cells beyond what grid files are read with.
        for cell in [1e-7, 2e6] {
            let e = GridGeometry::covering(0.0, 1.0, 0.0, 1.0, cell).unwrap_err();
            assert!(e.to_string().contains("1e-6 to 1e6 m"), "{e}");
        }
        assert!(GridGeometry::covering(0.0, 1e-5, 0.0, 1e-5, MIN_CELL).is_ok());
    }

    #[test]
    fn bilinear_sampling_reproduces_a_plane() {
        let geometry = GridGeometry::covering(0.0, 400.0, 0.0, 300.0, 100.0).unwrap();
        let mut grid = Grid::blank(geometry, "z", "nT");
        for j in 0..geometry.ny {
            for i in 0..geometry.nx {
                let k = geometry.index(i, j);
                grid.values[k] = 2.0 * geometry.x(i) - 0.5 * geometry.y(j) + 7.0;
            }
        }
        for (x, y) in [(0.0, 0.0), (123.0, 45.6), (400.0, 300.0), (399.9, 1.0)] {
            assert!((grid.sample(x, y) - (2.0 * x - 0.5 * y + 7.0)).abs() < 1e-9);
        }
        assert!(grid.sample(-1.0, 0.0).is_nan());
        assert!(grid.sample(0.0, 300.5).is_nan());
        let s = grid.stats();
        assert_eq!(s.count, 20);
        assert!(grid.difference(&grid).unwrap().stats().std == 0.0);
    }

    #[test]
    fn a_difference_that_overflows_is_an_error() {
        let geometry = GridGeometry::covering(0.0, 100.0, 0.0, 100.0, 100.0).unwrap();
        let mut a = Grid::blank(geometry, "a", "nT");
        let mut b = a.clone();
        a.values = vec![1.0, f64::NAN, 1e308, 3.0];
        b.values = vec![1.0, 2.0, -1e308, f64::NAN];
        let m = a.difference(&b).unwrap_err().to_string();
        // Index 2 is node (0, 1): the northern row, the western column.
        assert!(
            m.contains("row 1, column 1 (from the north-west corner, 1-based)")
                && m.contains("1e308 − -1e308"),
            "{m}"
        );
        let mut c = Grid::blank(
            GridGeometry::covering(0.0, 200.0, 0.0, 100.0, 100.0).unwrap(),
            "c",
            "nT",
        );
        c.values.fill(1.0);
        let m = a.difference(&c).unwrap_err().to_string();
        assert_eq!(
            m,
            "the grids' nodes differ: 2 × 2 nodes of 100 m from (0, 0) \
             against 3 × 2 nodes of 100 m from (0, 0)"
        );
        b.values[2] = 1e308;
        let d = a.difference(&b).unwrap();
        assert_eq!(d.values[0], 0.0);
        assert_eq!(d.values[2], 0.0);
        assert!(d.values[1].is_nan() && d.values[3].is_nan());
    }

    /// Grids of equal nodes in UTM zones 37N and 38N were differenced node
    /// by node (finding 12); now refused, naming both zones. A grid without
    /// a CRS is differenced with one that has one, and the result keeps
    /// the known CRS.
    #[test]
    fn grids_in_different_coordinate_systems_are_not_differenced() {
        use crate::projection::UtmZone;
        let geometry = GridGeometry::covering(437_100.0, 437_200.0, 0.0, 100.0, 100.0).unwrap();
        let zone = |number| {
            Some(Crs::Utm(UtmZone {
                number,
                north: true,
            }))
        };
        let mut a = Grid::blank(geometry, "a", "nT");
        a.values.fill(2.0);
        a.crs = zone(37);
        let mut b = a.clone();
        b.crs = zone(38);
        let e = a.difference(&b).unwrap_err();
        assert!(e.is_bad_input());
        assert_eq!(
            e.to_string(),
            "the grids' coordinate systems differ: WGS 84 / UTM zone 37N (EPSG:32637) \
             against WGS 84 / UTM zone 38N (EPSG:32638); their nodes are not the same places"
        );
        b.crs = None;
        assert_eq!(a.difference(&b).unwrap().crs, zone(37));
        assert_eq!(b.difference(&a).unwrap().crs, zone(37));
        b.crs = zone(37);
        assert_eq!(a.difference(&b).unwrap().values, vec![0.0; 4]);
    }
}
