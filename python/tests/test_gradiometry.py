"""Gradiometer dipole estimation: the CLI's track and bound."""

import json

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
