"""Reading flights, building them from arrays and DataFrames."""

import pathlib

import numpy as np
import pytest

import aeromag
from conftest import ROOT

HDF5 = ROOT / "crates" / "io" / "tests" / "data" / "hdf5"


def test_read_csv_columns_and_arrays(cal, cal_csv):
    assert len(cal) > 1000
    assert cal.file == str(cal_csv)
    for c in ["time", "mag", "flux_x", "line", "true_interf"]:
        assert c in cal.columns and c in cal
    mag = cal["mag"]
    assert isinstance(mag, np.ndarray) and mag.dtype == np.float64 and mag.shape == (len(cal),)
    # A new array each time: changing it does not change the flight.
    mag[0] = 0.0
    assert cal["mag"][0] != 0.0
    with pytest.raises(KeyError, match="no column 'nosuch'"):
        cal["nosuch"]


def test_hdf5_sgl_layout_with_sensor_and_line_choice():
    path = HDF5 / "root_gzip.h5"
    f = aeromag.read_flight(path)
    # SGL names mapped onto canonical ones; lat derived from ins_lat (rad).
    assert dict(f.mapping)["mag"] == "mag_1_uc"
    assert np.array_equal(f["mag"], f["mag_1_uc"])
    g = aeromag.read_flight(path, mag="mag_2_uc", lines=[1001])
    assert dict(g.mapping)["mag"] == "mag_2_uc"
    assert 0 < len(g) < len(f)
    assert np.all(g["line"] == 1001)
    # The same selection as text, as the CLI's --lines.
    assert len(aeromag.read_flight(path, lines="1001")) == len(g)


def test_only_the_fields_asked_for(cal_csv):
    # A CSV: the fields named, a canonical one through its derivation or
    # alias, the others listed as not read; the same values as a whole read.
    whole = aeromag.read_flight(cal_csv)
    f = aeromag.read_flight(cal_csv, fields=["time", "MAG", "true_*"])
    assert f.columns == [c for c in whole.columns if c in ("time", "mag") or c.startswith("true_")]
    assert "flux_x" in f.unread_columns and "mag" not in f.unread_columns
    assert whole.unread_columns == []
    for c in f.columns:
        assert np.array_equal(f[c], whole[c], equal_nan=True)
    assert len(aeromag.read_flight(cal_csv, fields="mag").columns) == 1
    with pytest.raises(aeromag.BadInputError, match="flux_x"):
        aeromag.TollesLawson(terms="p3").fit(aeromag.read_flight(cal_csv, fields="mag"))
    # An HDF5 file: only those datasets.
    path = HDF5 / "root_gzip.h5"
    g = aeromag.read_flight(path, fields=["mag", "lat"])
    assert sorted(g.columns) == ["ins_lat", "lat", "mag_1_uc"]
    assert "mag_2_uc" in g.unread_columns


def test_line_labels_of_one_number_in_two_texts_stay_two_lines(tmp_path):
    # Geosoft's LINE.VERSION: 1003.1 and 1003.10 are two lines, read as
    # written; without such a pair the labels stay numbers.
    p = tmp_path / "versions.csv"
    p.write_text("time,line\n0,1003.1\n1,1003.1\n2,0\n3,1003.10\n")
    f = aeromag.read_flight(p)
    assert list(f["line"]) == ["1003.1", "1003.1", "0", "1003.10"]
    assert len(aeromag.read_flight(p, lines="1003.10")) == 1
    p.write_text("time,line\n0,1003.1\n1,1003.2\n")
    assert aeromag.read_flight(p)["line"].dtype == np.float64


def test_time_range_and_column_map(cal_csv, tmp_path):
    f = aeromag.read_flight(cal_csv)
    t0 = f["time"][0]
    g = aeromag.read_flight(cal_csv, time_range=(t0, t0 + 10.0))
    assert np.all((g["time"] >= t0) & (g["time"] <= t0 + 10.0)) and len(g) > 10
    p = tmp_path / "my.csv"
    p.write_text("time,my_mag\n" + "".join(f"{float(t)!r},{float(m)!r}\n" for t, m in zip(f["time"][:50], f["mag"][:50])))
    h = aeromag.read_flight(p, columns={"mag": "my_mag"})
    assert np.array_equal(h["mag"], f["mag"][:50])
    # Truth never plays a measured role.
    with pytest.raises(aeromag.BadInputError, match="simulation truth"):
        aeromag.read_flight(cal_csv, columns={"mag": "true_interf"})


def test_from_dict_maps_file_names_and_checks():
    n = 200
    t = np.arange(n) * 0.1
    data = {
        "tt": t,
        "ins_lat": np.full(n, np.radians(45.0)),
        "ins_lon": np.full(n, np.radians(10.0)),
        "mag_1_uc": np.full(n, 50000.0),
        "line": np.where(t < 10, 1001.0, 1002.0),
    }
    f = aeromag.Flight.from_dict(data)
    assert f.file is None and len(f) == n
    # The SGL preset: time from tt, lat/lon in degrees from radians; the
    # conversion works on a copy, never on the caller's array.
    assert np.allclose(f["time"], t) and np.allclose(f["lat"], 45.0)
    assert np.allclose(data["ins_lat"], np.radians(45.0))
    # The arrays are copied: a change to the caller's array afterwards does
    # not reach the flight, whose checks were made on what it holds (found
    # by fuzzing: time edited to run backwards after the flight was built
    # made level panic and microlevel hang).
    data["mag_1_uc"][3] = 50001.0
    data["tt"][5] = -1.0
    assert f["mag"][3] == 50000.0 and f["time"][5] == 0.5
    data["tt"][5] = 0.5
    # copy=False reads float64 arrays in place (large flights): the flight
    # sees the change.
    h = aeromag.Flight.from_dict(data, copy=False)
    data["mag_1_uc"][3] = 50002.0
    assert h["mag"][3] == 50002.0
    data["mag_1_uc"][3] = 50000.0
    g = aeromag.Flight.from_dict(data, lines=[1002])
    assert len(g) == 100
    # Time going backwards is bad input naming the row.
    bad = dict(data, tt=t[::-1].copy())
    with pytest.raises(aeromag.BadInputError) as e:
        aeromag.Flight.from_dict(bad)
    assert e.value.column == "tt" or e.value.column == "time"
    assert e.value.row == 1
    with pytest.raises(aeromag.BadInputError):
        aeromag.Flight.from_dict({"a": np.zeros(3), "b": np.zeros(4)})


def test_from_dict_numbers_with_none_masks_and_text():
    n = 50
    t = np.arange(n) * 0.1
    mag = np.full(n, 50000.0)
    # Numbers with None (an object array, as pandas gives them): numbers,
    # None missing; it became the text "None" and the flight was built.
    with_none = [50000.0] * n
    with_none[7] = None
    f = aeromag.Flight.from_dict({"time": t, "mag": np.array(with_none, dtype=object)})
    assert np.isnan(f["mag"][7]) and f["mag"][8] == 50000.0
    # A masked array's masked values are missing (the mask was dropped).
    m = np.ma.masked_array(mag, mask=np.arange(n) == 3)
    f = aeromag.Flight.from_dict({"time": t, "mag": m})
    assert np.isnan(f["mag"][3]) and f["mag"][4] == 50000.0
    # A number column given as text is bad input at once, naming it.
    with pytest.raises(aeromag.BadInputError) as e:
        aeromag.Flight.from_dict({"time": t.astype(str), "mag": mag})
    assert "'time'" in str(e.value) and "text" in str(e.value)
    with pytest.raises(aeromag.BadInputError) as e:
        aeromag.Flight.from_dict({"time": t, "mag": np.array(["50000"] * (n - 1) + ["x"])})
    assert "'mag'" in str(e.value) and "row 49" in str(e.value)
    # Text line labels stay text, None an empty (missing) label.
    labels = np.array(["L1"] * (n - 1) + [None], dtype=object)
    f = aeromag.Flight.from_dict({"time": t, "mag": mag, "line": labels})
    assert f["line"][0] == "L1"
    with pytest.raises(TypeError):
        aeromag.Flight.from_pandas(3)


def test_pandas_round_trip(cal):
    pd = pytest.importorskip("pandas")
    df = cal.to_pandas()
    assert isinstance(df, pd.DataFrame) and df.shape == (len(cal), len(cal.columns))
    back = aeromag.Flight.from_pandas(df)
    assert back.columns == cal.columns
    for c in cal.columns:
        np.testing.assert_array_equal(back[c], cal[c])
    # Text columns (line labels) stay text.
    df["line"] = ["L" + str(int(x)) for x in df["line"]]
    f = aeromag.Flight.from_pandas(df)
    assert f["line"][0].startswith("L")


def test_polars_when_installed(cal):
    pl = pytest.importorskip("polars")
    df = cal.to_polars()
    assert df.height == len(cal)


def test_simulate_with_config_and_truth():
    f = aeromag.simulate("calibration", seed=3)
    assert "true_interf" in f.columns
    g = aeromag.simulate("calibration", seed=3)
    np.testing.assert_array_equal(f["mag"], g["mag"])  # seeded: identical
    with pytest.raises(aeromag.BadInputError, match="unknown scenario"):
        aeromag.simulate("nosuch")


def test_a_field_asked_for_that_the_file_lacks_is_bad_input(cal_csv):
    # A typo gave a flight of `time` alone, without a word.
    with pytest.raises(aeromag.BadInputError) as e:
        aeromag.read_flight(cal_csv, fields=["mag", "nosuch"])
    assert "nosuch" in str(e.value)
    f = aeromag.read_flight(cal_csv, fields=["MAG"])
    assert "mag" in f.columns


def test_to_xyz_reads_back_to_the_same_flight(tmp_path):
    """Geosoft XYZ out (as ``--out X.xyz``) and in again: the same columns
    and bits; a text cell with a space is refused naming column and row."""
    cal = aeromag.simulate("calibration", seed=2)
    cal.to_xyz(tmp_path / "c.xyz")
    assert (tmp_path / "c.xyz").read_text().startswith("/ XYZ export of aeromag ")
    back = aeromag.read_flight(tmp_path / "c.xyz")
    assert back.columns == cal.columns
    for name in cal.columns:
        np.testing.assert_array_equal(back[name], cal[name])
    spaced = aeromag.Flight.from_dict({"time": [0.0, 1.0], "mag": [5e4, 5e4], "note": ["ok", "two words"]})
    with pytest.raises(aeromag.BadInputError) as e:
        spaced.to_xyz(tmp_path / "s.xyz")
    assert (e.value.column, e.value.row) == ("note", 1)
    assert not (tmp_path / "s.xyz").exists()


def test_to_hdf5_reads_back_in_h5py_and_here(tmp_path):
    """HDF5 out (as ``--out X.h5``): h5py (the HDF5 C library) reads one
    dataset per column with the flight's bits, integers as int64 and text
    as UTF-8 strings, and so does read_flight; a name with '/' is refused."""
    h5py = pytest.importorskip("h5py")
    cal = aeromag.simulate("calibration", seed=2)
    flight = aeromag.Flight.from_dict({**cal.to_dict(), "label": ["L1020 é"] * (len(cal) - 1) + [""]})
    flight.to_hdf5(tmp_path / "c.h5")
    with h5py.File(tmp_path / "c.h5", "r") as h:
        assert sorted(h.keys()) == sorted(flight.columns)
        for name in cal.columns:
            assert h[name].shape == (len(cal),) and h[name].dtype == np.float64
            assert h[name][:].tobytes() == np.asarray(cal[name]).tobytes(), name
        labels = [b.decode() for b in h["label"][:]]
        assert labels == list(flight["label"])
    back = aeromag.read_flight(tmp_path / "c.h5")
    assert back.columns == flight.columns
    for name in cal.columns:
        assert np.asarray(back[name]).tobytes() == np.asarray(cal[name]).tobytes(), name
    assert list(back["label"]) == list(flight["label"])
    # A compensated flight's flag column is written as integers.
    applied = aeromag.TollesLawson().fit(cal).model_.apply(cal)
    applied.to_hdf5(tmp_path / "a.h5")
    with h5py.File(tmp_path / "a.h5", "r") as h:
        assert h["comp_flag"].dtype == np.int64
        assert (h["comp_flag"][:] == applied["comp_flag"]).all()
        assert h["mag_comp"][:].tobytes() == np.asarray(applied["mag_comp"]).tobytes()
    slash = aeromag.Flight.from_dict({"time": [0.0, 1.0], "a/b": [1.0, 2.0]})
    with pytest.raises(aeromag.BadInputError) as e:
        slash.to_hdf5(tmp_path / "s.h5")
    assert e.value.column == "a/b" and not (tmp_path / "s.h5").exists()


def test_text_datasets_written_by_h5py_are_text_columns(tmp_path):
    """Line labels as strings in an HDF5 flight (variable-length, as h5py
    writes Python str, or fixed-length bytes) are read as text columns."""
    h5py = pytest.importorskip("h5py")
    with h5py.File(tmp_path / "t.h5", "w") as h:
        h["tt"] = np.arange(4) * 0.1
        h["mag_1_uc"] = np.full(4, 5.0e4)
        h.create_dataset("line", data=["L1", "L1", "T2", ""], dtype=h5py.string_dtype())
        h["code"] = np.array([b"a", b"bb", b"", b"c"], dtype="S2")
    f = aeromag.read_flight(tmp_path / "t.h5")
    assert list(f["line"]) == ["L1", "L1", "T2", ""]
    assert list(f["code"]) == ["a", "bb", "", "c"]
    assert np.asarray(f["mag"]).tolist() == [5.0e4] * 4


def test_matlab_mat_files(tmp_path):
    """A MATLAB v7.3 MAT-file (HDF5 after a 512-byte user block; vectors as
    1 x n matrices, text as uint16 'char') reads as a flight; a v5 one is
    read too (tests/test_flight.py::test_matlab_v5_mat_files)."""
    h5py = pytest.importorskip("h5py")
    path = tmp_path / "flight.mat"
    n = 50
    with h5py.File(path, "w", userblock_size=512) as h:
        for name, values in [("tt", np.arange(n) * 0.1), ("mag_1_uc", 5.0e4 + np.arange(n)),
                             ("lat", np.full(n, 45.0)), ("lon", np.full(n, -75.0))]:
            h[name] = values.reshape(1, n) if name != "lat" else values.reshape(n, 1)
            h[name].attrs["MATLAB_class"] = np.bytes_("double")
        h["note"] = np.frombuffer("survey".encode("utf-16-le"), "<u2").reshape(6, 1)
        h["note"].attrs["MATLAB_class"] = np.bytes_("char")
    with open(path, "r+b") as f:
        f.write(b"MATLAB 7.3 MAT-file, Platform: GLNXA64".ljust(116) + b"\0" * 8 + b"\x00\x02IM")
    f = aeromag.read_flight(path)
    assert len(f) == n and "note" not in f.columns
    assert np.asarray(f["mag"]).tolist() == (5.0e4 + np.arange(n)).tolist()
    assert np.asarray(f["lat"]).tolist() == [45.0] * n


MAT5 = pathlib.Path(__file__).resolve().parents[2] / "crates" / "io" / "tests" / "data" / "mat5"


def test_matlab_v5_mat_files():
    """A MATLAB v5 MAT-file (tools/reference/mat5_flights.py): MagNav.jl's
    compressed traj and ins_data structs read as its HDF5 names, what is
    not a field listed in not_read; a file without a flight refused."""
    f = aeromag.read_flight(MAT5 / "magnav.mat")
    assert f.columns[:4] == ["ins_tt", "ins_lat", "ins_lon", "ins_roll"]
    k = np.arange(50.0)
    assert np.asarray(f["mag"]).tolist() == (50_000.0 + 0.125 * k).tolist()
    assert np.asarray(f["ins_lat"]).tolist() == (45.0 + k * 1e-4).tolist()
    assert f.not_read == [("traj.Cnb", "a 3 × 3 × 50 matrix"), ("traj.fileName", "text (1 × 7)")]
    only = aeromag.read_flight(MAT5 / "magnav.mat", fields="mag")
    assert only.columns == ["mag_1_uc"]
    with pytest.raises(aeromag.BadInputError, match=r"2 structs \(a, b\)"):
        aeromag.read_flight(MAT5 / "two_structs.mat")
    with pytest.raises(aeromag.BadInputError, match="MagNav.jl map"):
        aeromag.read_flight(MAT5 / "map.mat")


def test_to_mat_reads_back_here_and_in_scipy(tmp_path):
    """Flight.to_mat writes a MATLAB v5 MAT-file of n x 1 variables that
    reads back bit for bit, text included; SciPy reads the same values when
    it is installed; a name MATLAB cannot hold is bad input."""
    n = 6
    flight = aeromag.Flight.from_dict({
        "time": 0.1 * np.arange(n),
        "x": np.array([53064.063, np.nan, -0.0, 1e300, 5e-324, -7.25]),
        "line": ["L1020", "", "T901", "L1020", "1003.10", "x"],
        "note": ["µ", "", "", "", "", "ok"],
    })
    path = tmp_path / "f.mat"
    flight.to_mat(path)
    back = aeromag.read_flight(path)
    assert back.columns == flight.columns and back.not_read == []
    for c in ("time", "x"):
        assert np.asarray(back[c]).tobytes() == np.asarray(flight[c]).tobytes()
    assert list(back["line"]) == list(flight["line"])
    assert list(back["note"]) == list(flight["note"])
    bad = aeromag.Flight.from_dict({"2nd": np.arange(3.0)})
    with pytest.raises(aeromag.BadInputError, match="column '2nd'.*MATLAB variable name"):
        bad.to_mat(tmp_path / "b.mat")
    try:
        import scipy.io
    except ImportError:
        return
    m = scipy.io.loadmat(path)
    assert m["x"].shape == (n, 1)
    assert m["x"].ravel().tobytes() == np.asarray(flight["x"]).tobytes()
    assert [s.rstrip() for s in m["line"]] == list(flight["line"])
    assert [s.rstrip() for s in m["note"]] == list(flight["note"])


def test_a_magnav_map_is_not_read_as_a_flight(tmp_path):
    """MagNav.jl's map HDF5 (map, xx, yy, alt) is named as a map."""
    h5py = pytest.importorskip("h5py")
    path = tmp_path / "map.h5"
    with h5py.File(path, "w") as h:
        h["map"] = np.zeros((4, 5))
        h["xx"] = np.linspace(-95.0, -94.0, 5)
        h["yy"] = np.linspace(38.0, 39.0, 4)
        h["alt"] = 300.0
    with pytest.raises(aeromag.BadInputError, match="is a MagNav.jl map"):
        aeromag.read_flight(path)
