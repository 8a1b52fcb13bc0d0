"""Sweeps on local threads and over MPI ranks (issue 7)."""
import csv
import os
import shutil
import signal
import subprocess
import time

import pytest

from conftest import CLI, SOURCE_DIR, run_cli

TINY = SOURCE_DIR / "test/data/tiny-sweep.yaml"
MPIRUN = shutil.which("mpirun")
needs_mpi = pytest.mark.skipif(MPIRUN is None, reason="mpirun not installed")


def mpirun(n, *args, **kw):
    return subprocess.run([MPIRUN, "--allow-run-as-root", "--oversubscribe", "-np", str(n), CLI, *map(str, args)],
                          capture_output=True, text=True, **kw)


def rows(path):
    return list(csv.DictReader(open(path)))


@pytest.fixture(scope="module")
def threads_only(tmp_path_factory):
    out = tmp_path_factory.mktemp("sweep")
    run_cli("sweep", TINY, "--out", out, "--jobs", 2, check=True)
    return out


def test_tables_and_figures(threads_only):
    trials = rows(threads_only / "trials.csv")
    assert len(trials) == 10  # (2 elevations x 2 tilts + 1 listed) x 2 seeds
    conditions = rows(threads_only / "summary.csv")
    assert len(conditions) == 5
    assert all(c["n_seeds"] == "2" for c in conditions)
    assert [c["swept:world.tilt_deg"] for c in conditions] == ["30", "60", "30", "60", "60"]
    assert conditions[-1]["swept:model"] == "2d" and conditions[0]["swept:model"] == ""
    assert conditions[0]["model"] == "3d-0.2-custom"
    for metric in ("frac_active", "mean_mi_active", "frac_multimodal", "msai", "decode_median_m"):
        assert (threads_only / "figures" / f"sweep_{metric}.png").stat().st_size > 1000
    assert "sweep_msai.png" in (threads_only / "report.md").read_text()
    # Metrics of flying agents' trials have no value in a ground sweep: no empty figures for them.
    assert not any((threads_only / "figures" / f"sweep_{m}.png").exists()
                   for m in ("isotropy_median", "frac_unimodal", "decode_vertical_median_m"))
    assert (threads_only / "sweep.yaml").read_text() == TINY.read_text()


def test_dry_run_lists_the_trials():
    out = run_cli("sweep", TINY, "--dry-run", check=True).stdout.splitlines()
    assert out[-1] == "10 trials"
    assert "c004_model=2d_tilt_deg=60_seed1" in out


@needs_mpi
@pytest.mark.parametrize("ranks", [2, 3])
def test_mpi_runs_every_trial_once_with_the_same_summary(threads_only, tmp_path, ranks):
    proc = mpirun(ranks, "sweep", TINY, "--out", tmp_path, "--no-report", "--verbose", timeout=300)
    assert proc.returncode == 0, proc.stderr
    ran = [line.split(": ")[1] for line in proc.stdout.splitlines() if line.startswith("rank ")]
    assert sorted(ran) == sorted(r["name"] for r in rows(threads_only / "trials.csv"))  # each exactly once
    assert len({line.split(":")[0] for line in proc.stdout.splitlines() if line.startswith("rank ")}) > 1
    assert (tmp_path / "summary.csv").read_text() == (threads_only / "summary.csv").read_text()
    assert (tmp_path / "trials.csv").read_text() == (threads_only / "trials.csv").read_text()


@needs_mpi
def test_killed_rank_loses_only_its_trials(tmp_path):
    ref = tmp_path / "ref"
    run_cli("sweep", TINY, "--out", ref, "--hours", "0.15", "--no-report", "--jobs", 2, check=True)
    out = tmp_path / "mpi"
    proc = subprocess.Popen([MPIRUN, "--allow-run-as-root", "--oversubscribe", "-np", "2", CLI, "sweep", str(TINY),
                             "--out", str(out), "--hours", "0.15", "--no-report"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    deadline = time.time() + 120
    while time.time() < deadline and not (out.exists() and any(p.suffix == ".h5" for p in out.iterdir())):
        time.sleep(0.02)
    children = subprocess.run(["pgrep", "-P", str(proc.pid)], capture_output=True, text=True).stdout.split()
    assert children, "mpirun has no rank processes"
    os.kill(int(children[-1]), signal.SIGKILL)
    proc.communicate(timeout=120)
    done = [p for p in out.iterdir() if p.suffix == ".h5"]
    assert proc.returncode != 0 and 1 <= len(done) < 10
    proc = mpirun(2, "sweep", TINY, "--out", out, "--hours", "0.15", "--no-report", timeout=300)
    assert proc.returncode == 0, proc.stderr
    assert (out / "summary.csv").read_text() == (ref / "summary.csv").read_text()


BAD = {
    "wurst: 1\ngrid: {world.tilt_deg: [0]}\n": ("wurst", "unknown key"),
    "grid: {world.tilt_deg: []}\n": ("grid.world.tilt_deg", "empty grid"),
    "grid: {world.tilt_deg: 30}\n": ("grid.world.tilt_deg", "expected a list"),
    "grid: {world.tilt_deg: [zero]}\n": ("world.tilt_deg", "expected a number"),
    "grid: {model.bvc.sigma_phi: [0.01, -1]}\n": ("model.bvc.sigma_phi", "must be > 0"),
    "grid: {model.bvc.colour: [1]}\n": ("model.bvc.colour", "unknown key"),
    "base: {model: 3d-0.2}\n": ("", "needs a 'grid' and/or a 'list'"),
    "grid: {world.tilt_deg: [10]}\nseeds: 0\n": ("seeds", "must be >= 1"),
    "grid: {model: [2d, 5d]}\n": ("model", "unknown model '5d'"),
    "list: [3]\n": ("list[0]", "mapping of keys to values"),
}


@pytest.mark.parametrize("text", sorted(BAD))
def test_bad_sweep_files(tmp_path, text):
    key, reason = BAD[text]
    f = tmp_path / "bad.yaml"
    f.write_text(text)
    proc = run_cli("sweep", f, "--out", tmp_path / "out")
    assert proc.returncode == 2, proc.stderr
    assert str(f) in proc.stderr and key in proc.stderr and reason in proc.stderr, proc.stderr
    assert not (tmp_path / "out").exists()


def test_robot_settings_get_their_own_walks(tmp_path):
    f = tmp_path / "speed.yaml"
    f.write_text("base: {model: 2d, world: {source: cross, tilt_deg: 0}}\ngrid: {robot.speed: [0.5, 1.0]}\n")
    run_cli("sweep", f, "--out", tmp_path / "out", "--hours", "0.02", "--no-report", check=True)
    import h5py
    import numpy as np
    steps = {}
    for p in (tmp_path / "out").glob("*.h5"):
        with h5py.File(p) as h:
            x, y, bumped = (h["samples/x"][:], h["samples/y"][:],
                            h["samples/bumped"][:] if "bumped" in h["samples"] else None)
            d = np.hypot(np.diff(x), np.diff(y))
            steps[p.name.split("_seed")[0].split("=")[-1]] = np.median(d)
    assert steps["0.5"] == pytest.approx(0.144, abs=1e-6)
    assert steps["1.0"] == pytest.approx(0.288, abs=1e-6)


def test_seed_is_not_a_grid_key(tmp_path):
    f = tmp_path / "s.yaml"
    f.write_text("grid: {seed: [1, 2]}\n")
    proc = run_cli("sweep", f)
    assert proc.returncode == 2 and "list them under 'seeds:'" in proc.stderr
