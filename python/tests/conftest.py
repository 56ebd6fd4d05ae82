"""Shared fixtures: the CLI binary (built by the Rust tests:
target/release/aeromag, or $AEROMAG_BIN) and simulated flights."""

import os
import pathlib
import shutil
import subprocess

import pytest

import aeromag

ROOT = pathlib.Path(__file__).resolve().parents[2]


def cli_path() -> str:
    path = os.environ.get("AEROMAG_BIN") or str(ROOT / "target" / "release" / "aeromag")
    if not os.path.exists(path):
        found = shutil.which("aeromag")
        if found is None:
            pytest.skip("the aeromag CLI is not built (cargo build --release, or set AEROMAG_BIN)")
        path = found
    return path


@pytest.fixture(scope="session")
def cli():
    """Run the CLI: cli(args...) -> CompletedProcess (text)."""
    path = cli_path()

    def run(*args, check=True, input=None):
        p = subprocess.run([path, *map(str, args)], capture_output=True, text=True, input=input)
        if check and p.returncode != 0:
            raise AssertionError(f"aeromag {' '.join(map(str, args))} exited {p.returncode}:\n{p.stderr}")
        return p

    return run


@pytest.fixture(scope="session")
def sim_dir(tmp_path_factory, cli):
    """A calibration flight (seed 1) and a survey (seed 2) written by the CLI."""
    d = tmp_path_factory.mktemp("sim")
    cli("simulate", "calibration", "--seed", 1, "--out", d / "cal")
    cli("simulate", "survey", "--seed", 2, "--out", d / "survey")
    return d


@pytest.fixture(scope="session")
def cal_csv(sim_dir):
    return sim_dir / "cal" / "calibration.csv"


@pytest.fixture(scope="session")
def survey_csv(sim_dir):
    return sim_dir / "survey" / "survey.csv"


@pytest.fixture(scope="session")
def cal(cal_csv):
    return aeromag.read_flight(cal_csv)
