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
        dict(method="kalman", band=(0.2, 0.5)),  # was ignored: the Kalman method does not filter
    ]:
        with pytest.raises(aeromag.BadInputError):
            aeromag.TollesLawson(**bad).fit(cal)
    with pytest.raises(ValueError, match="invalid parameter"):
        aeromag.TollesLawson().set_params(lambda_=1.0)


def test_missing_files_are_file_not_found_errors(tmp_path):
    """A missing input is a BadInputError and a FileNotFoundError naming
    it, whatever kind of file it is (a flight, model, grid or scenario)."""
    missing = [
        lambda p: aeromag.read_flight(p / "none.csv"),
        lambda p: aeromag.load_model(p / "none.json"),
        lambda p: aeromag.read_grid(p / "none.asc"),
        lambda p: aeromag.read_grid(p / "none.tif"),
        lambda p: aeromag.simulate("calibration", config=p / "none.toml"),
        lambda p: aeromag.dipole_crlb(p / "none.toml"),
    ]
    for call in missing:
        with pytest.raises(FileNotFoundError) as e:
            call(tmp_path)
        err = e.value
        assert isinstance(err, aeromag.MissingFileError) and isinstance(err, aeromag.BadInputError)
        assert err.filename == err.file and err.file.startswith(str(tmp_path)), err.file
        assert err.errno == 2 and str(err).startswith(("cannot", "reading", "config: no file")), str(err)


def test_settings_files_name_file_and_line(tmp_path):
    """Model, scenario and gradiometer files give their name and the line
    of a syntax or type error (they gave neither as attributes)."""
    model = tmp_path / "bad.json"
    model.write_text('{\n  "format": "aeromag-model/2",\n  "kind": ,\n}\n')
    with pytest.raises(aeromag.BadInputError) as e:
        aeromag.load_model(model)
    assert (e.value.file, e.value.line) == (str(model), 3), (e.value.file, e.value.line)
    scenario = tmp_path / "bad.toml"
    scenario.write_text('seed = 1\n\n[scalar]\nlag_s = "x"\n')
    with pytest.raises(aeromag.BadInputError) as e:
        aeromag.simulate("calibration", config=scenario)
    assert (e.value.file, e.value.line) == (str(scenario), 4), str(e.value)
    assert str(e.value).startswith(f"'{scenario}': scenario file: TOML parse error at line 4")
    # Text given directly has no file, but still the line.
    with pytest.raises(aeromag.BadInputError) as e:
        aeromag.simulate("calibration", config='seed = 1\n[scalar\n')
    assert (e.value.file, e.value.line) == (None, 2)
    gradiometer = tmp_path / "grad.toml"
    gradiometer.write_text("seed = 3\n[system]\nbaseline_m = [1\n")
    with pytest.raises(aeromag.BadInputError) as e:
        aeromag.dipole_crlb(gradiometer)
    assert (e.value.file, e.value.line) == (str(gradiometer), 3), str(e.value)
    grid = tmp_path / "bad.asc"
    grid.write_text("ncols 2\nnrows x\n")
    with pytest.raises(aeromag.BadInputError) as e:
        aeromag.read_grid(grid)
    assert e.value.file == str(grid)
    with pytest.raises(aeromag.BadInputError) as e:
        aeromag.read_grid(tmp_path / "g.xyz")
    assert e.value.file == str(tmp_path / "g.xyz")


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
    with pytest.raises(NotADirectoryError) as e:
        tl.save(tmp_path / "a_file" / "m.json")
    # As open() raises it: errno, filename, the system's reason.
    assert e.value.errno == 20 and e.value.filename.endswith("m.json"), repr(e.value)
    assert str(e.value).startswith("[Errno 20] Not a directory: "), str(e.value)
    # A flight's CSV and a grid file raised AeromagError for the same path.
    cal = aeromag.simulate("calibration", seed=1)
    with pytest.raises(OSError):
        cal.to_csv(tmp_path / "a_file" / "f.csv")
    with pytest.raises(OSError):
        cal.to_csv(tmp_path)
    grid = aeromag.grid_flight(aeromag.simulate("survey", seed=1), cell=200.0, max_sweeps=5)
    for name in ["g.tif", "g.nc", "g.asc"]:
        with pytest.raises(OSError):
            grid.write(tmp_path / "a_file" / name)


def test_arguments_are_named_in_their_errors(tmp_path):
    """Found by fuzzing the API: errors that named no argument, named the
    CLI's option, or misread the argument."""
    cal = aeromag.simulate("calibration", seed=1)
    # A negative count was PyO3's "can't convert negative int to unsigned".
    for call, name in [
        (lambda: aeromag.simulate("calibration", seed=-1), "seed"),
        (lambda: aeromag.grid_flight(cal, max_sweeps=-1), "max_sweeps"),
        (lambda: aeromag.TollesLawson(method="kalman", field_order=-1).fit(cal), "field_order"),
        (lambda: aeromag.simulate_em(str(tmp_path / "em"), known_positions=-1), "known_positions"),
        (lambda: aeromag.simulate_gradiometer(seed=-2), "seed"),
    ]:
        with pytest.raises(aeromag.BadInputError, match=f"{name} must not be negative, got -"):
            call()
    with pytest.raises(TypeError, match="seed must be a whole number, got 1.5"):
        aeromag.simulate("calibration", seed=1.5)
    with pytest.raises(aeromag.BadInputError, match="seed: 18446744073709551616 is too large"):
        aeromag.simulate("calibration", seed=2**64)
    # NumPy's integers are whole numbers.
    assert np.array_equal(aeromag.simulate("calibration", seed=np.int64(1)).to_dict()["mag"], cal.to_dict()["mag"])
    # A path that names no file was parsed as TOML text.
    with pytest.raises(aeromag.BadInputError, match="config: no file '/nonexistent/my.toml'"):
        aeromag.simulate("calibration", config="/nonexistent/my.toml")
    # A NaN lever arm was "longer than 1000 m".
    with pytest.raises(aeromag.BadInputError, match="finite number of metres"):
        aeromag.TollesLawson(lever_arm=(float("nan"), 0, 0)).fit(cal)
    # The row selection said "--lines: '' has an empty label".
    with pytest.raises(aeromag.BadInputError, match="lines: an empty list selects no line"):
        aeromag.Flight.from_dict({"time": [0.0, 1.0], "line": [1.0, 1.0]}, lines=[])
    with pytest.raises(aeromag.BadInputError, match=" lines: no row has the line label '7'") as e:
        aeromag.Flight.from_dict({"time": [0.0, 1.0], "line": [1.0, 1.0]}, lines=[7])
    assert "--" not in str(e.value)
    with pytest.raises(aeromag.BadInputError, match="^time_range: start 2 is after end 1"):
        aeromag.Flight.from_dict({"time": [0.0, 1.0]}, time_range=(2.0, 1.0))
    # A TIFF header and junk: "failed to fill whole buffer".
    junk = tmp_path / "g.tif"
    junk.write_bytes(b"II*\x00junk")
    with pytest.raises(aeromag.BadInputError, match="truncated or damaged"):
        aeromag.read_grid(junk)


def test_a_flag_of_the_wrong_type_names_the_option():
    # Was "'str' object is not an instance of 'bool'", naming no option.
    cal = aeromag.simulate("calibration", seed=1)
    for name in ("tune", "no_tune", "series", "no_split_lines"):
        with pytest.raises(TypeError, match=f"^{name} must be True or False, got 'yes'$"):
            aeromag.TollesLawson(**{name: "yes"}).fit(cal)


def test_a_flight_argument_of_the_wrong_type_names_it():
    # Was "'str' object is not an instance of 'Flight'": PyO3 names the
    # argument only in a note, which str(e) leaves out.
    cal = aeromag.simulate("calibration", seed=1)
    tl = aeromag.TollesLawson().fit(cal)
    calls = [
        lambda: aeromag._aeromag.calibrate("x", {}),
        lambda: tl.model_.compensate("x"),
        lambda: tl.model_.interference("x"),
        lambda: tl.model_.apply("x"),
        lambda: aeromag.grid_flight("x"),
        lambda: aeromag.level("x"),
        lambda: aeromag.microlevel("x"),
        lambda: aeromag.score("x"),
        lambda: tl.fit("x"),
        lambda: tl.transform("x"),
    ]
    for call in calls:
        with pytest.raises(TypeError) as e:
            call()
        assert str(e.value).startswith("flight must be an aeromag.Flight")
        assert str(e.value).endswith(", got str")


def test_dir_shows_the_api_not_the_imports():
    names = dir(aeromag)
    assert "read_flight" in names and "MissingFileError" in names and "errors" in names
    assert not {"np", "os", "Optional", "annotations"} & set(names)
