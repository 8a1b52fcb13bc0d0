"""Shared fixtures: where the built CLI and the source tree are (ctest sets both)."""
import os
import pathlib
import subprocess

import pytest

SOURCE_DIR = pathlib.Path(os.environ.get("BVC3D_SOURCE_DIR", pathlib.Path(__file__).resolve().parents[2]))
CLI = os.environ.get("BVC3D_CLI", str(SOURCE_DIR / "build" / "bvc3d"))


def run_cli(*args, check=False, **kw):
    """Run the bvc3d program; returns the CompletedProcess (text mode)."""
    proc = subprocess.run([CLI, *map(str, args)], capture_output=True, text=True, **kw)
    if check and proc.returncode != 0:
        raise AssertionError(f"bvc3d {' '.join(map(str, args))} failed ({proc.returncode}):\n{proc.stderr}")
    return proc


@pytest.fixture
def cli():
    return run_cli


@pytest.fixture
def source_dir():
    return SOURCE_DIR
