"""Maps from Python (grid_flight, read_grid, microlevel): the same grids as
the CLI, NumPy arrays with coordinates and CRS."""

from pathlib import Path

import numpy as np
import pytest

import aeromag


def test_grid_equals_the_cli(cli, survey_csv, tmp_path):
    survey = aeromag.read_flight(survey_csv)
    g = aeromag.grid_flight(survey, column="true_anomaly", cell=100.0)
    out = tmp_path / "cli.nc"
    cli("grid", "-i", survey_csv, "--column", "true_anomaly", "--cell", 100, "--out", out)
    c = aeromag.read_grid(out)
    assert g.values.shape == (len(g.y), len(g.x)) == c.values.shape
    assert g.epsg == c.epsg == 32637 and g.crs == "WGS 84 / UTM zone 37N"
    np.testing.assert_array_equal(g.x, c.x)
    np.testing.assert_array_equal(g.y, c.y)
    # The file holds float32.
    np.testing.assert_allclose(g.values, c.values, rtol=0, atol=1e-3, equal_nan=True)
    info = g.info
    assert info["column"] == "true_anomaly" and abs(info["line_spacing_m"] - 500) < 5
    assert info["converged"] in (True, False) and info["blanked_nodes"] >= 0
    # Row 0 is the south row; sample() interpolates the nodes.
    assert g.y[0] < g.y[-1]
    j, i = np.argwhere(np.isfinite(g.values))[len(g.x)]
    assert g.sample(g.x[i], g.y[j]) == pytest.approx(g.values[j, i])


def test_products_and_files(survey_csv, tmp_path):
    survey = aeromag.read_flight(survey_csv)
    g = aeromag.grid_flight(survey, column="true_anomaly", method="bidirectional")
    d = g.vertical_derivative()
    assert d.unit == "nT/m" and d.values.shape == g.values.shape
    up = g.upward(200.0)
    assert up.stats()["std"] < g.stats()["std"]
    assert g.minus(g).stats()["std"] == 0.0
    for name in ["g.tif", "g.asc", "g.nc", "g.gxf"]:
        g.write(tmp_path / name)
        back = aeromag.read_grid(tmp_path / name)
        np.testing.assert_allclose(back.values, g.values, atol=1e-3, equal_nan=True)
    # Maps, as `aeromag grid --map` draws them.
    g.write_map(tmp_path / "g.png")
    assert (tmp_path / "g.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    d.write_map(tmp_path / "d.svg", diverging=True)
    assert "<svg" in (tmp_path / "d.svg").read_text()
    with pytest.raises(aeromag.BadInputError, match="PNG"):
        g.write_map(tmp_path / "g.jpg")


def test_microlevel_and_bad_arguments(survey_csv):
    survey = aeromag.read_flight(survey_csv)
    m = aeromag.microlevel(survey, column="true_anomaly")
    rms, largest = m.correction_nt
    assert 0 <= rms <= largest
    assert m.output_column == "true_anomaly_mlev"
    before, after = m.crossover_rms_nt
    assert before >= 0 and after >= 0
    f = m.to_flight()
    np.testing.assert_array_equal(f["true_anomaly_mlev"], m.values)
    assert repr(m) == (
        f"<aeromag.Microlevelled true_anomaly → true_anomaly_mlev: correction {rms:.4f} nT RMS "
        f"(largest {largest:.4f} nT), crossovers {before:.4f} → {after:.4f} nT RMS>"
    )
    with pytest.raises(aeromag.BadInputError, match="nope"):
        aeromag.grid_flight(survey, column="nope")
    with pytest.raises(aeromag.BadInputError, match="bidi"):
        aeromag.grid_flight(survey, method="bidi")
    with pytest.raises(aeromag.BadInputError, match="61"):
        aeromag.grid_flight(survey, utm_zone="61N")
    with pytest.raises(aeromag.BadInputError):
        aeromag.read_grid("/nonexistent/grid.tif")


def test_minimum_curvature_limits(survey_csv):
    """max_sweeps and convergence are `aeromag grid`'s --max-sweeps and
    --convergence: they act, and are checked."""
    survey = aeromag.read_flight(survey_csv)
    short = aeromag.grid_flight(survey, column="true_anomaly", max_sweeps=10)
    assert short.info["converged"] is False
    full = aeromag.grid_flight(survey, column="true_anomaly", max_sweeps=5000)
    assert full.info["converged"] is True
    with pytest.raises(aeromag.BadInputError, match="max sweeps = 0"):
        aeromag.grid_flight(survey, max_sweeps=0)
    with pytest.raises(aeromag.BadInputError, match="convergence"):
        aeromag.grid_flight(survey, convergence=-1.0)


def test_microlevel_gridding_limits_and_cutoff(survey_csv):
    """microlevel takes grid_flight's minimum-curvature limits for its
    working grid and says how it converged; a cut-off below 2 line
    spacings (which passed none of the stripes) is refused."""
    survey = aeromag.read_flight(survey_csv)
    short = aeromag.microlevel(survey, column="true_anomaly", max_sweeps=10)
    # Each of the final grid's two relaxations stops at 10 sweeps.
    assert short.gridding == (20, False)
    assert any("max-sweeps" in n for n in short.notes)
    full = aeromag.microlevel(survey, column="true_anomaly", max_sweeps=5000)
    sweeps, converged = full.gridding
    assert converged is True and 20 < sweeps < 10000
    assert not any("max-sweeps" in n for n in full.notes)
    with pytest.raises(aeromag.BadInputError, match="cut-off 1 line spacings is below 2"):
        aeromag.microlevel(survey, column="true_anomaly", cutoff=1.0)
    with pytest.raises(aeromag.BadInputError, match="max sweeps = 0"):
        aeromag.microlevel(survey, column="true_anomaly", max_sweeps=0)


def test_projected_positions(survey_csv):
    """A flight with eastings and northings (X, Y) instead of lat/lon grids
    in their plane (no CRS without their zone), named or found; levelling
    them needs their UTM zone."""
    survey = aeromag.read_flight(survey_csv)
    d = {c: np.asarray(survey[c]) for c in survey.columns if c not in ("lat", "lon")}
    lat, lon = np.radians(np.asarray(survey["lat"])), np.radians(np.asarray(survey["lon"]))
    x = 6371000.0 * np.cos(lat.mean()) * (lon - lon.mean())
    y = 6371000.0 * (lat - lat.mean())
    found = aeromag.grid_flight(aeromag.Flight.from_dict({**d, "X": x, "Y": y}),
                                column="true_anomaly", cell=100.0)
    named = aeromag.grid_flight(aeromag.Flight.from_dict({**d, "E": x, "N": y}),
                                column="true_anomaly", cell=100.0, xy=("E", "N"))
    assert found.epsg is None and named.epsg is None
    assert np.isfinite(found.values).sum() > found.values.size / 2
    np.testing.assert_array_equal(found.values, named.values)
    np.testing.assert_array_equal(found.x, named.x)
    assert found.x[0] < 0 < found.x[-1]
    with pytest.raises(aeromag.BadInputError, match="utm-zone"):
        aeromag.level(aeromag.Flight.from_dict({**d, "X": x, "Y": y}))


GEOSOFT = Path(__file__).resolve().parents[2] / "crates/grid/tests/data/geosoft"


@pytest.mark.parametrize("name", ["om_float.grd", "om_short.grd", "om_order.grd", "om_compress.grd"])
def test_an_oasis_montaj_grid_reads_as_harmonica_reads_it(name):
    g = aeromag.read_grid(GEOSOFT / name)
    assert g.values.shape == (49, 50)
    assert (g.cell, g.x[0], g.y[0], g.epsg) == (1.0, 1.0, -24.0, None)
    assert np.isnan(g.values).sum() == 655
    harmonica = pytest.importorskip("harmonica")
    want = harmonica.load_oasis_montaj_grid(GEOSOFT / name).values
    np.testing.assert_array_equal(np.isnan(g.values), np.isnan(want))
    np.testing.assert_allclose(g.values, want, rtol=1e-14, atol=0)


def test_a_grid_from_arrays_in_either_direction():
    x = 500000.0 + 25.0 * np.arange(4)
    y = 6000000.0 + 25.0 * np.arange(3)
    v = np.arange(12, dtype=float).reshape(3, 4)
    v[1, 2] = np.nan
    g = aeromag.Grid.from_array(v, x, y, name="tmi", unit="nT", epsg=32637)
    assert (g.cell, g.x[0], g.y[0], g.epsg, g.name, g.unit) == (25.0, x[0], y[0], 32637, "tmi", "nT")
    np.testing.assert_array_equal(g.values, v)
    # A north-up raster (y descending) and x reversed: the same grid.
    h = aeromag.Grid.from_array(v[::-1, ::-1], x[::-1], y[::-1])
    np.testing.assert_array_equal(h.values, v)
    assert (h.x[0], h.y[0], h.epsg) == (x[0], y[0], None)
    # Integer values and lists are numbers too.
    assert aeromag.Grid.from_array([[1, 2], [3, 4]], [0, 10], [0, 10]).values.tolist() == [[1.0, 2.0], [3.0, 4.0]]


@pytest.mark.parametrize(
    "values, x, y, needle",
    [
        (np.zeros((4, 3)), np.arange(4.0), np.arange(3.0), "values of shape [4, 3]"),
        (np.zeros((2, 3)), [0.0, 1.0, 2.5], [0.0, 1.25], "not evenly spaced"),
        (np.zeros((2, 3)), [0.0, 1.0, 2.0], [0.0, 2.0], "square cells"),
        (np.zeros(6), np.arange(3.0), np.arange(2.0), "a 2-D array is needed"),
        (np.full((2, 2), np.inf), [0.0, 1.0], [0.0, 1.0], "must be finite"),
        ([["a", "b"], ["c", "d"]], [0.0, 1.0], [0.0, 1.0], "not an array of numbers"),
    ],
)
def test_what_is_not_a_grid_is_refused(values, x, y, needle):
    with pytest.raises(aeromag.BadInputError, match=None) as e:
        aeromag.Grid.from_array(values, x, y)
    assert needle in str(e.value)


def test_xarray_round_trip_and_other_libraries_layouts(survey_csv):
    xr = pytest.importorskip("xarray")
    g = aeromag.grid_flight(aeromag.read_flight(survey_csv), column="true_anomaly", cell=100.0)
    da = g.to_xarray()
    assert da.dims == ("y", "x") and da.name == g.name and da.attrs["units"] == g.unit
    assert da.attrs["grid_mapping"] == "spatial_ref" and "UTM" in da["spatial_ref"].attrs["crs_wkt"]
    np.testing.assert_array_equal(da["x"].values, g.x)
    back = aeromag.Grid.from_xarray(da)
    np.testing.assert_array_equal(back.values, g.values)
    assert (back.x[0], back.y[0], back.cell, back.epsg, back.name, back.unit) == (
        g.x[0], g.y[0], g.cell, g.epsg, g.name, g.unit)
    # harmonica's / verde's layout: northing then easting, no CRS; a
    # north-up copy (y descending) is the same grid.
    other = xr.DataArray(g.values[::-1], dims=("northing", "easting"),
                         coords={"northing": g.y[::-1], "easting": g.x})
    same = aeromag.Grid.from_xarray(other, epsg=g.epsg)
    np.testing.assert_array_equal(same.values, g.values)
    assert same.epsg == g.epsg
    # Geographic coordinates are refused, as in the grid files.
    geo = da.copy()
    geo["spatial_ref"].attrs["crs_wkt"] = (
        'GEOGCS["WGS 84",DATUM["WGS_1984",SPHEROID["WGS 84",6378137,298.257223563]],'
        'PRIMEM["Greenwich",0],UNIT["degree",0.0174532925199433],AUTHORITY["EPSG","4326"]]')
    with pytest.raises(aeromag.BadInputError) as e:
        aeromag.Grid.from_xarray(geo)
    assert "geographic coordinate system" in str(e.value)
    with pytest.raises(aeromag.BadInputError) as e:
        aeromag.Grid.from_xarray(xr.DataArray(np.zeros((2, 2)), dims=("a", "b")))
    assert "dimension 'a' has no coordinate" in str(e.value) or 'dimension "a" has no coordinate' in str(e.value)


def test_a_grid_written_for_oasis_montaj_reads_back(tmp_path):
    g = aeromag.read_grid(GEOSOFT / "om_float.grd")
    g.write(tmp_path / "again.grd(GRD)")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["again.grd"]
    assert (tmp_path / "again.grd").read_bytes()[184:] == (GEOSOFT / "om_float.grd").read_bytes()[184:]
    back = aeromag.read_grid(tmp_path / "again.grd")
    np.testing.assert_array_equal(back.values, g.values)
    harmonica = pytest.importorskip("harmonica")
    np.testing.assert_array_equal(harmonica.load_oasis_montaj_grid(tmp_path / "again.grd").values, g.values)
