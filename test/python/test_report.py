"""bvc3d.report on a hand-made experiment folder: the example place-field panels are titled by
what they show."""
import csv

import h5py
import numpy as np
import pytest

from bvc3d import report


def make_folder(path, modality_by_model):
    """An experiment folder with one trial per model in the cross-60 world; each trial's cells have
    the given modality indices (cell k has k + 1 active bins, so the last candidate is the pick)."""
    models = list(modality_by_model)
    with open(path / "trials.csv", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["name", "model", "world", "seed"])
        for m in models:
            w.writerow([f"cross-60_{m}_seed0", m, "cross-60", 0])
    with open(path / "summary.csv", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["condition", "model", "world", "tilt_deg"])
        for m in models:
            w.writerow([f"cross-60_{m}", m, "cross-60", 60])
    centers = np.column_stack([np.linspace(-4, 4, 10), np.linspace(-3, 3, 10)])
    for m, mi in modality_by_model.items():
        mi = np.asarray(mi, dtype=np.int64)
        maps = np.zeros((10, len(mi)), dtype=np.float32)
        for k in range(len(mi)):
            if mi[k] > 0:
                maps[:k + 1, k] = 1
        with h5py.File(path / f"cross-60_{m}_seed0.h5", "w") as f:
            f["metrics/modality"] = mi
            f["metrics/rate_maps"] = maps
            f["metrics/bin_centers"] = centers
    return report.Folder(str(path))


@pytest.mark.parametrize("first,last,titles", [
    ([0, 2, 1, 3], [1, 2, 1], ["multimodal: A cell 3 (MI = 3)", "unimodal: B cell 2 (MI = 1)"]),
    ([0, 1, 1], [2, 3, 0], ["no multimodal cell; showing a unimodal one:\nA cell 2 (MI = 1)",
                            "no unimodal cell; showing a multimodal one:\nB cell 1 (MI = 3)"]),
    ([0, 0], [0, 1], ["A: no multimodal cell; no cell has a field (every MI = 0)", "unimodal: B cell 1 (MI = 1)"]),
])
def test_place_field_panels_say_what_they_show(tmp_path, first, last, titles):
    folder = make_folder(tmp_path, {"A": first, "B": last})
    out = tmp_path / "place_fields.png"
    got = report.fig_place_fields(folder, str(out))
    assert [t.rsplit("\n", 1)[0] for t in got] == titles
    assert all(t.endswith("\n60° tilt") for t in got)
    assert out.stat().st_size > 0


def test_pick_example_cell():
    maps = np.zeros((5, 4))
    maps[:2, 1] = maps[:4, 2] = maps[:1, 3] = 1
    assert report.pick_example_cell([0, 2, 2, 1], maps, "multimodal") == (2, "multimodal")
    assert report.pick_example_cell([0, 2, 2, 1], maps, "unimodal") == (3, "unimodal")
    assert report.pick_example_cell([0, 1, 1, 0], maps, "multimodal") == (2, "no multimodal cell; showing a unimodal one")
    assert report.pick_example_cell([0, 0], maps[:, :2], "unimodal")[0] is None


def test_failed_report_hint_works_as_printed(tmp_path):
    """When the figures fail, the error prints the command that redoes them; run verbatim in a shell
    with nothing of ours in its environment (no PYTHONPATH; `python3` on PATH may lack numpy), it
    works."""
    import os
    import shlex
    import subprocess

    from conftest import run_cli

    out = tmp_path / "exp"
    out.mkdir()
    (out / "figures").write_text("a file where the figures folder goes: the report fails")
    proc = run_cli("paper", "--hours", "0.02", "--models", "2d", "--tilts", "0", "--out", "exp", cwd=tmp_path)
    assert proc.returncode == 2, proc.stderr
    lines = proc.stderr.splitlines()
    i = next(k for k, line in enumerate(lines) if line.endswith("rerun it with:"))
    command = lines[i + 1].strip()
    assert command.startswith("PYTHONPATH=") and " -m bvc3d.report exp" in command
    interpreter = shlex.split(command)[1]
    assert os.path.isabs(interpreter), command  # an interpreter by path, not whatever `python3` is first on PATH
    (out / "figures").unlink()
    env = {"PATH": "/usr/local/bin:/usr/bin:/bin", "HOME": str(tmp_path)}
    done = subprocess.run(["bash", "-c", command], cwd=tmp_path, env=env, capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    assert (out / "report.md").exists() and (out / "figures" / "msai.png").exists()
    # The interpreter the program is told to use is the one it names.
    env = dict(os.environ, BVC3D_PYTHON="/usr/bin/python3.11" if os.path.exists("/usr/bin/python3.11") else "/usr/bin/python3")
    (out / "report.md").unlink()
    (out / "figures" / "msai.png").unlink()
    (out / "figures").rename(out / "figures.old")
    (out / "figures").write_text("blocker")
    proc = run_cli("summarize", "exp", cwd=tmp_path, env=env)
    assert proc.returncode == 2 and f" {env['BVC3D_PYTHON']} -m bvc3d.report exp" in proc.stderr, proc.stderr
