#!/usr/bin/env bash
# Installs the Python package with Debian's pip into a fresh venv, offline, as README's Install section
# says, and checks it from outside the repository: the module, the `bvc3d` command, and `bvc3d paper`
# writing its report with the installed package.
#   bash test/install/pip.sh        (.ci/run runs it; builds the library once, a few minutes on 2 cores)
# The install is made from a copy of the repository's files that is deleted before the checks, so
# nothing can come from a build folder.
set -euo pipefail
source_dir=$(cd "$(dirname "$0")/../.." && pwd)
scratch=$(mktemp -d)
trap 'rm -rf "$scratch"' EXIT
venv="$scratch/venv"
export PIP_NO_INDEX=1 PIP_NO_CACHE_DIR=1 PIP_DISABLE_PIP_VERSION_CHECK=1
unset PYTHONPATH BVC3D_PYTHON BVC3D_PYTHONPATH

# The files git tracks or would track (no build folders, no results).
mkdir "$scratch/source"
git -C "$source_dir" ls-files -z --cached --others --exclude-standard \
  | tar -C "$source_dir" --null --ignore-failed-read -T - -cf - | tar -C "$scratch/source" -xf -

# With ccache (scripts/setup installs it), the copy's compiles that ./build made already are cache hits:
# paths relative to the copy, and setup.py builds one level below it, as ./build is.
if command -v ccache >/dev/null; then
  export CMAKE_CXX_COMPILER_LAUNCHER=ccache CMAKE_C_COMPILER_LAUNCHER=ccache CCACHE_BASEDIR="$scratch/source"
fi
/usr/bin/python3 -m venv --system-site-packages "$venv"
(cd "$scratch/source" && "$venv/bin/pip" install --no-build-isolation . >"$scratch/pip.log" 2>&1) \
  || { tail -n 60 "$scratch/pip.log" >&2; echo "pip: install failed" >&2; exit 1; }
rm -rf "$scratch/source"
echo "pip: $(tail -n 1 "$scratch/pip.log")"

mkdir "$scratch/work"
cd "$scratch/work"
version=$(sed -n 's/^project(bvc3d VERSION \([0-9.]*\).*/\1/p' "$source_dir/CMakeLists.txt")
"$venv/bin/python" - "$venv" "$version" <<'PY'
import importlib.metadata
import sys

import bvc3d

venv, version = sys.argv[1:]
assert bvc3d.__file__.startswith(venv), f"bvc3d imported from {bvc3d.__file__}, not from the venv"
assert importlib.metadata.version("bvc3d") == version, importlib.metadata.version("bvc3d")
assert bvc3d.__version__ == version, f"bvc3d.__version__ {bvc3d.__version__} != CMakeLists.txt's {version}"
assert "2d" in bvc3d.model_presets(), bvc3d.model_presets()
returns = bvc3d.World.cross(tilt_deg=45).scan("spherical", 1.0, 2.0, 0.5)
assert returns.ndim == 2 and returns.shape[1] == 3 and len(returns) > 0, returns.shape
layer = bvc3d.BoundaryVectorLayer.preset("3d-0.2")
rates = layer.rates(returns)
assert rates.shape == (layer.n_cells,) and rates.max() > 0
print(f"pip: import bvc3d {bvc3d.__version__}: {len(returns)} returns in the cross arena, "
      f"{layer.n_cells} BVCs, max rate {rates.max():.1f}")
PY

"$venv/bin/bvc3d" --version | tee "$scratch/version.txt"
grep -qx "bvc3d $version" "$scratch/version.txt" \
  || { echo "pip: bvc3d --version does not print CMakeLists.txt's version $version" >&2; exit 1; }
"$venv/bin/bvc3d" run --hours 0.02 --out trial.h5 >/dev/null
[ -s trial.h5 ] || { echo "pip: bvc3d run wrote no trial.h5" >&2; exit 1; }
echo "pip: bvc3d run wrote trial.h5"
# The report runs as a child `python -m bvc3d.report`: it must find the installed package.
"$venv/bin/bvc3d" paper --models 2d --tilts 0 --hours 0.05 --out paper >"$scratch/paper.log" 2>&1 \
  || { cat "$scratch/paper.log" >&2; echo "pip: bvc3d paper failed" >&2; exit 1; }
[ -s paper/report.md ] && [ -s paper/figures/sai_grid.png ] \
  || { cat "$scratch/paper.log" >&2; echo "pip: bvc3d paper wrote no report" >&2; exit 1; }
echo "pip: bvc3d paper wrote report.md and its figures"
echo "pip: passed"
