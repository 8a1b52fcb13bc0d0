"""Results do not move unless a change means them to: `bvc3d paper --hours 0.5` (all four models in
all four arenas) and `bvc3d flight --hours 0.25` (the three flying models in the three flight worlds)
must write trial files whose every dataset and attribute equals, bit for bit, those recorded in
test/data/paper-0.5h-digests.json, test/data/flight-0.25h-digests.json and their additions (only
`format_version` may change). The flight digests were taken from the code before issue 26's house work.

The digests of test/data/paper-0.5h-digests.json were taken again after issue 16's speed work, which
moves the BVC sums by up to 4e-10 of a step's largest rate (docs/performance.md#results); before that,
from the files of the code before the architecture refactor. The weights of the 30° arena's 3-D trials were
retaken when Embree was held to its AVX2 kernels (its AVX-512 kernels, on the machine of the earlier digests, moved
them). A change that adds datasets or attributes without moving
any (a new metric, a new analysis parameter recorded with the metrics) records the new ones in a file of their own,
test/data/<run>-digests.<what>.json, so that the earlier digests stay as they were and still
must match:
    PYTHONPATH=build/python /usr/bin/python3 test/python/test_regression.py --add RUN WHAT RESULTS_DIR
A change that is meant to move results (and says so in docs/performance.md or the reproduction
notes) regenerates every digest file of a run with
    PYTHONPATH=build/python /usr/bin/python3 test/python/test_regression.py --write RUN RESULTS_DIR
RUN is paper or flight; RESULTS_DIR holds the files of `build/bvc3d RUN --hours H --no-report --out
RESULTS_DIR` with H as in RUNS. No key may be recorded in two files.
"""
import hashlib
import json
import pathlib
import sys

import h5py
import numpy as np
import pytest

DATA = pathlib.Path(__file__).resolve().parents[1] / "data"
# run: (command, simulated hours); its digests are test/data/<command>-<hours>h-digests[.<what>].json
RUNS = {"paper": ("paper", 0.5), "flight": ("flight", 0.25)}
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


def stem(run):
    command, hours = RUNS[run]
    return f"{command}-{hours}h-digests"


def digest_files(run):
    """The base file first, then the additions in name order."""
    return [DATA / f"{stem(run)}.json"] + sorted(DATA.glob(f"{stem(run)}.*.json"))


def recorded_digests(run):
    """{trial file: {key: digest}} over every digest file of a run; a key recorded twice is an error."""
    merged, origin = {}, {}
    for path in digest_files(run):
        for name, keys in json.loads(path.read_text()).items():
            for key, digest in keys.items():
                assert (name, key) not in origin, f"{name}: {key} is recorded in {origin[name, key]} and {path.name}"
                origin[name, key] = path.name
                merged.setdefault(name, {})[key] = digest
    return merged


@pytest.mark.parametrize("run", sorted(RUNS))
def test_short_run_is_bit_identical(tmp_path, run):
    from conftest import run_cli
    command, hours = RUNS[run]
    out = tmp_path / run
    run_cli(command, "--hours", hours, "--no-report", "--jobs", 2, "--out", out, check=True)
    expected = recorded_digests(run)
    got = folder_digests(out)
    assert sorted(got) == sorted(expected), "a different set of trial files"
    differences = [f"{name}: {key}" for name in expected for key in sorted(set(expected[name]) | set(got[name]))
                   if expected[name].get(key) != got[name].get(key)]
    assert not differences, "results moved:\n" + "\n".join(differences[:40])


def write(path, digests):
    path.write_text(json.dumps(digests, indent=0, sort_keys=True) + "\n")
    print(f"wrote {path}")


if __name__ == "__main__":
    if len(sys.argv) == 4 and sys.argv[1] == "--write" and sys.argv[2] in RUNS:
        run = sys.argv[2]
        got = folder_digests(sys.argv[3])
        claimed = set()
        for path in digest_files(run)[1:]:  # each addition keeps its keys; the base file takes the rest
            keys = {(n, k) for n, ks in json.loads(path.read_text()).items() for k in ks}
            claimed |= keys
            write(path, {n: {k: d for k, d in ks.items() if (n, k) in keys} for n, ks in got.items()})
        base = {n: {k: d for k, d in ks.items() if (n, k) not in claimed} for n, ks in got.items()}
        write(digest_files(run)[0], base)
    elif len(sys.argv) == 5 and sys.argv[1] == "--add" and sys.argv[2] in RUNS:
        run, what, folder = sys.argv[2:]
        recorded = recorded_digests(run)
        new = {n: {k: d for k, d in ks.items() if k not in recorded.get(n, {})}
               for n, ks in folder_digests(folder).items()}
        write(DATA / f"{stem(run)}.{what}.json", {n: ks for n, ks in new.items() if ks})
    else:
        raise SystemExit(__doc__)
