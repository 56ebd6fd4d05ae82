"""The examples run."""

import subprocess

import pytest
import sys

from conftest import ROOT


def test_quickstart_runs(tmp_path):
    p = subprocess.run(
        [sys.executable, str(ROOT / "python" / "examples" / "quickstart.py"), str(tmp_path)],
        capture_output=True,
        text=True,
    )
    assert p.returncode == 0, p.stderr
    assert "survey error" in p.stdout
    assert (tmp_path / "model_ls.json").exists() and (tmp_path / "model_kalman.json").exists()


def run_example(name, *args, cwd=None):
    return subprocess.run(
        [sys.executable, str(ROOT / "python" / "examples" / name), *map(str, args)],
        capture_output=True,
        text=True,
        cwd=cwd or str(ROOT / "python" / "examples"),
    )


def test_archive_with_batch(tmp_path):
    p = run_example("archive.py")
    assert p.returncode == 0, p.stderr
    lines = [l for l in p.stdout.splitlines() if l.startswith("flight_")]
    assert [l.split(":")[0] for l in lines] == [f"flight_{k}.csv" for k in range(1, 5)]


def test_archive_on_a_dask_local_cluster():
    pytest.importorskip("dask.distributed")
    p = run_example("dask_archive.py")
    assert p.returncode == 0, p.stderr
    assert sum(l.startswith("flight_") for l in p.stdout.splitlines()) == 4
