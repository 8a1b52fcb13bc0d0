"""Results do not move unless a change means them to: `bvc3d paper --hours 0.5` (all four models in
all four arenas) must write trial files whose every dataset and attribute equals, bit for bit, those
recorded in test/data/paper-0.5h-digests.json (only `format_version` may change).

The digests were taken from the files of the code before the architecture refactor. A change that is
meant to move results (and says so in docs/performance.md or the reproduction notes) regenerates
them with
    PYTHONPATH=build/python /usr/bin/python3 test/python/test_regression.py --write RESULTS_DIR
where RESULTS_DIR holds the files of `build/bvc3d paper --hours 0.5 --no-report --out RESULTS_DIR`.
"""
import hashlib
import json
import pathlib
import sys

import h5py
import numpy as np

DIGESTS = pathlib.Path(__file__).resolve().parents[1] / "data" / "paper-0.5h-digests.json"
IGNORED = {"/@format_version"}


def value_digest(v):
    if isinstance(v, np.ndarray):
        blob = str(v.dtype).encode() + str(v.shape).encode() + np.ascontiguousarray(v).tobytes()
    else:
        blob = repr(v.item() if isinstance(v, np.generic) else v).encode()
    return hashlib.sha256(blob).hexdigest()[:16]


def file_digests(path):
    """Every dataset and attribute of an HDF5 file: {"dataset" or "object/@attribute": digest}."""
    out = {}
    with h5py.File(path, "r") as f:
        def visit(name, obj):
            if isinstance(obj, h5py.Dataset):
                out[name] = value_digest(obj[()])
            for k, v in obj.attrs.items():
                out[f"{name}/@{k}"] = value_digest(v)
        for k, v in f.attrs.items():
            out[f"/@{k}"] = value_digest(v)
        f.visititems(visit)
    return {k: v for k, v in out.items() if k not in IGNORED}


def folder_digests(folder):
    return {p.name: file_digests(p) for p in sorted(pathlib.Path(folder).glob("*.h5"))}


def test_paper_half_hour_is_bit_identical(tmp_path):
    from conftest import run_cli
    out = tmp_path / "paper"
    run_cli("paper", "--hours", 0.5, "--no-report", "--jobs", 2, "--out", out, check=True)
    expected = json.loads(DIGESTS.read_text())
    got = folder_digests(out)
    assert sorted(got) == sorted(expected), "a different set of trial files"
    differences = [f"{name}: {key}" for name in expected for key in sorted(set(expected[name]) | set(got[name]))
                   if expected[name].get(key) != got[name].get(key)]
    assert not differences, "results moved:\n" + "\n".join(differences[:40])


if __name__ == "__main__":
    if len(sys.argv) != 3 or sys.argv[1] != "--write":
        raise SystemExit(__doc__)
    DIGESTS.write_text(json.dumps(folder_digests(sys.argv[2]), indent=0, sort_keys=True) + "\n")
    print(f"wrote {DIGESTS}")
