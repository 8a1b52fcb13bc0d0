"""Builds the compiled parts of the Python package with CMake, for `pip install .` (pyproject.toml).

setuptools packages the pure-Python modules (python/bvc3d) and the launcher of the program
(python/program, the module bvc3d.program). CMake builds the extension bvc3d._core and the `bvc3d`
program (only these two targets) in build-pip/ and installs both into the package (component
python_package, python/CMakeLists.txt). The CMake build folder sits beside ./build, one level below the
source tree: with ccache and CCACHE_BASEDIR set to the tree, its compiles are the same as ./build's.
"""
import os
import re
import subprocess
import sys
from pathlib import Path

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

SOURCE_DIR = Path(__file__).resolve().parent


def project_version():
    """The version in CMakeLists.txt's project() call, the one place it is written."""
    text = (SOURCE_DIR / "CMakeLists.txt").read_text()
    match = re.search(r"project\(\s*bvc3d\s+VERSION\s+([0-9.]+)", text)
    if match is None:
        raise RuntimeError("CMakeLists.txt has no `project(bvc3d VERSION ...)`")
    return match.group(1)


class CMakeExtension(Extension):
    """The extension bvc3d._core, built by CMake: setuptools compiles no sources itself. Declaring it
    makes the wheel specific to this interpreter and platform."""

    def __init__(self, name):
        super().__init__(name, sources=[])


class BuildWithCMake(build_ext):
    """Configures, builds and installs the CMake component python_package into the package."""

    def build_extension(self, ext):
        # The folder that holds the package folder bvc3d/ in the wheel being assembled.
        package_root = Path(self.get_ext_fullpath(ext.name)).resolve().parent.parent
        build_dir = SOURCE_DIR / CMAKE_BUILD_DIR
        jobs = os.environ.get("CMAKE_BUILD_PARALLEL_LEVEL") or str(os.cpu_count() or 1)
        configure = [
            "cmake", "-S", str(SOURCE_DIR), "-B", str(build_dir), "-G", "Ninja",
            "-DCMAKE_BUILD_TYPE=Release",
            # The extension must match the interpreter that installs it (a venv's python3, say).
            f"-DPython_EXECUTABLE={sys.executable}",
            "-DBVC3D_BUILD_TESTS=OFF", "-DBVC3D_BUILD_BENCHMARKS=OFF", "-DBVC3D_BUILD_EXAMPLES=OFF",
        ]
        subprocess.run(configure, check=True)
        subprocess.run(["cmake", "--build", str(build_dir), "-j", jobs, "--target", "_core", "bvc3d_cli"], check=True)
        subprocess.run(["cmake", "--install", str(build_dir), "--component", "python_package",
                        "--prefix", str(package_root)], check=True)


# Everything the build writes goes to build-pip/ (ignored by git), setuptools' part to build-pip/setuptools:
# not ./build, which is the CMake build folder of README and scripts/build, and no bvc3d.egg-info beside
# the sources.
CMAKE_BUILD_DIR = "build-pip"
BUILD_BASE = CMAKE_BUILD_DIR + "/setuptools"
(SOURCE_DIR / BUILD_BASE).mkdir(parents=True, exist_ok=True)
setup(
    version=project_version(),
    # In setup.py rather than pyproject.toml, where Debian 12's setuptools calls [tool.setuptools] beta.
    packages=["bvc3d", "bvc3d.program"],
    package_dir={"bvc3d": "python/bvc3d", "bvc3d.program": "python/program"},
    ext_modules=[CMakeExtension("bvc3d._core")],
    cmdclass={"build_ext": BuildWithCMake},
    options={"build": {"build_base": BUILD_BASE}, "egg_info": {"egg_base": BUILD_BASE}},
)
