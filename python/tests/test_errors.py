"""Bad input raises BadInputError (a ValueError) carrying file, line, row
and column; other failures are distinct."""

import numpy as np
import pytest

import aeromag


def test_bad_cell_names_file_line_row_column(tmp_path):
    p = tmp_path / "bad.csv"
    p.write_text("time,mag,line\n0,50000,1\n1,50000,1\n2,abc,1\n3,50000,1\n")
    with pytest.raises(aeromag.BadInputError) as e:
        aeromag.read_flight(p)
    err = e.value
    assert isinstance(err, ValueError) and isinstance(err, aeromag.AeromagError)
    assert err.file == str(p)
    assert (err.line, err.row, err.column) == (4, 2, "mag")


def test_rows_count_in_the_file_after_a_line_selection(tmp_path):
    p = tmp_path / "gap.csv"
    p.write_text("time,mag,line\n0,50000,1\n1,50000,1\n2,50000,2\n1.5,50000,2\n")
    with pytest.raises(aeromag.BadInputError) as e:
        aeromag.read_flight(p, lines=[2])
    assert (e.value.line, e.value.row, e.value.column) == (5, 3, "time")


def test_missing_file_and_bad_options(tmp_path):
    with pytest.raises(aeromag.BadInputError) as e:
        aeromag.read_flight(tmp_path / "none.csv")
    assert e.value.file.endswith("none.csv")
    cal = aeromag.simulate("calibration", seed=1)
    for bad in [
        dict(method="nosuch"),
        dict(terms="p4"),
        dict(band=(0.9, 0.1)),
        dict(ridge_lambda=-1.0),
        dict(field_order=3),  # needs method kalman
        dict(eddy_lag="soon"),
    ]:
        with pytest.raises(aeromag.BadInputError):
            aeromag.TollesLawson(**bad).fit(cal)
    with pytest.raises(ValueError, match="invalid parameter"):
        aeromag.TollesLawson().set_params(lambda_=1.0)


def test_missing_column_for_a_fit():
    cal = aeromag.simulate("calibration", seed=1)
    d = cal.to_dict()
    del d["flux_x"]
    with pytest.raises(aeromag.BadInputError) as e:
        aeromag.TollesLawson().fit(d)
    assert e.value.column == "flux_x"


def test_unwritable_output_is_oserror(tmp_path):
    tl = aeromag.TollesLawson(eddy_lag="none").fit(aeromag.simulate("calibration", seed=1))
    (tmp_path / "a_file").write_text("")
    with pytest.raises(OSError):
        tl.save(tmp_path / "a_file" / "m.json")
