//! From lines to the map (`aeromag grid`, `aeromag microlevel`,
//! `aeromag derive`): grids as NumPy arrays with their coordinates and CRS.

use crate::errors::{IntoPy, bad_argument, whole_opt};
use crate::flight::{FlightArg, PyFlight};
use crate::progress::PyProgress;
use aeromag::Flight;
use aeromag::grid::format::{read_grid as lib_read_grid, write_grid};
use aeromag::grid::gridding::MinCurvature;
use aeromag::grid::products::{Spectral, apply};
use aeromag::grid::projection::{Crs, UtmZone};
use aeromag::grid::{Grid, GridGeometry};
use aeromag::map::gridding::GridMethod;
use aeromag::map::{
    GridOptions, MicrolevelOptions, Microlevelled, ProjectedColumns, grid_flight as lib_grid,
    microlevel as lib_microlevel,
};
use numpy::{PyArray1, PyArray2};
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// The columns `xy = (easting, northing)` of projected positions.
pub(crate) fn projected(xy: Option<(String, String)>) -> Option<ProjectedColumns> {
    xy.map(|(e, n)| ProjectedColumns::new(e, n))
}

pub(crate) fn zone(utm_zone: Option<&str>) -> PyResult<Option<UtmZone>> {
    utm_zone.map(|z| UtmZone::parse(z).py_err()).transpose()
}

/// A grid (`aeromag grid`): node values with their easting/northing (m)
/// and coordinate system.
#[pyclass(name = "Grid", module = "aeromag._aeromag", frozen)]
pub struct PyGrid {
    grid: Grid,
    /// What `info` returns (a list, not a dict: the object is frozen and
    /// `info` hands out a new dict each time).
    info: Vec<(String, Py<PyAny>)>,
}

impl PyGrid {
    fn plain(grid: Grid) -> Self {
        Self {
            grid,
            info: Vec::new(),
        }
    }
}

#[pymethods]
impl PyGrid {
    /// Node values, shape (ny, nx), row 0 the southern row; NaN = blank.
    #[getter]
    fn values<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let g = self.grid.geometry;
        let rows: Vec<Vec<f64>> = self
            .grid
            .values
            .chunks(g.nx.max(1))
            .map(<[f64]>::to_vec)
            .collect();
        PyArray2::from_vec2(py, &rows).map_err(|e| bad_argument(e.to_string()))
    }

    /// Easting of each column of nodes, m.
    #[getter]
    fn x<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        let g = self.grid.geometry;
        PyArray1::from_vec(py, (0..g.nx).map(|i| g.x(i)).collect())
    }

    /// Northing of each row of nodes, m.
    #[getter]
    fn y<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        let g = self.grid.geometry;
        PyArray1::from_vec(py, (0..g.ny).map(|j| g.y(j)).collect())
    }

    /// Node spacing, m.
    #[getter]
    fn cell(&self) -> f64 {
        self.grid.geometry.cell
    }

    /// EPSG code of the coordinate system (None if unknown).
    #[getter]
    fn epsg(&self) -> Option<u16> {
        self.grid.crs.map(|c| c.epsg())
    }

    /// Name of the coordinate system, e.g. `WGS 84 / UTM zone 37N`.
    #[getter]
    fn crs(&self) -> Option<String> {
        self.grid.crs.map(|c| c.name())
    }

    /// What is gridded.
    #[getter]
    fn name(&self) -> String {
        self.grid.name.clone()
    }

    /// Its unit.
    #[getter]
    fn unit(&self) -> String {
        self.grid.unit.clone()
    }

    /// How the grid was made (`grid_flight`): column, line spacing and
    /// direction, blanking, convergence; empty for other grids.
    #[getter]
    fn info<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        for (k, v) in &self.info {
            d.set_item(k, v.clone_ref(py))?;
        }
        Ok(d)
    }

    /// Count, mean, std, min and max of the non-blank nodes.
    fn stats<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let s = self.grid.stats();
        let d = PyDict::new(py);
        d.set_item("count", s.count)?;
        d.set_item("mean", s.mean)?;
        d.set_item("std", s.std)?;
        d.set_item("min", s.min)?;
        d.set_item("max", s.max)?;
        Ok(d)
    }

    /// Bilinear interpolation at an easting and northing (m); NaN outside
    /// the grid or next to a blank node.
    fn sample(&self, x: f64, y: f64) -> f64 {
        self.grid.sample(x, y)
    }

    /// First vertical derivative (z down), unit per metre (FFT).
    fn vertical_derivative(&self, py: Python<'_>) -> PyResult<PyGrid> {
        let g = py
            .detach(|| apply(&self.grid, Spectral::VerticalDerivative))
            .py_err()?;
        Ok(PyGrid::plain(g))
    }

    /// Upward continuation by `height_m` (FFT).
    fn upward(&self, py: Python<'_>, height_m: f64) -> PyResult<PyGrid> {
        let g = py
            .detach(|| apply(&self.grid, Spectral::UpwardContinuation(height_m)))
            .py_err()?;
        Ok(PyGrid::plain(g))
    }

    /// This grid minus `other` (the same nodes).
    fn minus(&self, other: &PyGrid) -> PyResult<PyGrid> {
        Ok(PyGrid::plain(self.grid.difference(&other.grid).py_err()?))
    }

    /// Write the grid; the format follows the extension (`.tif`, `.asc`,
    /// `.nc`/`.grd`, `.gxf`).
    fn write(&self, path: std::path::PathBuf) -> PyResult<()> {
        write_grid(&path, &self.grid).py_err()?;
        Ok(())
    }

    /// Draw the grid as a map, PNG (`.png`) or SVG (`.svg`), as `aeromag
    /// grid --map` draws it: colour with shaded relief, or `diverging`
    /// colours centred on zero for a derivative or a difference; easting
    /// and northing in km.
    #[pyo3(signature = (path, diverging=false))]
    fn write_map(&self, py: Python<'_>, path: std::path::PathBuf, diverging: bool) -> PyResult<()> {
        use aeromag::map::picture::MapPicture;
        let picture = if diverging {
            MapPicture::diverging(&self.grid)
        } else {
            MapPicture::field(&self.grid)
        };
        py.detach(|| picture.write(&self.grid, &path)).py_err()?;
        Ok(())
    }

    /// Pickling (and `copy.deepcopy`): the node values' bytes, the
    /// geometry, EPSG code, name, unit and `info` ([`grid_from_state`]).
    fn __reduce__<'py>(&self, py: Python<'py>) -> PyResult<crate::pickle::Reduced<'py>> {
        let g = self.grid.geometry;
        let args = (
            crate::pickle::f64_bytes(py, &self.grid.values)?,
            (g.x0, g.y0, g.cell, g.nx, g.ny),
            self.epsg(),
            &self.grid.name,
            &self.grid.unit,
            self.info(py)?,
        )
            .into_pyobject(py)?;
        Ok((crate::pickle::constructor(py, "_grid_from_state")?, args))
    }

    fn __repr__(&self) -> String {
        let g = self.grid.geometry;
        format!(
            "Grid({} × {} nodes, cell {} m, {}, {})",
            g.nx,
            g.ny,
            g.cell,
            self.grid.crs.map_or("no CRS".into(), |c| c.name()),
            self.grid.name
        )
    }
}

/// Grid a column of a survey (the keywords are `aeromag grid`'s flags).
#[pyfunction]
#[pyo3(signature = (flight, column=None, cell=None, tension=0.25, method="min-curvature", blanking=None,
    utm_zone=None, lever_arm=None, extent=None, max_sweeps=None, convergence=None, xy=None, progress=None),
    text_signature = "(flight, column=None, cell=None, tension=0.25, method='min-curvature', blanking=None, utm_zone=None, lever_arm=None, extent=None, max_sweeps=500, convergence=None, xy=None, progress=None)")]
#[allow(clippy::too_many_arguments)]
pub fn grid_flight(
    py: Python<'_>,
    flight: FlightArg<'_>,
    column: Option<String>,
    cell: Option<f64>,
    tension: f64,
    method: &str,
    blanking: Option<f64>,
    utm_zone: Option<&str>,
    lever_arm: Option<[f64; 3]>,
    extent: Option<[f64; 4]>,
    max_sweeps: Option<Bound<'_, PyAny>>,
    convergence: Option<f64>,
    xy: Option<(String, String)>,
    progress: Option<Py<PyAny>>,
) -> PyResult<PyGrid> {
    let method = match method {
        "min-curvature" => GridMethod::MinCurvature,
        "bidirectional" => GridMethod::Bidirectional,
        m => {
            return Err(bad_argument(format!(
                "method '{m}': use 'min-curvature' or 'bidirectional'"
            )));
        }
    };
    let geometry = match (extent, cell) {
        (Some(e), Some(c)) => Some(GridGeometry::covering(e[0], e[1], e[2], e[3], c).py_err()?),
        (Some(_), None) => return Err(bad_argument("extent needs cell")),
        (None, _) => None,
    };
    let opts = GridOptions {
        column,
        cell_m: cell,
        blanking_m: blanking,
        zone: zone(utm_zone)?,
        projected: projected(xy),
        lever_arm_m: lever_arm,
        geometry,
        method,
        min_curvature: MinCurvature {
            tension,
            max_iterations: whole_opt("max_sweeps", max_sweeps.as_ref())?
                .unwrap_or(MinCurvature::default().max_iterations),
            convergence,
            ..MinCurvature::default()
        },
    };
    let mut obs = PyProgress::new(progress);
    let result = py.detach(|| lib_grid(&flight.inner, &opts, &mut obs));
    obs.finish()?;
    let g = result.py_err()?;
    let mut info: Vec<(&str, Py<PyAny>)> = vec![
        (
            "column",
            g.column.clone().into_pyobject(py)?.into_any().unbind(),
        ),
        (
            "blanking_m",
            g.blanking_m.into_pyobject(py)?.into_any().unbind(),
        ),
        (
            "blanked_nodes",
            g.blanked_nodes.into_pyobject(py)?.into_any().unbind(),
        ),
        (
            "rows_used",
            g.rows_used.into_pyobject(py)?.into_any().unbind(),
        ),
        (
            "converged",
            pyo3::types::PyBool::new(py, g.report.converged)
                .to_owned()
                .into_any()
                .unbind(),
        ),
        (
            "notes",
            g.notes
                .iter()
                .map(|n| n.to_string())
                .collect::<Vec<_>>()
                .into_pyobject(py)?
                .into_any()
                .unbind(),
        ),
    ];
    if let Some(l) = &g.survey.lines {
        info.push((
            "line_spacing_m",
            l.spacing_m.into_pyobject(py)?.into_any().unbind(),
        ));
        info.push((
            "line_direction_deg",
            l.direction_deg.into_pyobject(py)?.into_any().unbind(),
        ));
    }
    Ok(PyGrid {
        grid: g.grid,
        info: info.into_iter().map(|(k, v)| (k.to_string(), v)).collect(),
    })
}

/// Read a grid file (GeoTIFF, ESRI ASCII, netCDF, GXF, a Surfer or a Geosoft .grd).
#[pyfunction]
pub fn read_grid(path: std::path::PathBuf) -> PyResult<PyGrid> {
    Ok(PyGrid::plain(lib_read_grid(&path).py_err()?))
}

/// Rebuild a pickled grid (the constructor of `Grid.__reduce__`): the
/// node values' bytes (row by row from the south), the geometry `(x0, y0,
/// cell, nx, ny)`, the EPSG code (None: no CRS), name, unit and `info`.
/// Bad input when the values do not fill the geometry, the geometry is not
/// a grid's (a cell or coordinates out of range) or the EPSG code is not
/// a UTM zone's.
#[pyfunction]
#[pyo3(name = "_grid_from_state")]
pub fn grid_from_state(
    values: &[u8],
    geometry: (f64, f64, f64, Bound<'_, PyAny>, Bound<'_, PyAny>),
    epsg: Option<Bound<'_, PyAny>>,
    name: String,
    unit: String,
    info: &Bound<'_, PyDict>,
) -> PyResult<PyGrid> {
    use aeromag::grid::grid::{MAX_CELL, MAX_COORDINATE, MAX_NODES, MIN_CELL};
    let what = "pickled grid";
    let values = crate::pickle::f64s_from_bytes(&format!("{what}: its values"), values)?;
    let (x0, y0, cell, nx, ny) = geometry;
    let geometry = GridGeometry {
        x0,
        y0,
        cell,
        nx: crate::errors::whole("nx", &nx)?,
        ny: crate::errors::whole("ny", &ny)?,
    };
    let g = geometry;
    let nodes = g.nx.checked_mul(g.ny).filter(|&n| n > 0 && n <= MAX_NODES);
    if nodes != Some(values.len()) {
        return Err(bad_argument(format!(
            "{what}: {} values for {} × {} nodes",
            values.len(),
            g.nx,
            g.ny
        )));
    }
    let inside = |v: f64| v.abs() <= MAX_COORDINATE;
    let a_grid = (MIN_CELL..=MAX_CELL).contains(&g.cell)
        && [g.x0, g.y0, g.x_max(), g.y_max()].into_iter().all(inside);
    if !a_grid {
        return Err(bad_argument(format!(
            "{what}: cell {} m from ({}, {}) m is not a grid's geometry",
            g.cell, g.x0, g.y0
        )));
    }
    let crs = whole_opt::<u16>("epsg", epsg.as_ref())?
        .map(|code| UtmZone::parse(&code.to_string()).map(Crs::Utm))
        .transpose()
        .py_err()?;
    let info = info
        .iter()
        .map(|(k, v)| Ok((k.extract::<String>()?, v.unbind())))
        .collect::<PyResult<_>>()?;
    Ok(PyGrid {
        grid: Grid {
            geometry,
            values,
            crs,
            name,
            unit,
        },
        info,
    })
}

/// A micro-levelled survey (`aeromag microlevel`).
#[pyclass(name = "Microlevelled", module = "aeromag._aeromag", frozen)]
pub struct PyMicrolevelled {
    m: Microlevelled,
    flight: Flight,
}

#[pymethods]
impl PyMicrolevelled {
    /// The column micro-levelled.
    #[getter]
    fn column(&self) -> String {
        self.m.column.clone()
    }

    /// `<column>_mlev`.
    #[getter]
    fn output_column(&self) -> String {
        self.m.output_column()
    }

    /// The micro-levelled values, nT.
    #[getter]
    fn values<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, &self.m.values)
    }

    /// The correction per row, nT (0 off the lines).
    #[getter]
    fn correction<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, &self.m.correction)
    }

    /// RMS and largest |correction| on the lines, nT.
    #[getter]
    fn correction_nt(&self) -> (f64, f64) {
        (self.m.correction_rms_nt, self.m.correction_max_nt)
    }

    /// RMS of the crossover differences before and after, nT (None
    /// without crossovers).
    #[getter]
    fn crossover_rms_nt(&self) -> Option<(f64, f64)> {
        self.m.crossover_rms_nt
    }

    /// Sweeps of minimum curvature on the working grid's final level and
    /// whether it converged (a warning in `notes` when it did not).
    #[getter]
    fn gridding(&self) -> (usize, bool) {
        (self.m.gridding.final_sweeps(), self.m.gridding.converged)
    }

    /// Notes and warnings.
    #[getter]
    fn notes(&self) -> Vec<String> {
        self.m.notes.iter().map(|n| n.to_string()).collect()
    }

    /// The flight with `<column>_mlev` and `<column>_mlev_corr` added.
    fn to_flight(&self) -> PyResult<PyFlight> {
        let mut t = self.flight.table().clone();
        self.m.add_to(&mut t).py_err()?;
        Ok(PyFlight::new(Flight::from_table(t).py_err()?))
    }

    /// Pickling (and `copy.deepcopy`): the result, the traverse lines' ids
    /// (which the reports' JSON leaves out) and the flight
    /// ([`microlevelled_from_state`]).
    fn __reduce__<'py>(&self, py: Python<'py>) -> PyResult<crate::pickle::Reduced<'py>> {
        let state = (&self.m, &self.m.lines.traverse_ids);
        let state = crate::pickle::to_cbor(py, "micro-levelled survey", &state)?;
        let flight = Py::new(py, PyFlight::new(self.flight.clone()))?;
        let args = (state, flight).into_pyobject(py)?;
        Ok((
            crate::pickle::constructor(py, "_microlevelled_from_state")?,
            args,
        ))
    }

    fn __repr__(&self) -> String {
        let m = &self.m;
        let crossovers = m.crossover_rms_nt.map_or("no crossovers".into(), |(a, b)| {
            format!("crossovers {a:.4} → {b:.4} nT RMS")
        });
        format!(
            "<aeromag.Microlevelled {} → {}: correction {:.4} nT RMS (largest {:.4} nT), {crossovers}>",
            m.column,
            m.output_column(),
            m.correction_rms_nt,
            m.correction_max_nt
        )
    }
}

/// Micro-level a levelled survey (the keywords are `aeromag microlevel`'s
/// flags).
#[pyfunction]
#[pyo3(signature = (flight, column=None, cell=None, cutoff=4.0, along_line=None, cosine_power=2.0,
    tension=0.25, utm_zone=None, lever_arm=None, max_sweeps=None, convergence=None, xy=None, progress=None),
    text_signature = "(flight, column=None, cell=None, cutoff=4.0, along_line=None, cosine_power=2.0, tension=0.25, utm_zone=None, lever_arm=None, max_sweeps=500, convergence=None, xy=None, progress=None)")]
#[allow(clippy::too_many_arguments)]
pub fn microlevel(
    py: Python<'_>,
    flight: FlightArg<'_>,
    column: Option<String>,
    cell: Option<f64>,
    cutoff: f64,
    along_line: Option<f64>,
    cosine_power: f64,
    tension: f64,
    utm_zone: Option<&str>,
    lever_arm: Option<[f64; 3]>,
    max_sweeps: Option<Bound<'_, PyAny>>,
    convergence: Option<f64>,
    xy: Option<(String, String)>,
    progress: Option<Py<PyAny>>,
) -> PyResult<PyMicrolevelled> {
    let opts = MicrolevelOptions {
        column,
        cell_m: cell,
        zone: zone(utm_zone)?,
        projected: projected(xy),
        lever_arm_m: lever_arm,
        cutoff_line_spacings: cutoff,
        along_line_m: along_line,
        cosine_power,
        min_curvature: MinCurvature {
            tension,
            max_iterations: whole_opt("max_sweeps", max_sweeps.as_ref())?
                .unwrap_or(MinCurvature::default().max_iterations),
            convergence,
            ..MinCurvature::default()
        },
    };
    let mut obs = PyProgress::new(progress);
    let result = py.detach(|| lib_microlevel(&flight.inner, &opts, &mut obs));
    obs.finish()?;
    Ok(PyMicrolevelled {
        m: result.py_err()?,
        flight: flight.inner.clone(),
    })
}

/// Rebuild a pickled micro-levelled survey (the constructor of
/// `Microlevelled.__reduce__`): the result's state and its flight. Bad
/// input when the state is not a micro-levelled survey's or its series do
/// not have one value per row of the flight.
#[pyfunction]
#[pyo3(name = "_microlevelled_from_state")]
pub fn microlevelled_from_state(
    state: &[u8],
    flight: PyRef<'_, PyFlight>,
) -> PyResult<PyMicrolevelled> {
    let what = "micro-levelled survey";
    let (mut m, traverse_ids): (Microlevelled, Vec<i64>) = crate::pickle::from_cbor(what, state)?;
    m.lines.traverse_ids = traverse_ids;
    let flight = flight.inner.clone();
    crate::pickle::check_rows(what, "values", m.values.len(), &flight)?;
    crate::pickle::check_rows(what, "correction", m.correction.len(), &flight)?;
    Ok(PyMicrolevelled { m, flight })
}
