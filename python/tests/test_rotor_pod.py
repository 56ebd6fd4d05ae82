"""Rotor and pod models: the CLI's model files, applied like the CLI."""

import warnings

import numpy as np
import pytest

import aeromag
from conftest import ROOT


def test_rotor_model_equals_the_cli(cli, tmp_path):
    cli("simulate", "helicopter", "--seed", 11, "--out", tmp_path / "h")
    csv = tmp_path / "h" / "helicopter.csv"
    model = tmp_path / "rotor.json"
    cli("rotor", "fit", "-i", csv, "--preset", "aeromag-sim-helicopter", "--model", model)
    flight = aeromag.read_flight(csv)
    stages = []
    m = aeromag.fit_rotor(flight, preset="aeromag-sim-helicopter",
                          progress=lambda stage, done, total: stages.append(stage))
    assert m.kind == "helicopter-rotor"
    # The progress callback was never called.
    assert "fitting the rotor model" in stages, stages
    m.save(tmp_path / "py.json")
    assert (tmp_path / "py.json").read_bytes() == model.read_bytes()
    loaded = aeromag.load_model(model)
    assert isinstance(loaded, aeromag.Model)
    out = tmp_path / "out.csv"
    cli("rotor", "apply", "--model", model, "-i", csv, "--out", out)
    written = aeromag.read_flight(out)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        np.testing.assert_array_equal(loaded.apply(flight)["mag_comp"], written["mag_comp"])
    # Applied to a flight with a spike in mag: the CLI's warning, as an
    # AeromagWarning (none on the clean flight above).
    data = flight.to_dict()
    data["mag"][5000] += 1000.0
    spiked = aeromag.Flight.from_dict(data)
    for call in (loaded.apply, loaded.compensate, loaded.interference):
        with pytest.warns(aeromag.AeromagWarning, match="spikes") as caught:
            call(spiked)
        assert len(caught) == 1 and caught[0].filename == __file__
    r = cli("rotor", "apply", "--model", model, "-i", csv, "--out", out)
    assert "warning" not in r.stderr
    with pytest.raises(aeromag.BadInputError, match="preset"):
        aeromag.fit_rotor(flight, hub_m=(0, 0, -2.6))
    with pytest.raises(aeromag.BadInputError, match="tail rotor"):
        aeromag.fit_rotor(flight, preset="aeromag-sim-helicopter", gear_ratio=4.0)
    with pytest.raises(aeromag.BadInputError, match="phase channel"):
        aeromag.fit_rotor(flight, preset="aeromag-sim-helicopter", tail_rotor=True,
                          estimate_phase=True)


def test_pod_model_equals_the_cli(cli, tmp_path):
    cli("simulate", "pod", "--seed", 1, "--out", tmp_path / "p")
    csv = tmp_path / "p" / "pod.csv"
    model = tmp_path / "pod.json"
    setup = dict(cable_length_m=40.0, attach_m=(0, 0, 1.2), inclination_deg=45.0,
                 grad_north_nt_per_km=5.91, grad_up_nt_per_km=-25.91)
    cli("pod", "fit", "-i", csv, "--model", model, "--cable-length-m", 40, "--attach-m", "0,0,1.2",
        "--inclination-deg", 45, "--grad-north-nt-per-km", 5.91, "--grad-up-nt-per-km", -25.91)
    flight = aeromag.read_flight(csv)
    stages = []
    m = aeromag.fit_pod(flight, **setup, progress=lambda stage, done, total: stages.append(stage))
    assert m.to_json() == model.read_text()
    assert "fitting the pod model" in stages, stages
    rates = m.heading_rates(flight)
    assert rates and all(r[3] > 0.9 for r in rates)
    assert np.all(np.isfinite(m.interference(flight)))
