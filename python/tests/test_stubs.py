"""The type stubs describe the extension as it is (mypy's stubtest)."""

import subprocess
import sys

import pytest


def test_stubs_match_the_extension():
    pytest.importorskip("mypy.stubtest")
    p = subprocess.run(
        [sys.executable, "-m", "mypy.stubtest", "aeromag._aeromag"],
        capture_output=True,
        text=True,
    )
    assert p.returncode == 0, p.stdout + p.stderr
