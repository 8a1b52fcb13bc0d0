"""What one command writes, the next reads; output paths take a trailing slash; an error leaves nothing.

Issue 32, findings 1 and 2: `export-scans --out walk/` and `view --export page/` (as the docs write
them) crashed and left folders behind; `walk --out walk.csv` then `run --trajectory walk.csv` was
refused. Each round trip below is checked against what the first command wrote (numpy reads it).
"""
import os

import numpy as np
import pytest

from conftest import run_cli


def listing(folder):
    return sorted(str(p.relative_to(folder)) for p in folder.rglob("*"))


def test_export_scans_to_a_folder_with_a_trailing_slash_then_replay_and_map_read_it(tmp_path):
    out = tmp_path / "walk"
    proc = run_cli("export-scans", "--world", "cross", "--tilt", "45", "--hours", "0.002", "--format", "pcd",
                   "--out", f"{out}/", cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert [p.name for p in tmp_path.iterdir()] == ["walk"]  # no temporary folder beside it
    scans = sorted(p.name for p in out.glob("*.pcd"))
    assert len(scans) == len((out / "poses.txt").read_text().splitlines()) // 4 >= 2  # 4x4 rows per pose
    # Again into the same folder: refused, naming it; with --force the earlier recording is replaced. Then read back
    # by replay and map.
    again = run_cli("export-scans", "--hours", "0.002", "--out", f"{out}//", cwd=tmp_path)
    assert again.returncode == 2 and f"--out '{out}' exists" in again.stderr, again.stderr
    assert run_cli("export-scans", "--hours", "0.002", "--out", f"{out}//", "--force", cwd=tmp_path).returncode == 0
    assert sorted(p.name for p in tmp_path.iterdir()) == ["walk"]
    replay = run_cli("replay", "--scans", f"{out}/", "--poses", out / "poses.txt", "--model", "2d",
                     "--out", tmp_path / "r" / "replay.h5/", cwd=tmp_path)
    assert replay.returncode == 0, replay.stderr
    assert (tmp_path / "r" / "replay.h5").is_file()
    mapped = run_cli("map", "--scans", out, "--poses", out / "poses.txt", "--out", tmp_path / "map.ply",
                     cwd=tmp_path)
    assert mapped.returncode == 0, mapped.stderr
    assert (tmp_path / "map.ply").read_bytes().startswith(b"ply\n")


def test_export_scans_below_a_file_is_refused_and_leaves_nothing(tmp_path):
    (tmp_path / "file").write_text("x")
    for out in (tmp_path / "file" / "walk", tmp_path / "new" / "file2" / "walk"):
        if out.parent.name == "file2":
            (tmp_path / "new").mkdir()
            (tmp_path / "new" / "file2").write_text("y")
        proc = run_cli("export-scans", "--hours", "0.001", "--out", f"{out}/", cwd=tmp_path)
        assert proc.returncode == 2, proc.stderr
        assert "internal error" not in proc.stderr and "is not a folder" in proc.stderr
    assert listing(tmp_path) == ["file", "new", "new/file2"]


def test_a_failing_export_scans_leaves_no_folder_it_made(tmp_path):
    track = tmp_path / "track.csv"
    track.write_text("t,x,y,heading\n0,-4,-4,0\n0.288,40,-4,0\n")
    proc = run_cli("export-scans", "--trajectory", track, "--out", tmp_path / "a" / "b" / "walk/", cwd=tmp_path)
    assert proc.returncode == 2
    assert f"trajectory '{track}', row 1" in proc.stderr and "lies outside world" in proc.stderr
    assert listing(tmp_path) == ["track.csv"]


def test_view_export_with_a_trailing_slash_and_below_a_file(tmp_path):
    page = tmp_path / "page"
    proc = run_cli("view", "--export", f"{page}/", "--export-steps", "1", cwd=tmp_path)
    if proc.returncode != 0 and "is the viewer built" in proc.stderr + proc.stdout or "npm ci" in proc.stderr:
        pytest.skip("the viewer's page is not built here")
    assert proc.returncode == 0, proc.stderr
    assert (page / "index.html").is_file() and (page / "data" / "index.js").is_file()
    assert listing(tmp_path) == listing(tmp_path)  # stable
    assert sorted(p.name for p in tmp_path.iterdir()) == ["page"]
    (tmp_path / "file").write_text("x")
    proc = run_cli("view", "--export", tmp_path / "file" / "page", cwd=tmp_path)
    assert proc.returncode == 2 and "internal error" not in proc.stderr, proc.stderr
    assert "is not a folder" in proc.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["file", "page"]


def test_localize_makes_no_output_folder_when_its_inputs_fail(tmp_path):
    out = tmp_path / "results" / "loc"
    proc = run_cli("localize", "--templates", tmp_path / "none.h5", "--queries", tmp_path / "none.h5", "--model", "2d",
                   "--no-figure", "--out", f"{out}/", cwd=tmp_path)
    assert proc.returncode == 2 and "none.h5" in proc.stderr
    assert listing(tmp_path) == []


def test_walk_output_runs_as_a_trajectory(tmp_path):
    walk = tmp_path / "walk.csv"
    run_cli("walk", "--hours", "0.005", "--seed", "3", "--out", walk, check=True)
    rows = np.genfromtxt(walk, delimiter=",", names=True)
    assert "bumped" in rows.dtype.names
    proc = run_cli("run", "--trajectory", walk, "--protocol", "online", "--sample-hours", "0.005",
                   "--out", tmp_path / "t.h5", "--checkpoint-minutes", "0")
    assert proc.returncode == 0, proc.stderr
    import h5py
    with h5py.File(tmp_path / "t.h5") as f:
        x = f["samples/x"][:] if "samples/x" in f else f["x"][:]
    n = len(x)
    assert n >= 10
    np.testing.assert_array_equal(x, rows["x"][:n])


def test_route_output_runs_as_a_trajectory(tmp_path, source_dir):
    world = source_dir / "test" / "bad_inputs" / "gazebo" / "room.world"
    route = tmp_path / "route.csv"
    run_cli("route", "--world", world, "--tour", "--out", route, check=True)
    proc = run_cli("run", "--world", world, "--trajectory", route, "--protocol", "online", "--sample-hours", "0.002",
                   "--model", "2d", "--out", tmp_path / "t.h5", "--checkpoint-minutes", "0")
    assert proc.returncode == 0, proc.stderr


def test_a_repeated_trajectory_column_is_named(tmp_path):
    track = tmp_path / "track.csv"
    track.write_text("t,x,y,heading,y\n0,0,0,0,0\n")
    proc = run_cli("run", "--trajectory", track, "--out", tmp_path / "t.h5")
    assert proc.returncode == 2
    assert "line 1: the header names the column 'y' twice" in proc.stderr
    assert os.listdir(tmp_path) == ["track.csv"]


def test_docs_robot_keys_are_the_defaults(source_dir):
    """docs/python.md names the robot's keys with values it calls the defaults: they are (bvc3d config)."""
    import re
    text = (source_dir / "docs" / "python.md").read_text()
    m = re.search(r"`radius=([\d.]+), turn_rate=([\d.]+)`, the defaults", text)
    assert m, "docs/python.md no longer names the robot's default keys"
    config = run_cli("config", check=True).stdout
    defaults = {k: float(v) for k, v in re.findall(r"^\s+(radius|turn_rate): ([\d.]+)", config, re.M)}
    assert defaults == {"radius": float(m.group(1)), "turn_rate": float(m.group(2))}


def test_analyze_out_and_a_narrow_table(tmp_path):
    out = tmp_path / "t.h5"
    run_cli("run", "--hours", "0.02", "--seed", "1", "--out", out, "--checkpoint-minutes", "0", check=True)
    proc = run_cli("analyze", out, "--min-samples", "10", "--out", tmp_path / "sub" / "m.csv/", check=True)
    assert max(len(line) for line in proc.stdout.splitlines()) <= 100
    import csv
    (row,) = list(csv.DictReader(open(tmp_path / "sub" / "m.csv")))
    assert row["min_samples"] == "10" and row["trial"] in proc.stdout and float(row["n_bins"]) > 0
    bad = run_cli("analyze", tmp_path / "none.h5", "--out", tmp_path / "new" / "m.csv")
    assert bad.returncode == 2 and not (tmp_path / "new").exists()


def test_readme_states_the_decoding_coverage_of_its_trials(source_dir):
    """README's figure of the decoding error says how many samples were undecoded: the range it gives
    is the range of frac_undecoded over docs/reproduction/spec-trials.csv, rounded outwards."""
    import csv
    import math
    import re
    text = (source_dir / "README.md").read_text()
    m = re.search(r"(\d+)–(\d+) % of each trial's samples are undecoded", text)
    assert m, "README.md no longer states the decoding coverage"
    trials = source_dir / "docs" / "reproduction" / "spec-trials.csv"
    values = [float(r["frac_undecoded"]) for r in csv.DictReader(open(trials))]
    assert (int(m.group(1)), int(m.group(2))) == (math.floor(100 * min(values)), math.ceil(100 * max(values)))
    assert "decoding_coverage.png" in text and (source_dir / "docs/figures/decoding_coverage.png").exists()


def test_a_trajectory_off_the_model_step_is_warned_about(tmp_path):
    """Rows every 0.05 s stepped once per row (--step-per-row) step the model 5.76 times as often per
    second as the robot's 0.288 s step (by default they are resampled: test_trajectory_steps.py)."""
    fast, model = tmp_path / "fast.csv", tmp_path / "model.csv"
    t = np.arange(200) * 0.05
    fast.write_text("t,x,y,heading\n" + "".join(f"{a},{-4 + 0.02 * i},-4,0\n" for i, a in enumerate(t)))
    t = np.arange(200) * 0.288
    model.write_text("t,x,y,heading\n" + "".join(f"{a},{-4 + 0.02 * i},-4,0\n" for i, a in enumerate(t)))
    for path, warned in ((fast, True), (model, False)):
        proc = run_cli("run", "--trajectory", path, "--protocol", "online", "--sample-hours", "0.001",
                       "--out", tmp_path / f"{path.stem}.h5", "--checkpoint-minutes", "0", "--step-per-row")
        assert proc.returncode == 0, proc.stderr
        assert ("every 0.05 s" in proc.stderr and "5.76 times as fast" in proc.stderr) == warned, proc.stderr
