"""Pickling: models and grids come back bit for bit (pickle, copy.deepcopy,
a model fitted in a worker process), and a corrupt payload is bad input."""

import copy
import multiprocessing
import pathlib
import pickle
from concurrent.futures import ProcessPoolExecutor

import numpy as np
import pytest

import aeromag
from aeromag import _aeromag

SGL = 'installation = "sgl"\n'


def bits(a):
    """An array's dtype, shape and bytes: equal only when bit for bit
    equal (NaN included, unlike ==)."""
    a = np.asarray(a)
    return a.dtype.str, a.shape, a.tobytes()


def same_output(x, y):
    """Arrays, or dicts of arrays (SensorsModel.compensate), bit for bit."""
    if isinstance(x, dict):
        return x.keys() == y.keys() and all(bits(x[k]) == bits(y[k]) for k in x)
    return bits(x) == bits(y)


def copies(x):
    """x through pickle (the oldest and the newest protocol) and deepcopy."""
    out = [pickle.loads(pickle.dumps(x, protocol=p)) for p in (0, pickle.HIGHEST_PROTOCOL)]
    return out + [copy.deepcopy(x)]


@pytest.fixture(scope="module")
def cal():
    return aeromag.simulate("calibration", seed=1)


@pytest.fixture(scope="module")
def survey():
    return aeromag.simulate("survey", seed=2)


def assert_same_model(a, b, flight):
    """The same model: its file, notes and what it does to `flight`."""
    assert type(a) is type(b) and a is not b
    assert a.to_json() == b.to_json()
    assert a.notes == b.notes
    for name in ("interference", "compensate"):
        if hasattr(a, name):
            assert same_output(getattr(a, name)(flight), getattr(b, name)(flight)), name


@pytest.mark.parametrize(
    "params",
    [
        {},
        dict(eddy_lag="auto", terms="p3,i6,e9", ridge_lambda=0.01),
        dict(method="kalman", no_tune=True, series=True),
    ],
)
def test_tl_model_round_trips_bit_for_bit(cal, params):
    if params.get("series"):
        # Rows without a reading: the series are NaN there, and those bits
        # must come back too.
        d = cal.to_dict()
        d["mag"][1000:1010] = np.nan
        cal = aeromag.Flight.from_dict(d)
    m = aeromag.TollesLawson(**params).fit(cal).model_
    if params.get("series"):
        assert any(np.isnan(v).any() for v in m.series.values())
    for c in copies(m):
        assert_same_model(m, c, cal)
        assert bits(c.coef) == bits(m.coef) and bits(c.coef_std) == bits(m.coef_std)
        assert c.terms == m.terms and c.method == m.method and c.fit_stats == m.fit_stats
        assert repr(c) == repr(m)
        if m.series is None:
            assert c.series is None
        else:
            assert c.series.keys() == m.series.keys()
            for k in m.series:
                assert bits(c.series[k]) == bits(m.series[k]), k
        causal = m.compensate(cal, causal=True)
        assert bits(c.compensate(cal, causal=True)) == bits(causal)
    # The fitted estimator, which holds the model, pickles too.
    tl = aeromag.TollesLawson(**params).fit(cal)
    back = pickle.loads(pickle.dumps(tl))
    assert bits(back.transform(cal)) == bits(tl.transform(cal))
    assert back.get_params() == tl.get_params()


def test_notes_and_a_model_read_from_a_file_round_trip(cal, tmp_path):
    # A fit on a single heading leaves terms undetermined: warnings.
    d = cal.to_dict()
    one = aeromag.Flight.from_dict({k: v[d["line"] == 1] for k, v in d.items()})
    m = aeromag.TollesLawson(eddy_lag="none").fit(one).model_
    assert any(n.startswith("warning") for n in m.notes)
    assert_same_model(m, pickle.loads(pickle.dumps(m)), cal)
    m.save(tmp_path / "m.json")
    loaded = aeromag.load_model(tmp_path / "m.json")
    assert loaded.notes == [] and loaded.to_json() == m.to_json()
    assert_same_model(loaded, pickle.loads(pickle.dumps(loaded)), cal)


def test_sensors_model_round_trips():
    flight = aeromag.simulate("calibration_truncated", seed=3, config=SGL)
    m = aeromag.calibrate_sensors(flight, ["mag_1_uc", "mag_4_uc"], vector="flux_a",
                                  reference_sensor="mag_1_uc")
    assert {"mag_1_comp", "mag_4_comp", "mag_4_grad"} <= m.compensate(flight).keys()
    for c in copies(m):
        assert_same_model(m, c, flight)
        assert c.sensors == m.sensors and c.reference_sensors == m.reference_sensors
        assert [s.to_json() for s in c.models] == [s.to_json() for s in m.models]


def test_rotor_and_pod_models_round_trip(tmp_path):
    heli = aeromag.simulate("helicopter", seed=11)
    pod = aeromag.simulate("pod", seed=1)
    setup = dict(cable_length_m=40.0, attach_m=(0, 0, 1.2), inclination_deg=45.0,
                 grad_north_nt_per_km=5.91, grad_up_nt_per_km=-25.91)
    for m, flight in [
        (aeromag.fit_rotor(heli, preset="aeromag-sim-helicopter"), heli),
        (aeromag.fit_pod(pod, **setup), pod),
    ]:
        for c in copies(m):
            assert_same_model(m, c, flight)
            assert c.kind == m.kind and bits(c.coef) == bits(m.coef)
            assert c.heading_rates(flight) == m.heading_rates(flight)
        # load_model shares the constructor's choice by kind; a file with a
        # byte-order mark was read as a Tolles-Lawson model and refused.
        path = tmp_path / "m.json"
        path.write_text("\ufeff" + m.to_json(), encoding="utf-8")
        loaded = aeromag.load_model(path)
        assert type(loaded) is aeromag.Model and loaded.to_json() == m.to_json()


def test_grid_round_trips_bit_for_bit(survey):
    g = aeromag.grid_flight(survey, column="true_anomaly", cell=100.0)
    assert np.isnan(g.values).any(), "blank nodes (NaN) must come back too"
    # A product grid has no info; its unit is its own.
    for grid in (g, g.vertical_derivative()):
        for c in copies(grid):
            assert type(c) is aeromag.Grid and c is not grid
            for name in ("values", "x", "y"):
                assert bits(getattr(c, name)) == bits(getattr(grid, name)), name
            assert (c.cell, c.epsg, c.crs, c.name, c.unit) == (
                grid.cell, grid.epsg, grid.crs, grid.name, grid.unit)
            assert c.info == grid.info and repr(c) == repr(grid)
            assert c.stats() == grid.stats()
            assert bits(c.upward(200.0).values) == bits(grid.upward(200.0).values)
    assert g.info["column"] == "true_anomaly" and g.epsg == 32637


MAT5 = pathlib.Path(__file__).resolve().parents[2] / "crates" / "io" / "tests" / "data" / "mat5"


def assert_same_flight(a, b):
    """The same flight: columns (bit for bit, text as text), mapping, file,
    warnings, unread columns and variables, and the same CSV written
    (integer columns as read)."""
    assert type(b) is aeromag.Flight and b is not a
    for name in ("columns", "mapping", "file", "warnings", "unread_columns", "not_read"):
        assert getattr(b, name) == getattr(a, name), name
    assert len(b) == len(a) and repr(b) == repr(a)
    for name in a.columns:
        assert bits(b[name]) == bits(a[name]), name


def csv_bytes(flight, path):
    flight.to_csv(path)
    return path.read_bytes()


def test_flights_round_trip_bit_for_bit(cal_csv, tmp_path):
    read = aeromag.read_flight(cal_csv)
    selected = aeromag.read_flight(cal_csv, lines=[2, 3], fields=["time", "lat", "lon", "alt", "mag",
                                                                  "flux_x", "flux_y", "flux_z", "line"])
    assert selected.unread_columns and len(selected) < len(read)
    d = read.to_dict()
    d["mag"][100:103] = np.nan
    d["line"] = np.array([f"L{int(x)}" for x in d["line"]])
    d["line"][5] = ""
    built = aeromag.Flight.from_dict(d, copy=False)
    model = aeromag.TollesLawson().fit(read).model_
    mat = MAT5 / "magnav.mat"
    from_mat = aeromag.read_flight(mat)
    assert from_mat.not_read
    for c in copies(from_mat):
        assert_same_flight(from_mat, c)
    for flight in (read, selected, built, model.apply(built)):
        for c in copies(flight):
            assert_same_flight(flight, c)
            assert csv_bytes(c, tmp_path / "c.csv") == csv_bytes(flight, tmp_path / "f.csv")
            assert bits(model.compensate(c)) == bits(model.compensate(flight))
    assert read.file == str(cal_csv) and built["line"][5] == ""
    # What is fitted on a copy is what is fitted on the flight.
    assert aeromag.TollesLawson().fit(copy.deepcopy(selected)).model_.to_json() == (
        aeromag.TollesLawson().fit(selected).model_.to_json())


def test_a_corrupt_flight_payload_is_bad_input(cal):
    make, (layout, numbers) = cal.__reduce__()
    assert make is _aeromag._flight_from_state
    assert_same_flight(cal, make(layout, numbers))
    t = cal["time"]
    backwards = bytearray(numbers)
    backwards[:16] = np.array([t[1], t[0]]).tobytes()
    cases = [
        (("{not json", numbers), "layout is not readable"),
        ((layout, numbers[:-8]), "numbers for"),
        ((layout, numbers[:-1]), "8-byte floats"),
        ((layout.replace('"name":"lat"', '"name":"lon"'), numbers), "repeated"),
        ((layout, bytes(backwards)), "time"),
    ]
    for args, match in cases:
        with pytest.raises(aeromag.BadInputError, match=match):
            make(*args)


def test_a_pickled_flight_keeps_its_file_lines_and_data_rows(tmp_path):
    """The rows of a flight read with a line selection keep their file
    lines and data rows: the errors of the rebuilt flight name them."""
    p = tmp_path / "sel.csv"
    p.write_text("time,mag,line\n0,50000,1\n1,50000,1\n2,50000,2\n3,50000,2\n4,50000,2\n")
    f = aeromag.read_flight(p, lines=[2])
    make, (layout, numbers) = f.__reduce__()
    assert_same_flight(f, make(layout, numbers))
    # Time 2, 1.5, 4: the second row (data row 3, line 5) goes back.
    changed = bytearray(numbers)
    changed[8:16] = np.array([1.5]).tobytes()
    with pytest.raises(aeromag.BadInputError) as e:
        make(layout, bytes(changed))
    assert (e.value.file, e.value.line, e.value.row, e.value.column) == (str(p), 5, 3, "time")


def fit_in_worker(seed):
    """In a worker process: simulate and fit; the model goes back pickled."""
    flight = aeromag.simulate("calibration", seed=seed)
    return aeromag.TollesLawson(method="ls").fit(flight).model_


def test_a_model_fitted_in_a_worker_process_equals_one_fitted_here(cal):
    ctx = multiprocessing.get_context("spawn")
    with ProcessPoolExecutor(max_workers=1, mp_context=ctx) as pool:
        remote = pool.submit(fit_in_worker, 1).result()
    local = aeromag.TollesLawson(method="ls").fit(cal).model_
    assert isinstance(remote, aeromag.TlModel)
    assert_same_model(local, remote, cal)
    assert bits(remote.coef) == bits(local.coef)
    # The package's own process pool returns models too.
    [batched] = aeromag.batch(fit_in_worker, [1], processes=1)
    assert batched.to_json() == local.to_json()


def test_corrupt_payloads_are_bad_input(cal, survey):
    m = aeromag.TollesLawson(method="kalman", no_tune=True, series=True).fit(cal).model_
    make, (text, notes, series) = m.__reduce__()
    assert make is _aeromag._model_from_json
    assert_same_model(m, make(text, notes, series), cal)
    cases = [
        (("garbage",), "not a JSON model file"),
        ((text.replace('"coefficients"', '"coefs"'),), "coefficients"),
        ((text.replace('"tolles-lawson"', '"helicopter-rotor"'),), "rotor"),
        ((text, "{not json"), "notes"),
        ((text, notes, series[:-3]), "not a whole number of 8-byte floats"),
        ((text, notes, series[:8]), "not five series"),
    ]
    for args, match in cases:
        with pytest.raises(aeromag.BadInputError, match=match):
            make(*args)
    rotor_text = aeromag.fit_pod(aeromag.simulate("pod", seed=1), cable_length_m=40.0,
                                 inclination_deg=45.0, attach_m=(0, 0, 1.2)).to_json()
    with pytest.raises(aeromag.BadInputError, match="no Kalman series"):
        make(rotor_text, "[]", series)

    g = aeromag.grid_flight(survey, column="true_anomaly", cell=200.0)
    make, (values, (x0, y0, cell, nx, ny), epsg, name, unit, info) = g.__reduce__()
    assert make is _aeromag._grid_from_state
    geometry = (x0, y0, cell, nx, ny)
    cases = [
        ((values[:-1], geometry, epsg), "8-byte floats"),
        ((values, (x0, y0, cell, nx + 1, ny), epsg), "values for"),
        ((values, (x0, y0, cell, nx, -ny), epsg), "ny must not be negative"),
        ((values, (x0, y0, -cell, nx, ny), epsg), "geometry"),
        ((values, (float("nan"), y0, cell, nx, ny), epsg), "geometry"),
        ((values, geometry, 4326), "UTM zone"),
        ((values, geometry, 1 << 20), "epsg: 1048576 is too large"),
    ]
    for args, match in cases:
        with pytest.raises(aeromag.BadInputError, match=match):
            make(*args, name, unit, info)
    c = make(values, geometry, None, name, unit, {})
    assert c.crs is None and c.epsg is None and c.info == {}
    assert bits(c.values) == bits(g.values)


def test_an_em_calibration_round_trips(tmp_path):
    files = aeromag.simulate_em(str(tmp_path / "em"), seed=3)
    det = aeromag.detect_em(files["raw"])
    cal = aeromag.calibrate_em(det, files["known"], files["system"])
    poses = aeromag.locate_em(det, cal).to_dict()
    figures = ("polarization_ratio_before", "polarization_ratio_after", "transmitter_distortion",
               "attitude_correction_deg")
    for c in copies(cal):
        assert type(c) is aeromag.EmCalibration and c is not cal
        assert c.to_json() == cal.to_json() and repr(c) == repr(cal)
        assert [getattr(c, f) for f in figures] == [getattr(cal, f) for f in figures]
        again = aeromag.locate_em(det, c).to_dict()
        assert again.keys() == poses.keys()
        assert all(bits(again[k]) == bits(poses[k]) for k in poses)
    make, (text, *numbers) = cal.__reduce__()
    assert make is _aeromag._em_calibration_from_json
    with pytest.raises(aeromag.BadInputError, match="pickled EM calibration"):
        make("garbage", *numbers)
    with pytest.raises(aeromag.BadInputError, match="version"):
        make(text.replace('"version": 1', '"version": 99'), *numbers)


def same_flight(a, b):
    """Two flights with the same columns, bit for bit."""
    x, y = a.to_dict(), b.to_dict()
    return list(x) == list(y) and all(
        bits(x[k]) == bits(y[k]) if np.asarray(x[k]).dtype.kind == "f" else list(x[k]) == list(y[k])
        for k in x
    )


def test_levelled_and_microlevelled_surveys_round_trip(survey):
    lev = aeromag.level(survey)
    figures = ("value_column", "output_column", "k_s", "rms_nt", "line_levels", "notes")
    for c in copies(lev):
        assert type(c) is aeromag.Levelled and c is not lev and repr(c) == repr(lev)
        assert [getattr(c, f) for f in figures] == [getattr(lev, f) for f in figures]
        assert bits(c.levelled) == bits(lev.levelled) and bits(c.flags) == bits(lev.flags)
        assert same_flight(c.crossovers(), lev.crossovers())
        assert same_flight(c.to_flight(), lev.to_flight())
    make, (state, flight) = lev.__reduce__()
    assert make is _aeromag._levelled_from_state and isinstance(flight, aeromag.Flight)
    with pytest.raises(aeromag.BadInputError, match="pickled levelled survey: its state"):
        make(b"garbage", flight)
    short = aeromag.Flight.from_dict({k: v[:10] for k, v in survey.to_dict().items()})
    with pytest.raises(aeromag.BadInputError, match="values for a flight of 10 rows"):
        make(state, short)

    m = aeromag.microlevel(lev.to_flight(), column=lev.output_column)
    figures = ("column", "output_column", "correction_nt", "crossover_rms_nt", "gridding", "notes")
    for c in copies(m):
        assert type(c) is aeromag.Microlevelled and c is not m and repr(c) == repr(m)
        assert [getattr(c, f) for f in figures] == [getattr(m, f) for f in figures]
        assert bits(c.values) == bits(m.values) and bits(c.correction) == bits(m.correction)
        assert same_flight(c.to_flight(), m.to_flight())
    make, (state, flight) = m.__reduce__()
    assert make is _aeromag._microlevelled_from_state
    with pytest.raises(aeromag.BadInputError, match="pickled micro-levelled survey: its state"):
        make(state[:-5], flight)
    with pytest.raises(aeromag.BadInputError, match="values for a flight of 10 rows"):
        make(state, short)


def test_em_detections_and_poses_round_trip(tmp_path):
    files = aeromag.simulate_em(str(tmp_path / "em"), seed=4)
    det = aeromag.detect_em(files["raw"])
    poses = aeromag.locate_em(det, aeromag.calibrate_em(det, files["known"], files["system"]))
    for x, figures in [
        (det, ("sample_rate_hz", "window_len", "polarization_ratio_rms", "notes")),
        (poses, ("failed", "by_continuity", "notes")),
    ]:
        for c in copies(x):
            assert type(c) is type(x) and c is not x and repr(c) == repr(x)
            assert len(c) == len(x) > 0
            assert [getattr(c, f) for f in figures] == [getattr(x, f) for f in figures]
            a, b = c.to_dict(), x.to_dict()
            assert a.keys() == b.keys() and all(bits(a[k]) == bits(b[k]) for k in a)
        make, (state,) = x.__reduce__()
        with pytest.raises(aeromag.BadInputError, match="its state is not readable"):
            make(state[: len(state) // 2])
    # A pickled detection locates as the original does.
    again = aeromag.locate_em(pickle.loads(pickle.dumps(det)), aeromag.calibrate_em(
        det, files["known"], files["system"]))
    assert all(bits(again.to_dict()[k]) == bits(poses.to_dict()[k]) for k in poses.to_dict())
