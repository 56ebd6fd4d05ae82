"""TollesLawson: the CLI's model, byte for byte; scikit-learn conventions;
progress and the GIL."""

import threading

import numpy as np
import pytest

import aeromag
from aeromag import _aeromag


@pytest.mark.parametrize(
    "flags, params",
    [
        ([], {}),
        (
            ["--terms", "p3,i6,e9", "--convention", "magnav", "--lambda", "0.01", "--band", "0.2,0.8", "--trim", "10"],
            dict(terms="p3,i6,e9", convention="magnav", ridge_lambda=0.01, band=(0.2, 0.8), trim=10),
        ),
        (["--eddy-lag", "0.3,0.8", "--reference", "none"], dict(eddy_lag=[0.3, 0.8], reference="none")),
        (["--band", "none", "--no-split-lines", "--eddy-lag", "none"], dict(band=None, no_split_lines=True, eddy_lag="none")),
        (
            ["--lever-arm", "1.5,0,-0.2", "--date", "2020-06-01", "--eddy-lag", "none"],
            dict(lever_arm=(1.5, 0.0, -0.2), date="2020-06-01", eddy_lag="none"),
        ),
        (["--method", "kalman", "--no-tune", "--field-order", "3"], dict(method="kalman", no_tune=True, field_order=3)),
        # Any recorded channel as an extra regressor (a current on an SGL
        # flight; here the base station's), through a fitted lag, and the
        # exact-magnitude model.
        (
            ["--extra", "diurnal:lag", "--magnitude", "exact", "--eddy-lag", "none", "--reference", "none"],
            dict(extra=["diurnal:lag"], magnitude="exact", eddy_lag="none", reference="none"),
        ),
    ],
)
def test_python_and_cli_write_byte_identical_model_files(cli, cal_csv, tmp_path, flags, params):
    cli_model = tmp_path / "cli.json"
    cli("calibrate", "-i", cal_csv, "--model", cli_model, *flags)
    py_model = tmp_path / "py.json"
    aeromag.TollesLawson(**params).fit(aeromag.read_flight(cal_csv)).save(py_model)
    assert py_model.read_bytes() == cli_model.read_bytes()


def test_compensation_equals_the_cli(cli, cal_csv, survey_csv, tmp_path):
    model = tmp_path / "m.json"
    cli("calibrate", "-i", cal_csv, "--model", model)
    out = tmp_path / "comp.csv"
    cli("compensate", "-i", survey_csv, "--model", model, "--out", out)
    cols = np.genfromtxt(out, delimiter=",", names=True, comments="#")
    survey = aeromag.read_flight(survey_csv)
    loaded = aeromag.load_model(model)
    tl = aeromag.TollesLawson.from_model(loaded)
    np.testing.assert_allclose(tl.transform(survey), cols["mag_comp"], rtol=0, atol=1e-9)
    np.testing.assert_allclose(tl.predict(survey), cols["mag_interf"], rtol=0, atol=1e-9)
    np.testing.assert_array_equal(survey["mag"] - tl.predict(survey), tl.transform(survey))


def test_fitted_attributes_and_sklearn_conventions(cal):
    tl = aeromag.TollesLawson(eddy_lag="none")
    assert not hasattr(tl, "coef_")
    with pytest.raises(AttributeError):
        tl.predict(cal)
    assert tl.fit(cal) is tl
    assert len(tl.coef_) == len(tl.coef_std_) == len(tl.terms_) == 16
    assert tl.terms_[:3] == ["p_x", "p_y", "p_z"]
    assert np.all(tl.coef_std_ > 0)
    assert tl.fit_stats_["rows"] > 1000 and isinstance(tl.notes_, list)
    params = tl.get_params()
    assert params["eddy_lag"] == "none" and params["method"] == "ls"
    clone = aeromag.TollesLawson(**params)
    assert clone.get_params() == params
    assert tl.set_params(ridge_lambda=0.5) is tl and tl.ridge_lambda == 0.5
    assert repr(aeromag.TollesLawson(method="kalman")) == "TollesLawson(method='kalman')"
    # The Kalman series with series=True.
    k = aeromag.TollesLawson(method="kalman", no_tune=True, series=True).fit(cal)
    assert set(k.series_) >= {"kalman_field", "kalman_innovation"}
    assert len(k.series_["kalman_field"]) == len(cal)


def test_python_defaults_are_the_librarys():
    sig = aeromag.TollesLawson().get_params()
    for k, v in _aeromag.calibrate_defaults().items():
        if k == "date":
            assert aeromag.decimal_year(sig["date"]) == v
        elif k == "band":
            assert tuple(sig["band"]) == tuple(v)
        else:
            assert sig[k] == v, k


def test_progress_callback_and_tqdm_like_bar(cal):
    calls = []
    aeromag.TollesLawson().fit(cal, progress=lambda stage, done, total: calls.append((stage, done, total)))
    assert calls and all(isinstance(s, str) for s, _, _ in calls)

    class Bar:
        def __init__(self):
            self.total, self.n, self.descriptions = None, 0, []

        def update(self, k):
            self.n += k

        def reset(self, total=None):
            self.total, self.n = total, 0

        def set_description(self, d):
            self.descriptions.append(d)

    bar = Bar()
    aeromag.TollesLawson(method="kalman", no_tune=True).fit(cal, progress=bar)
    assert bar.descriptions
    # An exception in the callback ends the call with that exception.
    def stop(stage, done, total):
        raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        aeromag.TollesLawson().fit(cal, progress=stop)


def test_the_gil_is_released_while_fitting(cal):
    ticks = []
    done = threading.Event()

    def count():
        while not done.is_set():
            ticks.append(1)

    t = threading.Thread(target=count)
    t.start()
    n0 = len(ticks)
    aeromag.TollesLawson().fit(cal)  # no callback: the GIL is only given up by release
    n1 = len(ticks)
    done.set()
    t.join()
    assert n1 > n0 + 100


def test_igrf_against_the_cli(cli):
    import json

    ref = json.loads(cli("igrf", "--lat", 45.5, "--lon", -73.6, "--alt", 1000, "--date", "2020-06-01", "--json").stdout)
    f = aeromag.igrf([45.5, 45.5], -73.6, 1000.0, "2020-06-01")
    assert f["x"].shape == (2,)
    for k in ["x", "y", "z", "f", "declination", "inclination"]:
        assert abs(f[k][0] - ref[k]) < 1e-9 * max(1.0, abs(ref[k])), k
    with pytest.raises(aeromag.BadInputError):
        aeromag.igrf(95.0, 0.0)
    # A longitude of 1e300 was taken (any finite value was).
    with pytest.raises(aeromag.BadInputError, match="−360…360"):
        aeromag.igrf(45.0, 1e300)
    # None was read as NaN ("lat NaN°"), a complex latitude lost its
    # imaginary part with NumPy's warning only.
    with pytest.raises(TypeError, match="lat must be a number"):
        aeromag.igrf(None, 0.0)
    with pytest.raises(TypeError, match="time must be a number"):
        aeromag.igrf(0.0, 0.0, 0.0, None)
    with pytest.raises(TypeError, match="lat must be real"):
        aeromag.igrf(np.array([50 + 5j]), 0.0)
