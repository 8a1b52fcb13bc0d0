"""The paper's experiment end to end through the CLI (issue 5)."""
import csv
import filecmp
import math
import os
import signal
import struct
import subprocess
import time

import h5py
import numpy as np
import pytest

from conftest import CLI, run_cli

HOURS = "0.05"  # three simulated minutes per phase: seconds of wall time


def png_size(path):
    with open(path, "rb") as f:
        head = f.read(24)
    assert head[:8] == b"\x89PNG\r\n\x1a\n", f"{path} is not a PNG"
    return struct.unpack(">II", head[16:24])


@pytest.fixture(scope="module")
def paper_dir(tmp_path_factory):
    out = tmp_path_factory.mktemp("paper")
    run_cli("paper", "--hours", HOURS, "--out", out, "--jobs", 2, check=True)
    return out


def trial_files(d):
    return sorted(p for p in os.listdir(d) if p.endswith(".h5"))


def test_files_datasets_and_metrics(paper_dir):
    files = trial_files(paper_dir)
    assert len(files) == 16
    for name in files:
        with h5py.File(paper_dir / name) as f:
            assert f.attrs["format"] == "bvc3d-trial"
            n = f["samples/t"].shape[0]
            assert n > 200
            for k in ("x", "y", "heading"):
                assert f["samples"][k].shape == (n,) and f["samples"][k].dtype == np.float64
            assert f["samples/rates"].shape == (n, 250) and f["samples/rates"].dtype == np.float32
            assert f["weights"].shape == (250, 960)
            m = f["metrics"].attrs
            for k in ("frac_active", "frac_multimodal"):
                assert 0 <= m[k] <= 1
            assert m["mean_mi_active"] >= 1 or math.isnan(m["mean_mi_active"])
            assert 0 <= m["msai"] <= 1
            assert 0 <= m["decode_median_m"] <= 15
            b = f["metrics/bin_centers"].shape[0]
            assert b == m["n_bins"] and f["metrics/sai"].shape == (b,) and f["metrics/rate_maps"].shape == (b, 250)
            assert np.all(np.isfinite(f["samples/rates"][:]))


def test_summary_has_sixteen_rows(paper_dir):
    rows = list(csv.DictReader(open(paper_dir / "summary.csv")))
    assert len(rows) == 16
    assert {r["model"] for r in rows} == {"2d", "3d-0.1", "3d-0.2", "3d-3l"}
    assert {r["tilt_deg"] for r in rows} == {"0", "30", "45", "60"}
    assert all(r["n_seeds"] == "1" for r in rows)
    md = (paper_dir / "summary.md").read_text().splitlines()
    assert len([l for l in md if l.startswith("| ") and "cross-" in l]) == 16


def test_figures_and_report(paper_dir):
    expected = {  # width, height in pixels (figure inches x 120 dpi)
        "mi_active.png": (840, 432), "mi_mean.png": (840, 432), "mi_multimodal.png": (840, 432),
        "msai.png": (840, 432), "decoding.png": (840, 432), "decoding_coverage.png": (840, 432),
        "trajectory.png": (552, 552),
        "place_fields.png": (1008, 480), "sai_grid.png": (1344, 1200), "environments.png": (1632, 432),
    }
    for name, size in expected.items():
        assert png_size(paper_dir / "figures" / name) == size, name
    report = (paper_dir / "report.md").read_text()
    for name in expected:
        assert f"(figures/{name})" in report
    assert "| 3d-3l | cross-60 |" in report
    # How the trials were run and analyzed, from the files; one seed: no means, no spreads.
    assert (f"explore_then_sample: {HOURS} h of exploration with learning on (not recorded), then {HOURS} h of "
            "sampling with learning frozen (recorded)") in report
    assert "gridsize 50, min_samples 20, quantile 0.1" in report and "eps 1 m" in report and "d_th 2 m" in report
    assert "**Seeds**: 0, one trial per condition" in report
    assert "±" not in report and "standard deviation" not in report


def test_report_module_works_on_its_own(paper_dir, tmp_path):
    env = dict(os.environ)
    proc = subprocess.run(["/usr/bin/python3", "-m", "bvc3d.report", str(paper_dir)], capture_output=True, text=True,
                          env=env)
    assert proc.returncode == 0, proc.stderr
    proc = subprocess.run(["/usr/bin/python3", "-m", "bvc3d.report", str(tmp_path)], capture_output=True, text=True,
                          env=env)
    assert proc.returncode != 0 and "no trials.csv" in proc.stderr


def test_analyze_recomputes_the_stored_metrics(paper_dir, tmp_path):
    path = paper_dir / "cross-45_3d-0.2_seed0.h5"
    cells = tmp_path / "cells.csv"
    table = tmp_path / "metrics.csv"
    proc = run_cli("analyze", path, "--cells", cells, "--out", table, check=True)
    assert max(len(line) for line in proc.stdout.splitlines()) <= 100  # a terminal can show it
    (row,) = list(csv.DictReader(open(table)))
    assert row["file"] == str(path) and row["min_samples"] == "20"
    with h5py.File(path) as f:
        names = [n for n in row if n in f["metrics"].attrs]
        assert len(names) >= 10
        for n in names:
            if isinstance(f["metrics"].attrs[n], (str, bytes)):
                assert row[n] == f["metrics"].attrs[n], n
                continue
            assert float(row[n]) == pytest.approx(f["metrics"].attrs[n], rel=1e-5, nan_ok=True), n
            if list(row).index(n) < list(row).index("gridsize"):  # a metric (then the parameters used)
                assert f" {n} " in proc.stdout
        mi = f["metrics/modality"][:]
    np.testing.assert_array_equal(np.genfromtxt(cells, delimiter=",", names=True)["modality"], mi)
    run_cli("analyze", path, "--min-samples", 5, "--out", f"{table}/", "--force", check=True)  # recomputed, written
    (other,) = list(csv.DictReader(open(table)))
    assert other["min_samples"] == "5" and other != row


def test_rerun_skips_complete_trials(paper_dir):
    before = {n: os.stat(paper_dir / n).st_mtime_ns for n in trial_files(paper_dir)}
    proc = run_cli("paper", "--hours", HOURS, "--out", paper_dir, "--no-report", check=True)
    assert "0 run, 16 already complete" in proc.stdout
    assert before == {n: os.stat(paper_dir / n).st_mtime_ns for n in trial_files(paper_dir)}


def test_jobs_one_and_two_give_identical_files(paper_dir, tmp_path):
    run_cli("paper", "--hours", HOURS, "--out", tmp_path, "--jobs", 1, "--no-report", check=True)
    for name in trial_files(paper_dir):
        assert filecmp.cmp(paper_dir / name, tmp_path / name, shallow=False), name


def test_interrupt_then_resume_gives_identical_files(paper_dir, tmp_path):
    """SIGINT while trials run, rerun the same command: the same files as an uninterrupted run."""
    env = dict(os.environ)
    proc = subprocess.Popen([CLI, "paper", "--hours", HOURS, "--out", str(tmp_path), "--jobs", "1", "--no-report"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env)
    deadline = time.time() + 60
    while time.time() < deadline and len(trial_files(tmp_path)) < 4:  # the first group is written
        time.sleep(0.01)
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 130, err
    assert "interrupted" in err
    done = trial_files(tmp_path)
    assert 4 <= len(done) < 16
    assert not [p for p in os.listdir(tmp_path) if ".tmp" in p]  # nothing half-written
    for name in done:  # what was finished is final
        assert filecmp.cmp(paper_dir / name, tmp_path / name, shallow=False), name
    run_cli("paper", "--hours", HOURS, "--out", tmp_path, "--jobs", 1, "--no-report", check=True)
    for name in trial_files(paper_dir):
        assert filecmp.cmp(paper_dir / name, tmp_path / name, shallow=False), name
    assert not (tmp_path / ".checkpoints").exists()


def test_single_trial_checkpoint_resume_is_identical(tmp_path):
    args = ["run", "--world", "cross", "--tilt", "60", "--model", "3d-3l", "--hours", "0.5", "--seed", "4"]
    run_cli(*args, "--out", tmp_path / "straight.h5", check=True)
    target = tmp_path / "resumed.h5"
    proc = subprocess.Popen([CLI, *args, "--out", str(target), "--checkpoint-minutes", "1"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    ckpt = tmp_path / "resumed.h5.ckpt"
    deadline = time.time() + 60
    while time.time() < deadline and not ckpt.exists():
        time.sleep(0.005)
    time.sleep(0.05)
    proc.send_signal(signal.SIGINT)
    proc.communicate(timeout=60)
    if proc.returncode == 0:
        pytest.skip("the trial finished before the interrupt arrived")
    assert proc.returncode == 130
    assert ckpt.exists() and not target.exists()
    run_cli(*args, "--out", target, "--checkpoint-minutes", "1", check=True)
    assert filecmp.cmp(tmp_path / "straight.h5", target, shallow=False)
    assert not ckpt.exists()


@pytest.mark.parametrize("args, message", [
    (["paper", "--models", "2d,4d"], "unknown model '4d'"),
    (["paper", "--hours", "-1"], "--hours must be a positive"),
    (["paper", "--seeds", "0"], "--seeds must be >= 1"),
    (["paper", "--tilts", "0,abc"], "'abc' is not a finite number"),
    (["paper", "--tilts", "75"], "pass through the outer walls"),
    (["run", "--world", "atlantis"], "neither a preset"),
    (["run", "--sample-hours", "0"], "sample_hours must be in (0, 10000]"),
    (["run", "--explore-hours", "-2"], "explore_hours must be in [0, 10000]"),
    (["run", "--protocol", "forever"], "protocol 'forever'"),
    (["analyze", "/nonexistent.h5"], "does not exist"),
])
def test_bad_input(tmp_path, args, message):
    out = tmp_path / "out"
    flag = ["--out", str(out / "t.h5")] if args[0] == "run" else (["--out", str(out)] if args[0] == "paper" else [])
    proc = run_cli(*args, *flag)
    assert proc.returncode == 2, proc.stderr
    assert message in proc.stderr
    assert not out.exists() or not any(out.iterdir())


def test_unwritable_output_folder(tmp_path):
    blocker = tmp_path / "file"
    blocker.write_text("x")
    proc = run_cli("paper", "--hours", HOURS, "--out", blocker / "sub")
    assert proc.returncode == 2 and "not a folder" in proc.stderr
    ro = tmp_path / "ro"
    ro.mkdir()
    ro.chmod(0o500)
    if os.access(ro, os.W_OK):  # root ignores permissions
        pytest.skip("running as root: permissions do not block writing")
    proc = run_cli("paper", "--hours", HOURS, "--out", ro / "sub")
    assert proc.returncode == 2 and "cannot create" in proc.stderr


def test_trial_yaml(tmp_path):
    cfg = tmp_path / "trial.yaml"
    cfg.write_text("world: {source: cross, tilt_deg: 30}\nmodel: 3d-0.1\nseed: 3\n"
                   "protocol: {explore_hours: 0.02, sample_hours: 0.02, record_bvc: true}\nanalysis: {extent: arena}\n")
    out = tmp_path / "t.h5"
    run_cli("run", "--config", cfg, "--out", out, check=True)
    with h5py.File(out) as f:
        assert f.attrs["model"] == "3d-0.1" and f.attrs["seed"] == 3 and f.attrs["tilt_deg"] == 30
        assert f["samples/bvc_rates"].shape[1] == 960
        c = f["metrics/bin_centers"][:]
        # Binned over the arena [-5, 5]²: centers sit on its lattice (steps 10/50 in x, 10/28 in y,
        # the second lattice offset by half a step), not on the trajectory's.
        for v, step in ((c[:, 0], 10 / 50), (c[:, 1], 10 / 28)):
            k = (v + 5) / step * 2
            np.testing.assert_allclose(k, np.round(k), atol=1e-6)
    cfg.write_text("world: cross\nmodel: 3d-0.1\nprotocol: {explore_hours: 1, sample_hour: 1}\n")
    proc = run_cli("run", "--config", cfg, "--out", out)
    assert proc.returncode == 2 and "protocol.sample_hour" in proc.stderr and "unknown key" in proc.stderr


def test_python_run_trial_matches_the_cli(tmp_path):
    import bvc3d
    r = bvc3d.run_trial(model="3d-0.1", world="cross", tilt_deg=30, seed=2, explore_hours=0.05, sample_hours=0.05,
                        record_bvc=True)
    n = len(r["t"])
    assert r["rates"].shape == (n, 250) and r["rates"].dtype == np.float32
    assert r["bvc_rates"].shape == (n, 960) and r["weights"].shape == (250, 960)
    out = tmp_path / "t.h5"
    run_cli("run", "--model", "3d-0.1", "--world", "cross", "--tilt", 30, "--seed", 2, "--hours", HOURS, "--out", out,
            check=True)
    with h5py.File(out) as f:
        np.testing.assert_array_equal(f["samples/rates"][:], r["rates"])
        np.testing.assert_array_equal(f["weights"][:], r["weights"])
        for k, v in r["metrics"].items():
            assert v == pytest.approx(f["metrics"].attrs[k], nan_ok=True), k
    assert r["name"] == "cross-30_3d-0.1_seed2"
    with pytest.raises(ValueError, match="unknown model"):
        bvc3d.run_trial(model="4d")
    with pytest.raises(ValueError, match="sample_hours"):
        bvc3d.run_trial(sample_hours=0)


def test_analyze_starts_from_the_files_own_parameters(tmp_path):
    out = tmp_path / "arena.h5"
    run_cli("run", "--tilt", 45, "--hours", HOURS, "--extent", "arena", "--out", out, check=True)
    table = tmp_path / "m.csv"
    run_cli("analyze", out, "--out", table, check=True)
    (row,) = list(csv.DictReader(open(table)))
    with h5py.File(out) as f:
        assert float(row["frac_active"]) == pytest.approx(f["metrics"].attrs["frac_active"])
        assert float(row["n_bins"]) == f["metrics"].attrs["n_bins"]
        np.testing.assert_array_equal(f["metrics/extent"][:], [-5, 5, -5, 5])
    run_cli("analyze", out, "--extent", "data", "--out", table, "--force", check=True)
    (data,) = list(csv.DictReader(open(table)))
    assert data["n_bins"] != row["n_bins"]  # binned over the trajectory instead: another grid


def test_sigterm_checkpoints_like_ctrl_c(tmp_path):
    target = tmp_path / "t.h5"
    proc = subprocess.Popen([CLI, "run", "--model", "3d-3l", "--hours", "0.5", "--out", str(target),
                             "--checkpoint-minutes", "1"], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    ckpt = tmp_path / "t.h5.ckpt"
    deadline = time.time() + 60
    while time.time() < deadline and not ckpt.exists():
        time.sleep(0.005)
    proc.send_signal(signal.SIGTERM)
    _, err = proc.communicate(timeout=60)
    if proc.returncode == 0:
        pytest.skip("the trial finished before the signal arrived")
    assert proc.returncode == 130 and "interrupted" in err
    assert ckpt.exists() and not target.exists()


@pytest.mark.parametrize("args, message", [
    (["run", "--seed", "-1"], "seed"),
    (["walk", "--seed", "1.5"], "seed"),
    (["walk", "--hours", "-1"], "must be a number >= 0"),
    (["scan", "--pose", "1e30,0,0"], "within ±1e6 m"),
    (["run", "--hours", "0.0001"], "fewer than 2 model steps"),
])
def test_more_bad_input(tmp_path, args, message):
    proc = run_cli(*args, *(["--out", str(tmp_path / "t.h5")] if args[0] == "run" else []))
    assert proc.returncode != 0, proc.stderr
    assert message in proc.stderr, proc.stderr
    assert len(proc.stderr) < 400  # a short message, not a wall of digits
