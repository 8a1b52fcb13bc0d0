"""The `bvc3d` command of a pip-installed package: runs the compiled program that ships inside it.

`bvc3d paper` writes its report by running `$BVC3D_PYTHON -m bvc3d.report` with $BVC3D_PYTHONPATH on
the module path (app/cmd_experiment.cpp). Unless they are already set, both point at this interpreter
and this installation, so the report comes from the installed package and not from the build folder
the program was compiled in (which may be gone, or hold another version).
"""
import os
import sys
from pathlib import Path


def program_path():
    """The compiled `bvc3d` program inside the installed package."""
    return Path(__file__).resolve().parent / "bvc3d"


def main():
    """Replaces this process with the compiled program, passing on the command line."""
    package_parent = Path(__file__).resolve().parents[2]  # site-packages, which holds bvc3d/
    os.environ.setdefault("BVC3D_PYTHON", sys.executable)
    os.environ.setdefault("BVC3D_PYTHONPATH", str(package_parent))
    program = str(program_path())
    os.execv(program, ["bvc3d", *sys.argv[1:]])
