"""EM positioning: the Python chain writes the CLI's files, bit for bit,
and locates the bird where the simulator put it."""

import numpy as np
import pytest

import aeromag


@pytest.fixture(scope="module")
def record(tmp_path_factory):
    out = tmp_path_factory.mktemp("em")
    files = aeromag.simulate_em(str(out), seed=3)
    return out, files


def test_chain_equals_the_cli(cli, record, tmp_path):
    out, files = record
    assert files["epochs"] >= 8 and files["frames"] > 0
    # CLI chain.
    det_c, cal_c, pos_c = (tmp_path / n for n in ("det_cli.csv", "cal_cli.json", "poses_cli.csv"))
    cli("em", "detect", "-i", files["raw"], "--out", det_c)
    cli("em", "calibrate", "-i", det_c, "--known", files["known"], "--system", files["system"], "--out", cal_c)
    cli("em", "locate", "-i", det_c, "--calibration", cal_c, "--out", pos_c)
    # Python chain, from the objects.
    det = aeromag.detect_em(files["raw"])
    cal = aeromag.calibrate_em(det, files["known"], files["system"])
    calls = []
    poses = aeromag.locate_em(det, cal, progress=lambda *call: calls.append(call))
    # The progress callback was never called.
    assert ("locating", 0, len(poses)) in calls, calls
    det.save(str(tmp_path / "det.csv"))
    cal.save(str(tmp_path / "cal.json"))
    poses.save(str(tmp_path / "poses.csv"))
    for py, c in [("det.csv", det_c), ("cal.json", cal_c), ("poses.csv", pos_c)]:
        assert (tmp_path / py).read_bytes() == c.read_bytes(), py
    # … and from the CLI's files (paths in, same poses).
    again = aeromag.locate_em(det_c, cal_c)
    for k, v in poses.to_dict().items():
        np.testing.assert_array_equal(v, again.to_dict()[k])
    assert len(det) == len(poses) == files["epochs"]
    assert cal.polarization_ratio_after < cal.polarization_ratio_before
    assert poses.notes == []


def test_a_half_space_other_than_the_calibrations_is_warned_of(cli, record, tmp_path):
    out, files = record
    det = aeromag.detect_em(files["raw"])
    cal = aeromag.calibrate_em(det, files["known"], files["system"])
    # The birds trail behind and below (the default half-space's side):
    # located with the half-space ahead, every pose is mirrored to -r.
    poses = aeromag.locate_em(det, cal, half_space=(1.0, 0.0, 0.0))
    assert len(poses.notes) == 1 and poses.notes[0].startswith("warning: ")
    assert "--half-space=-1,0,1" in poses.notes[0] and "mirrored" in poses.notes[0]
    right = aeromag.locate_em(det, cal).to_dict()
    np.testing.assert_allclose(poses.to_dict()["x_m"], -right["x_m"], rtol=1e-9)
    # The CLI prints the same warning.
    cal.save(str(tmp_path / "cal.json"))
    det.save(str(tmp_path / "det.csv"))
    r = cli("em", "locate", "-i", tmp_path / "det.csv", "--calibration", tmp_path / "cal.json",
            "--half-space=1,0,0", "--out", tmp_path / "poses.csv")
    assert poses.notes[0] in r.stderr


def test_poses_match_the_truth(record):
    out, files = record
    det = aeromag.detect_em(files["raw"])
    cal = aeromag.calibrate_em(det, files["known"], files["system"])
    poses = aeromag.locate_em(det, cal).to_dict()
    # The half-space as any sequence of three numbers (a list was refused).
    for normal in ([-1.0, 0.0, 1.0], np.array([-1.0, 0.0, 1.0])):
        np.testing.assert_array_equal(aeromag.locate_em(det, cal, half_space=normal).to_dict()["x_m"], poses["x_m"])
    truth = aeromag.read_flight(files["truth"])
    assert poses["status"].sum() == 0
    np.testing.assert_allclose(poses["time_s"], truth["time_s"], atol=1e-9)
    err = np.sqrt(sum((poses[f"{a}_m"] - truth[f"true_{a}_m"]) ** 2 for a in "xyz"))
    rng = truth["true_range_m"]
    # The seed's positioning accuracy is a fraction of a percent of the range.
    assert np.median(err / rng) < 0.01, np.median(err / rng)


def test_bad_input(record, tmp_path):
    out, files = record
    # An empty folder name wrote the five files into the current folder.
    with pytest.raises(aeromag.BadInputError, match="output folder is empty"):
        aeromag.simulate_em("")
    with pytest.raises(aeromag.BadInputError, match="half-space"):
        aeromag.locate_em(files["raw"], files["raw"], half_space=(0.0, 0.0, 0.0))
    with pytest.raises(aeromag.BadInputError, match="window"):
        aeromag.detect_em(files["raw"], window="hann")
    bad = tmp_path / "bad.raw"
    bad.write_bytes(b"not a raw record")
    with pytest.raises(aeromag.BadInputError) as e:
        aeromag.detect_em(bad)
    assert e.value.file is not None and "bad.raw" in e.value.file
