"""The online compensator from Python (issue 21): push one sample or a
block, the same values as `compensate(causal=True)` and as the CLI's
`compensate --causal`, bit for bit."""

import numpy as np
import pytest

import aeromag


@pytest.fixture(scope="module")
def model(cal):
    return aeromag.TollesLawson().fit(cal).model_


def test_push_and_push_block_equal_the_causal_batch(model, survey_csv):
    survey = aeromag.read_flight(survey_csv)
    batch = model.compensate(survey, causal=True)
    cols = [survey[c] for c in ("time", "flux_x", "flux_y", "flux_z", "mag")]
    n = 3000
    one = model.online()
    by_sample = np.array([one.push(t, (x, y, z), m)[1] for t, x, y, z, m in zip(*(c[:n] for c in cols))])
    assert by_sample.tobytes() == batch[:n].tobytes()
    # The rest in two blocks, continuing the same state.
    block = aeromag.OnlineCompensator(model)
    out = [block.push_block(*(c[:n] for c in cols))]
    out.append(block.push_block(*(c[n:] for c in cols)))
    comp = np.concatenate([o["mag_comp"] for o in out])
    assert comp.tobytes() == batch.tobytes()
    flags = np.concatenate([o["comp_flag"] for o in out])
    assert flags[0] == 2 and (flags[1:] == 0).all()
    # A strided view, lists and a column of integers are arrays of numbers
    # ("not contiguous", "cannot be converted to 'PyArray<T, D>'" before).
    wide = np.zeros((n, 2))
    wide[:, 0] = cols[0][:n]
    again = aeromag.OnlineCompensator(model).push_block(
        wide[:, 0], *(list(c[:n]) for c in cols[1:4]), np.round(cols[4][:n]).astype(np.int64)
    )
    want = aeromag.OnlineCompensator(model).push_block(cols[0][:n], *(c[:n] for c in cols[1:4]), np.round(cols[4][:n]))
    assert again["mag_comp"].tobytes() == want["mag_comp"].tobytes()
    with pytest.raises(TypeError, match="^mag must be an array of real numbers"):
        block.push_block(*(c[:3] for c in cols[:4]), cols[4][:3] + 0j)
    with pytest.raises(TypeError, match="^flux_y must be one-dimensional"):
        block.push_block(cols[0][:3], cols[1][:3], np.zeros((3, 2)), cols[3][:3], cols[4][:3])
    # The causal convention costs almost nothing against the batch path.
    line = survey["line"] > 0
    truth = survey["true_external"]
    rms = lambda c: float(np.std((c - truth)[line]))
    assert rms(batch) <= 1.05 * rms(model.compensate(survey))


def test_flags_and_bad_arguments(model, survey_csv, cli, tmp_path):
    oc = model.online()
    assert oc.channels == [] and oc.max_step_s == pytest.approx(0.15, rel=1e-6)
    b = (20_000.0, 1_000.0, 45_000.0)
    assert oc.push(0.0, b, 49_300.0)[2] == 2
    assert oc.push(0.1, b, 49_300.0)[2] == 0
    assert oc.push(0.05, b, 49_300.0)[2] == 3
    i, c, f = oc.push(0.2, b, float("nan"))
    assert f == 1 and np.isnan(i) and np.isnan(c)
    assert oc.push(5.0, b, 49_300.0)[2] == 2
    # A dropout value or a reading in tesla is no reading: not compensated
    # (a mag of 0 was compensated to about 20 nT and flagged 0).
    for t, flux, mag in [(5.1, b, 0.0), (5.2, b, 4.93e-5), (5.3, tuple(v * 1e-9 for v in b), 49_300.0)]:
        i, c, f = oc.push(t, flux, mag)
        assert f == 1 and np.isnan(c), (t, i, c, f)
    assert oc.push(5.4, b, 49_300.0)[2] == 2
    with pytest.raises(aeromag.BadInputError, match="channels"):
        oc.push(6.0, b, 49_300.0, [1.0])
    with pytest.raises(aeromag.BadInputError, match="one length"):
        oc.push_block(np.zeros(3), np.zeros(3), np.zeros(3), np.zeros(2), np.zeros(3))
    with pytest.raises(aeromag.BadInputError, match="causal"):
        model.compensate(aeromag.read_flight(survey_csv), sample_rate=10.0)


def test_python_and_cli_give_the_same_causal_values(model, survey_csv, cli, tmp_path):
    path = tmp_path / "m.json"
    model.save(path)
    out = tmp_path / "causal.csv"
    cli("compensate", "--causal", "--model", path, "-i", survey_csv, "--out", out)
    written = aeromag.read_flight(out)
    py = model.compensate(aeromag.read_flight(survey_csv), causal=True)
    assert written["mag_comp"].tobytes() == py.tobytes()


def test_adaptive_push_block_equals_push_and_the_cli(model, survey_csv, cli, tmp_path):
    """`adapt="kalman"`: one sample at a time and in blocks give the same
    values, which are the CLI's `stream --adapt kalman`; the coefficients
    come with their standard deviations."""
    survey = aeromag.read_flight(survey_csv)
    n = 2000
    cols = [survey[c][:n] for c in ("time", "flux_x", "flux_y", "flux_z", "mag")]
    speed = np.hypot(survey["vn"][:n], survey["ve"][:n])
    alt = survey["alt"][:n]
    one = aeromag.OnlineCompensator(model, adapt="kalman")
    assert one.coefficients is not None
    by_sample = np.array(
        [one.push(t, (x, y, z), m, speed=v, alt=a)[0] for (t, x, y, z, m), v, a in zip(zip(*cols), speed, alt)]
    )
    block = model.online(adapt="kalman")
    out = [block.push_block(*(c[:700] for c in cols), speed=speed[:700], alt=alt[:700])]
    out.append(block.push_block(*(c[700:] for c in cols), speed=speed[700:], alt=alt[700:]))
    interf = np.concatenate([o["mag_interf"] for o in out])
    assert interf.tobytes() == by_sample.tobytes()
    coef = block.coefficients
    assert coef["name"][0] == "p_x" and len(coef["value"]) == len(coef["std"])
    assert coef["value"] == one.coefficients["value"]
    assert all(s > 0 for s in coef["std"])
    # The fixed model's values differ: the coefficients moved.
    fixed = model.online().push_block(*cols)["mag_interf"]
    assert not np.array_equal(fixed, interf)
    # The CLI on the same lines.
    path = tmp_path / "m.json"
    model.save(path)
    lines = [l for l in open(survey_csv) if not l.startswith("#")][: n + 1]
    r = cli("stream", "--model", path, "--adapt", "kalman", input="".join(lines))
    got = np.array([float(l.rsplit(",", 3)[1]) for l in r.stdout.splitlines()[1:]])
    assert got.tobytes() == by_sample.tobytes()
    with pytest.raises(aeromag.BadInputError, match="adaptation"):
        aeromag.OnlineCompensator(model, adapt="lms")
