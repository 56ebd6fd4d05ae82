"""Gradiometer dipole estimation: the CLI's track and bound."""

import json
import warnings

import numpy as np
import pytest

import aeromag


def test_locate_equals_the_cli(cli, tmp_path):
    cli("simulate", "gradiometer", "--out", tmp_path / "g")
    csv = tmp_path / "g" / "gradiometer.csv"
    scenario = tmp_path / "g" / "gradiometer.toml"
    out = tmp_path / "est.csv"
    cli("dipole", "locate", "-i", csv, "--config", scenario, "--out", out)
    track = aeromag.locate_dipole(aeromag.read_flight(csv), config=scenario)
    written = aeromag.read_flight(out)
    assert track.columns == written.columns
    for c in track.columns:
        np.testing.assert_array_equal(track[c], written[c])
    # The pass simulated in memory is the file's.
    sim = aeromag.simulate_gradiometer(config=scenario)
    np.testing.assert_array_equal(sim["time"], aeromag.read_flight(csv)["time"])
    with pytest.raises(aeromag.BadInputError, match="layout"):
        aeromag.locate_dipole(sim, layout="triangle")


def test_crlb_equals_the_cli(cli):
    ref = json.loads(cli("dipole", "crlb", "--json").stdout)
    assert aeromag.dipole_crlb() == ref


def test_locate_warns_as_the_cli(cli, tmp_path):
    """The command's warnings reach Python as AeromagWarning: a sensor
    noise set 4 times the sensors' (the filter's innovations then far below
    1) and a gap in the pass; none on the clean pass. The object's track in
    km is bad input for the scalar gradiometer."""
    sim = aeromag.simulate_gradiometer()
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        aeromag.locate_dipole(sim)
    with pytest.warns(aeromag.AeromagWarning, match="normalised innovations") as caught:
        aeromag.locate_dipole(sim, noise_nt=2.0)
    assert len(caught) == 1 and caught[0].filename == __file__
    path = tmp_path / "pass.csv"
    sim.to_csv(str(path))
    r = cli("dipole", "locate", "-i", path, "--noise-nt", "2", "--out", tmp_path / "est.csv")
    assert str(caught[0].message) in r.stderr
    data = sim.to_dict()
    keep = np.r_[0:150, 200:len(sim)]
    gap = aeromag.Flight.from_dict({k: v[keep] for k, v in data.items()})
    with pytest.warns(aeromag.AeromagWarning, match="gap"):
        aeromag.locate_dipole(gap)
    # The scalar gradiometer takes the object's track as known positions.
    scalar = tmp_path / "scalar.toml"
    scalar.write_text('[system]\ngradiometer = "scalar"\n')
    data = aeromag.simulate_gradiometer(config=str(scalar)).to_dict()
    km = {k: (v / 1000.0 if k.startswith("obj_") and k.endswith("_m") else v) for k, v in data.items()}
    with pytest.raises(aeromag.BadInputError, match="inside the sphere") as e:
        aeromag.locate_dipole(aeromag.Flight.from_dict(km), config=str(scalar))
    assert e.value.column == "obj_north_m"
