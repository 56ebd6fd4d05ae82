"""Several scalar sensors (issue 20): the CLI's multi-sensor model byte for
byte, its compensated columns, the report's figures and bad input."""

import numpy as np
import pytest

import aeromag

CURRENTS = ["cur_strb", "cur_flap:lag"]


@pytest.fixture(scope="module")
def sgl_csv(cli, tmp_path_factory):
    d = tmp_path_factory.mktemp("sgl")
    toml = d / "sgl.toml"
    toml.write_text('installation = "sgl"\n')
    cli("simulate", "calibration-truncated", "--config", toml, "--seed", 3, "--out", d / "cal")
    return d / "cal" / "calibration_truncated.csv"


@pytest.mark.parametrize(
    "flags, kwargs",
    [
        (
            ["--vector", "flux_a,flux_d", "--extra", ",".join(CURRENTS)],
            dict(vector=["flux_a", "flux_d"], extra=CURRENTS),
        ),
        (
            ["--extra", ",".join(CURRENTS), "--extra-selection", "all", "--reference-sensor", "mag_1_uc"],
            dict(extra=CURRENTS, extra_selection="all", reference_sensor="mag_1_uc"),
        ),
    ],
)
def test_python_and_cli_write_byte_identical_sensor_models(cli, sgl_csv, tmp_path, flags, kwargs):
    cli_model = tmp_path / "cli.json"
    cli("calibrate", "-i", sgl_csv, "--mag", "mag_1_uc,mag_4_uc", "--model", cli_model, *flags)
    model = aeromag.calibrate_sensors(aeromag.read_flight(sgl_csv), ["mag_1_uc", "mag_4_uc"], **kwargs)
    py_model = tmp_path / "py.json"
    model.save(py_model)
    assert py_model.read_bytes() == cli_model.read_bytes()
    assert model.sensors == ["mag_1", "mag_4"] and model.columns == ["mag_1_uc", "mag_4_uc"]
    expected_ref = [None, "mag_1_uc"] if "reference_sensor" in kwargs else [None, None]
    assert model.reference_sensors == expected_ref
    assert len(model) == 2 and all(isinstance(m, aeromag.TlModel) for m in model.models)


def test_compensation_and_report_figures_equal_the_cli(cli, sgl_csv, tmp_path):
    m = tmp_path / "m.json"
    cli("calibrate", "-i", sgl_csv, "--mag", "mag_1_uc,mag_4_uc", "--extra", ",".join(CURRENTS), "--model", m)
    out = tmp_path / "comp.csv"
    cli("compensate", "-i", sgl_csv, "--model", m, "--out", out)
    cols = np.genfromtxt(out, delimiter=",", names=True, comments="#")
    flight = aeromag.read_flight(sgl_csv)
    model = aeromag.load_model(m)
    assert isinstance(model, aeromag.SensorsModel)
    comp = model.compensate(flight)
    assert set(comp) == {"mag_1_interf", "mag_1_comp", "mag_4_interf", "mag_4_comp", "mag_4_grad"}
    for name, values in comp.items():
        np.testing.assert_allclose(values, cols[name], rtol=0, atol=1e-9, err_msg=name)
    applied = model.apply(flight)
    np.testing.assert_array_equal(applied["mag_4_comp"], comp["mag_4_comp"])
    # The figures of `aeromag report`, from Python and from the CLI.
    fig = model.score(applied)
    cli("report", "-i", out, "--model", m, "--out", tmp_path / "rep")
    import json

    cli_fig = json.loads((tmp_path / "rep" / "figures.json").read_text())
    assert [s["sensor"] for s in fig["sensors"]] == ["mag_1", "mag_4"]
    for a, b in zip(fig["sensors"], cli_fig["sensors"]):
        assert a["figures"]["ir"] == pytest.approx(b["figures"]["ir"], rel=1e-9)
        assert a["groups"]["shares"] == pytest.approx(b["groups"]["shares"], rel=1e-9, abs=1e-12)
        assert [c["channel"] for c in a["currents"]] == [c["channel"] for c in b["currents"]]
        assert sum(a["groups"]["shares"]) == pytest.approx(1.0, abs=1e-9)


def test_bad_sensor_input_names_what_is_wrong(sgl_csv):
    flight = aeromag.read_flight(sgl_csv)
    with pytest.raises(aeromag.BadInputError, match="mag_9_uc"):
        aeromag.calibrate_sensors(flight, "mag_1_uc,mag_9_uc")
    with pytest.raises(aeromag.BadInputError, match="--vector"):
        aeromag.calibrate_sensors(flight, ["mag_1_uc", "mag_4_uc", "mag_5_uc"], vector=["flux_a", "flux_b"])
    with pytest.raises(aeromag.BadInputError, match="extra selection"):
        aeromag.calibrate_sensors(flight, ["mag_1_uc"], extra=CURRENTS, extra_selection="some")
    with pytest.raises(TypeError):
        aeromag.calibrate_sensors(flight, ["mag_1_uc"], no_such_option=1)


def test_another_sensors_units_are_checked_as_mags(sgl_csv):
    """A second sensor in µT, pT or T, or its vector magnetometer in T,
    was fitted without a word (the same column as the flight's `mag` was
    refused)."""
    d = aeromag.read_flight(sgl_csv).to_dict()

    def scaled(prefix, k):
        return aeromag.Flight.from_dict({c: v * k if c.startswith(prefix) else v for c, v in d.items()})

    for prefix, k, says in [
        ("mag_4_uc", 1e-3, "microtesla"),
        ("mag_4_uc", 1e3, "picotesla"),
        ("mag_4_uc", 1e-9, "tesla"),
        ("flux_d_", 1e-9, "tesla"),
    ]:
        with pytest.raises(aeromag.BadInputError, match=says):
            aeromag.calibrate_sensors(scaled(prefix, k), ["mag_1_uc", "mag_4_uc"], vector=["flux_a", "flux_d"])
