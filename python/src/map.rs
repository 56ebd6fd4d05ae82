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
use numpy::{PyArray1, PyArray2, PyReadonlyArray1};
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// The columns `xy = (easting, northing)` of projected positions.
pub(crate) fn projected(xy: Option<(String, String)>) -> Option<ProjectedColumns> {
    xy.map(|(e, n)| ProjectedColumns::new(e, n))
}

pub(crate) fn zone(utm_zone: Option<&str>) -> PyResult<Option<UtmZone>> {
    utm_zone.map(|z| UtmZone::parse(z).py_err()).transpose()
}

/// The coordinate system of an EPSG code argument (None: none; else a
/// WGS 84 / UTM code, 326zz or 327zz).
fn crs_of_epsg(epsg: Option<&Bound<'_, PyAny>>) -> PyResult<Option<Crs>> {
    whole_opt::<u16>("epsg", epsg)?
        .map(|code| UtmZone::parse(&code.to_string()).map(Crs::Utm))
        .transpose()
        .py_err()
}

/// `v` as a flat, C-ordered float64 array of `ndim` dimensions (NumPy's
/// `ascontiguousarray`: lists, integer arrays and xarray values too), with
/// its shape; bad input naming `what` otherwise.
fn float_array(
    py: Python<'_>,
    v: &Bound<'_, PyAny>,
    what: &str,
    ndim: usize,
) -> PyResult<(Vec<f64>, Vec<usize>)> {
    let a = py
        .import("numpy")?
        .call_method1("ascontiguousarray", (v, "float64"))
        .map_err(|e| bad_argument(format!("{what}: not an array of numbers ({e})")))?;
    let shape: Vec<usize> = a.getattr("shape")?.extract()?;
    if shape.len() != ndim {
        return Err(bad_argument(format!(
            "{what}: a {ndim}-D array is needed, got shape {shape:?}"
        )));
    }
    let flat: PyReadonlyArray1<'_, f64> = a.call_method0("ravel")?.extract()?;
    Ok((flat.as_slice()?.to_vec(), shape))
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

    /// A grid from a 2-D array of node values and the nodes' coordinates,
    /// as NumPy holds a grid: `values` of shape `(len(y), len(x))`, row `k`
    /// at northing `y[k]`, column `i` at easting `x[i]` (m, evenly spaced,
    /// square cells); either axis may run backwards, as a north-up
    /// raster's `y` does; NaN is a blank node. `epsg`: a WGS 84 / UTM code
    /// (326zz, 327zz) or None. Bad input (`BadInputError`) for a shape that
    /// is not `(len(y), len(x))`, uneven or unequal spacings, a value that
    /// is infinite or beyond float32 (`aeromag_grid::Grid::from_axes`).
    #[staticmethod]
    #[pyo3(
        signature = (values, x, y, *, name=String::new(), unit=String::new(), epsg=None),
        text_signature = "(values, x, y, *, name='', unit='', epsg=None)"
    )]
    fn from_array(
        py: Python<'_>,
        values: &Bound<'_, PyAny>,
        x: &Bound<'_, PyAny>,
        y: &Bound<'_, PyAny>,
        name: String,
        unit: String,
        epsg: Option<Bound<'_, PyAny>>,
    ) -> PyResult<PyGrid> {
        let crs = crs_of_epsg(epsg.as_ref())?;
        let (values, shape) = float_array(py, values, "values", 2)?;
        let (x, _) = float_array(py, x, "x", 1)?;
        let (y, _) = float_array(py, y, "y", 1)?;
        if shape != [y.len(), x.len()] {
            return Err(bad_argument(format!(
                "values of shape {shape:?}: a grid of len(y) × len(x) = [{}, {}] nodes takes \
                 values of that shape (rows along y)",
                y.len(),
                x.len()
            )));
        }
        let mut grid = Grid::from_axes(&x, &y, &values, &name, &unit).py_err()?;
        grid.crs = crs;
        Ok(PyGrid::plain(grid))
    }

    /// The grid as an `xarray.DataArray` (needs xarray): dimensions
    /// `("y", "x")`, rows from the south, coordinates `x` and `y` in m,
    /// named as the grid, `attrs["units"]` its unit; with a coordinate
    /// system, a `spatial_ref` coordinate holding its WKT (`crs_wkt`,
    /// `spatial_ref`) named by `attrs["grid_mapping"]`, as rioxarray and
    /// CF write it. `Grid.from_xarray` reads it back.
    fn to_xarray<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let xr = py.import("xarray").map_err(|_| {
            pyo3::exceptions::PyImportError::new_err(
                "Grid.to_xarray needs xarray: pip install xarray",
            )
        })?;
        let axis = |values: Bound<'py, PyArray1<f64>>, dim: &str| -> PyResult<Bound<'py, PyAny>> {
            let attrs = PyDict::new(py);
            attrs.set_item("units", "m")?;
            attrs.set_item("standard_name", format!("projection_{dim}_coordinate"))?;
            ((dim,), values, attrs)
                .into_pyobject(py)
                .map(|t| t.into_any())
        };
        let coords = PyDict::new(py);
        coords.set_item("x", axis(self.x(py), "x")?)?;
        coords.set_item("y", axis(self.y(py), "y")?)?;
        let attrs = PyDict::new(py);
        if !self.grid.unit.is_empty() {
            attrs.set_item("units", &self.grid.unit)?;
        }
        if let Some(crs) = self.grid.crs {
            let wkt = crs.wkt();
            let reference = PyDict::new(py);
            reference.set_item("crs_wkt", &wkt)?;
            reference.set_item("spatial_ref", &wkt)?;
            coords.set_item("spatial_ref", ((), 0, reference))?;
            attrs.set_item("grid_mapping", "spatial_ref")?;
        }
        let kwargs = PyDict::new(py);
        kwargs.set_item("dims", ("y", "x"))?;
        kwargs.set_item("coords", coords)?;
        kwargs.set_item("attrs", attrs)?;
        if !self.grid.name.is_empty() {
            kwargs.set_item("name", &self.grid.name)?;
        }
        xr.getattr("DataArray")?
            .call((self.values(py)?,), Some(&kwargs))
    }

    /// A grid from a 2-D `xarray.DataArray` (`to_xarray`'s, verde's,
    /// harmonica's, rioxarray's): its first dimension the rows (northing),
    /// its second the columns (easting), each with a 1-D coordinate in m,
    /// in either direction; the name from `.name`, the unit from
    /// `attrs["units"]`; the coordinate system `epsg` if given, else the
    /// WKT (`crs_wkt` or `spatial_ref`) of the coordinate
    /// `attrs["grid_mapping"]` names (default `spatial_ref`), when it is a
    /// WGS 84 / UTM zone. A WKT in degrees or feet is refused: aeromag's
    /// grids are in metres.
    #[staticmethod]
    #[pyo3(signature = (array, *, epsg=None))]
    fn from_xarray(
        py: Python<'_>,
        array: &Bound<'_, PyAny>,
        epsg: Option<Bound<'_, PyAny>>,
    ) -> PyResult<PyGrid> {
        let not_an_array = |_| bad_argument("from_xarray takes an xarray.DataArray");
        let dims: Vec<String> = array
            .getattr("dims")
            .and_then(|d| d.extract())
            .map_err(not_an_array)?;
        let [rows, columns] = dims.as_slice() else {
            return Err(bad_argument(format!(
                "a DataArray of dimensions {dims:?}: a grid has two, rows (northing) then \
                 columns (easting)"
            )));
        };
        let coords = array.getattr("coords").map_err(not_an_array)?;
        let axis = |dim: &str| -> PyResult<Bound<'_, PyAny>> {
            if !coords.contains(dim)? {
                return Err(bad_argument(format!(
                    "dimension {dim:?} has no coordinate: give the nodes' coordinates in m \
                     (array.assign_coords({dim}=...))"
                )));
            }
            coords.get_item(dim)?.getattr("values")
        };
        let (y, x) = (axis(rows)?, axis(columns)?);
        let text = |v: Bound<'_, PyAny>| -> PyResult<String> {
            if v.is_none() {
                Ok(String::new())
            } else {
                Ok(v.str()?.to_string())
            }
        };
        let name = text(array.getattr("name")?)?;
        let attrs = array.getattr("attrs")?;
        let unit = text(attrs.call_method1("get", ("units",))?)?;
        let crs = if epsg.as_ref().is_some_and(|e| !e.is_none()) {
            crs_of_epsg(epsg.as_ref())?
        } else {
            let mapping = text(attrs.call_method1("get", ("grid_mapping", "spatial_ref"))?)?;
            let wkt = if coords.contains(&mapping)? {
                let a = coords.get_item(&mapping)?.getattr("attrs")?;
                let w = text(a.call_method1("get", ("crs_wkt",))?)?;
                if w.is_empty() {
                    text(a.call_method1("get", ("spatial_ref",))?)?
                } else {
                    w
                }
            } else {
                String::new()
            };
            aeromag::grid::projection::Crs::from_wkt_in_metres(&wkt)
                .map_err(|reason| bad_argument(format!("the DataArray's {mapping}: {reason}")))?
        };
        let values = array.getattr("values")?;
        let mut grid = Self::from_array(py, &values, &x, &y, name, unit, None)?;
        grid.grid.crs = crs;
        Ok(grid)
    }

    /// Write the grid; the format follows the extension (`.tif`, `.asc`,
    /// `.nc`/`.grd`, `.gxf`; `name.grd(GRD)` writes Oasis montaj's own grid
    /// to `name.grd`, without its coordinate system).
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
    if g.nx.checked_mul(g.ny) != Some(values.len()) {
        return Err(bad_argument(format!(
            "{what}: {} values for {} × {} nodes",
            values.len(),
            g.nx,
            g.ny
        )));
    }
    if let Some(problem) = g.problem() {
        return Err(bad_argument(format!(
            "{what}: not a grid's geometry: {problem}"
        )));
    }
    let crs = crs_of_epsg(epsg.as_ref())?;
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
