"""By how much two builds' numbers differ: compares the DUMP files of `model_steps PRESET STEPS BLOCK DUMP`
(every step's BVC rates as float64, then every step's place-cell rates as float32) of the same preset.

    /usr/bin/python3 test/ubench/compare_dumps.py NEW OLD STEPS [N_BVC [N_PLACE]]

Prints the largest change of a BVC rate relative to its step's largest rate, how many BVC and
place-cell rates differ at all, and the largest change of a place-cell rate.
"""
import sys

import numpy as np


def read(path, steps, n_bvc, n_place):
    raw = np.fromfile(path, dtype=np.uint8)
    expected = steps * (8 * n_bvc + 4 * n_place)
    if raw.size != expected:
        sys.exit(f"{path}: {raw.size} bytes, expected {expected} for {steps} steps of {n_bvc} BVCs "
                 f"and {n_place} place cells")
    bvc = raw[:steps * 8 * n_bvc].view(np.float64).reshape(steps, n_bvc)
    place = raw[steps * 8 * n_bvc:].view(np.float32).reshape(steps, n_place)
    return bvc, place


def main(argv):
    if len(argv) < 4:
        sys.exit(__doc__)
    steps = int(argv[3])
    n_bvc = int(argv[4]) if len(argv) > 4 else 960
    n_place = int(argv[5]) if len(argv) > 5 else 250
    new_bvc, new_place = read(argv[1], steps, n_bvc, n_place)
    old_bvc, old_place = read(argv[2], steps, n_bvc, n_place)
    largest = np.abs(old_bvc).max(axis=1, keepdims=True)
    relative = np.abs(new_bvc - old_bvc) / np.where(largest > 0, largest, 1.0)
    print(f"BVC rates: {np.count_nonzero(new_bvc != old_bvc)} of {new_bvc.size} differ; "
          f"largest change {relative.max():.3g} of the step's largest rate")
    print(f"place-cell rates: {np.count_nonzero(new_place != old_place)} of {new_place.size} differ; "
          f"largest change {np.abs(new_place.astype(np.float64) - old_place).max():.3g}")


if __name__ == "__main__":
    main(sys.argv)
