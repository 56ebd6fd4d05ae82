"""Levelling, figures and observability: the CLI's numbers."""

import json

import numpy as np
import pytest

import aeromag


def test_level_equals_the_cli(cli, survey_csv, tmp_path):
    out, xs = tmp_path / "lev.csv", tmp_path / "xs.csv"
    p = cli("level", "-i", survey_csv, "--out", out, "--crossovers", xs)
    survey = aeromag.read_flight(survey_csv)
    lev = aeromag.level(survey)
    assert lev.value_column == "mag" and lev.output_column == "mag_level"
    written = aeromag.read_flight(out)
    np.testing.assert_array_equal(lev.levelled, written["mag_level"])
    np.testing.assert_array_equal(lev.flags, written["level_flag"])
    k, k_std = lev.k_s
    assert f"k (d|B0|/dt term) = {k:.4f} ± {k_std:.4f} s" in p.stdout
    table = lev.crossovers()
    cli_table = aeromag.read_flight(xs)
    assert table.columns == cli_table.columns and len(table) == len(cli_table) > 10
    assert lev.rms_nt["after"] <= lev.rms_nt["before"]
    labels = [l[0] for l in lev.line_levels]
    assert "1001" in labels
    full = lev.to_flight()
    np.testing.assert_array_equal(full["mag_level"], written["mag_level"])
    # Tie-line levelling: no k.
    tie = aeromag.level(survey, tie_only=True)
    assert tie.k_s[0] == 0.0
    # The repr says what was levelled into what, and how well.
    r = repr(lev)
    assert r.startswith("<aeromag.Levelled mag → mag_level: ") and r.endswith(" s>")
    assert f"{len(lev.line_levels)} lines, {len(table)} crossovers" in r
    assert f"RMS {lev.rms_nt['before']:.4f} → {lev.rms_nt['levelled']:.4f} nT" in r
    assert f"k {k:.4f} s" in r


def test_score_equals_the_report(cli, cal_csv, tmp_path):
    model = tmp_path / "m.json"
    cli("calibrate", "-i", cal_csv, "--model", model)
    comp = tmp_path / "comp.csv"
    cli("compensate", "-i", cal_csv, "--model", model, "--out", comp)
    rep = tmp_path / "rep"
    cli("report", "-i", comp, "--model", model, "--out", rep)
    ref = json.loads((rep / "figures.json").read_text())
    flight = aeromag.load_model(model).apply(aeromag.read_flight(cal_csv))
    fig = aeromag.score(flight)
    assert fig["fom_windows"] == ref["fom_windows"] > 0
    for k in ["fom_before_nt", "fom_after_nt", "ir", "residual_rms_nt", "interference_rms_nt"]:
        assert fig[k] == pytest.approx(ref[k], rel=1e-12, abs=1e-12), k
    assert fig["ir"] > 10


def test_observability_of_a_single_heading(cal):
    full = aeromag.observability(cal)
    assert full["rank"] == len(full["coefficients"]) == 16
    assert full["undetermined"] == []
    d = cal.to_dict()
    one = {k: v[(d["line"] == 1)] for k, v in d.items()}
    o = aeromag.observability(aeromag.Flight.from_dict(one))
    assert o["undetermined"], "one straight heading cannot determine every term"
    effect = {c["name"]: c["effect_std_nt"] for c in o["coefficients"]}
    effect_full = {c["name"]: c["effect_std_nt"] for c in full["coefficients"]}
    for name in o["undetermined"]:
        assert effect[name] > effect_full[name] and (effect[name] >= 1.0 or
                                                     next(c["mu"] for c in o["coefficients"] if c["name"] == name) > 0.9)


def test_tie_labels_given_as_text_are_labels_not_characters():
    # `ties="2001"` was split into the labels 2, 0, 0, 1.
    assert aeromag._labels("2001") == ["2001"]
    assert aeromag._labels("T1, T2") == ["T1", "T2"]
    assert aeromag._labels(2001) == ["2001"]
    assert aeromag._labels(["T1", 2]) == ["T1", "2"]
    assert aeromag._labels(None) is None
