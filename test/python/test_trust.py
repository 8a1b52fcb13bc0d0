"""Faults end cleanly and resume (issue 13): write failures, locks, broken checkpoints, Ctrl-C in
Python, progress lines, seeds over their whole range, summaries that refuse to mix, --extent."""
import csv
import os
import pathlib
import re
import resource
import shutil
import signal
import subprocess
import sys
import textwrap
import time

import h5py
import numpy as np
import pytest

from conftest import CLI, SOURCE_DIR, run_cli

PYTHON = "/usr/bin/python3"
PYTHONPATH = str(pathlib.Path(CLI).parent / "python")


def with_file_limit(limit_bytes):
    """preexec_fn: files of at most `limit_bytes` (RLIMIT_FSIZE); bigger writes fail with EFBIG."""
    def apply():
        resource.setrlimit(resource.RLIMIT_FSIZE, (limit_bytes, limit_bytes))
    return apply


def leftovers(folder):
    """Temporary files an interrupted write could leave."""
    return sorted(p.name for p in pathlib.Path(folder).rglob("*") if ".tmp" in p.name)


def one_error_line(stderr):
    lines = [l for l in stderr.splitlines() if l.startswith("bvc3d: error:")]
    assert len(lines) == 1, stderr
    for sign in ("internal error", "Segmentation", "Traceback", "AddressSanitizer", "HDF5-DIAG"):
        assert sign not in stderr, stderr
    return lines[0]


# ---- write failures -------------------------------------------------------------------------------

def test_trial_file_too_large_is_named_and_a_rerun_resumes(tmp_path):
    out = tmp_path / "t.h5"
    args = ["run", "--hours", "0.02", "--seed", "3", "--out", out, "--checkpoint-minutes", "0"]
    proc = subprocess.run([CLI, *map(str, args)], capture_output=True, text=True,
                          preexec_fn=with_file_limit(100_000))
    assert proc.returncode == 2, proc.stderr
    line = one_error_line(proc.stderr)
    assert f"cannot write '{out}'" in line and "File too large" in line
    assert not out.exists() and leftovers(tmp_path) == []
    run_cli(*args, check=True)
    with h5py.File(out) as f:
        assert f.attrs["format"] == "bvc3d-trial" and f["samples/rates"].shape[0] > 100


def test_checkpoint_write_failure_then_resume_gives_the_same_file(tmp_path):
    """A checkpoint that cannot be written stops the run with its file named; the rerun's file is the
    file of an uninterrupted run."""
    out = tmp_path / "t.h5"
    args = ["run", "--hours", "0.05", "--seed", "4", "--out", out, "--checkpoint-minutes", "1"]
    proc = subprocess.run([CLI, *map(str, args)], capture_output=True, text=True, preexec_fn=with_file_limit(40_000))
    assert proc.returncode == 2, proc.stderr
    line = one_error_line(proc.stderr)
    assert ".ckpt" in line and "File too large" in line
    assert leftovers(tmp_path) == []
    run_cli(*args, check=True)
    reference = tmp_path / "ref.h5"
    run_cli("run", "--hours", "0.05", "--seed", "4", "--out", reference, "--checkpoint-minutes", "0", check=True)
    assert out.read_bytes() == reference.read_bytes()


@pytest.fixture
def small_disk(tmp_path):
    """A 600 kB tmpfs (needs root and mount); skipped where it cannot be made."""
    mount = tmp_path / "disk"
    mount.mkdir()
    if os.geteuid() != 0 or shutil.which("mount") is None:
        pytest.skip("a tmpfs needs root; RLIMIT_FSIZE tests cover the same paths")
    if subprocess.run(["mount", "-t", "tmpfs", "-o", "size=600k", "tmpfs", str(mount)], capture_output=True).returncode:
        pytest.skip("cannot mount a tmpfs here")
    yield mount
    subprocess.run(["umount", str(mount)], check=False)


def test_full_disk_during_an_experiment_is_named_and_resumes(small_disk, tmp_path):
    out = small_disk / "paper"
    args = ["paper", "--hours", "0.02", "--models", "2d", "--tilts", "0,30,45", "--jobs", "1", "--no-report",
            "--out", out]
    proc = run_cli(*args)
    assert proc.returncode == 2, proc.stderr
    line = one_error_line(proc.stderr)
    assert "No space left on device" in line and str(out) in line
    kept = sorted(p.name for p in out.glob("*.h5"))
    assert len(kept) < 3 and leftovers(small_disk) == []
    for name in kept:  # what was written is whole
        with h5py.File(out / name) as f:
            assert f["samples/rates"].shape[0] > 0
    # With space again, the rerun keeps the finished trials and runs the rest.
    moved = tmp_path / "paper"
    shutil.copytree(out, moved)
    proc = run_cli(*args[:-1], moved, check=True)
    assert f"({3 - len(kept)} run, {len(kept)} already complete)" in proc.stdout


def test_figures_that_cannot_be_written_leave_no_half_figure(tmp_path):
    out = tmp_path / "paper"
    run_cli("paper", "--hours", "0.02", "--models", "2d", "--tilts", "0", "--no-report", "--out", out, check=True)
    # Tables fit under the limit, figures do not.
    proc = subprocess.run([CLI, "summarize", str(out)], capture_output=True, text=True,
                          preexec_fn=with_file_limit(20_000))
    assert proc.returncode == 2, proc.stderr
    line = one_error_line(proc.stderr)
    assert "cannot write '" in line and ".png': File too large" in line
    assert "Traceback" not in proc.stderr
    for png in (out / "figures").glob("*.png"):
        assert png.read_bytes().endswith(b"IEND\xaeB`\x82"), f"{png} is half-written"
    assert (out / "trials.csv").exists() and leftovers(out) == []
    run_cli("summarize", out, check=True)  # with room again
    assert len(list((out / "figures").glob("*.png"))) >= 8


# ---- two writers, crashes, broken checkpoints -----------------------------------------------------

def test_a_second_process_on_the_same_folder_stops_and_a_killed_one_leaves_no_stuck_lock(tmp_path):
    out = tmp_path / "paper"
    first = subprocess.Popen([CLI, "paper", "--hours", "1", "--models", "2d", "--tilts", "0", "--no-report",
                              "--out", str(out)],
                             stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    try:
        lock = out / ".bvc3d.lock"
        for _ in range(200):
            if lock.exists() and lock.read_text():
                break
            time.sleep(0.05)
        second = run_cli("paper", "--hours", "1", "--models", "2d", "--tilts", "0", "--no-report", "--out", out)
        assert second.returncode == 2
        line = one_error_line(second.stderr)
        assert f"output folder '{out}' is in use by bvc3d process {first.pid}" in line
        assert run_cli("summarize", out).returncode == 2  # the same lock
    finally:
        first.kill()  # SIGKILL: no chance to clean up
        first.wait()
    again = run_cli("paper", "--hours", "0.02", "--models", "2d", "--tilts", "0", "--no-report", "--out", out)
    assert again.returncode == 0, again.stderr
    assert not (out / ".bvc3d.lock").exists()


def test_two_runs_of_one_trial_file(tmp_path):
    out = tmp_path / "t.h5"
    first = subprocess.Popen([CLI, "run", "--hours", "1", "--out", str(out)], stdout=subprocess.DEVNULL,
                             stderr=subprocess.DEVNULL)
    try:
        for _ in range(200):
            if pathlib.Path(f"{out}.lock").exists():
                break
            time.sleep(0.05)
        second = run_cli("run", "--hours", "1", "--out", out)
        assert second.returncode == 2
        assert f"trial file '{out}' is in use" in one_error_line(second.stderr)
    finally:
        first.kill()
        first.wait()


def interrupted_run(tmp_path, seed):
    """A trial stopped by Ctrl-C once its checkpoint exists."""
    out = tmp_path / "t.h5"
    # All sampling, so that the checkpoint has segments of samples.
    args = [CLI, "run", "--explore-hours", "0", "--sample-hours", "0.3", "--seed", str(seed), "--out", str(out),
            "--checkpoint-minutes", "1"]
    proc = subprocess.Popen(args, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    ckpt = pathlib.Path(f"{out}.ckpt")
    for _ in range(600):
        if ckpt.exists():
            break
        time.sleep(0.05)
    proc.send_signal(signal.SIGINT)
    proc.communicate(timeout=60)
    assert proc.returncode == 130 and ckpt.exists()
    return out, ckpt, args[1:]


@pytest.mark.parametrize("damage", ["truncate", "garbage", "missing segment"])
def test_a_broken_checkpoint_is_named_before_the_trial_restarts(tmp_path, damage):
    out, ckpt, args = interrupted_run(tmp_path, seed=5)
    if damage == "truncate":
        ckpt.write_bytes(ckpt.read_bytes()[:500])
    elif damage == "garbage":
        ckpt.write_bytes(b"\x89HDF\r\n\x1a\n" + b"\0" * 300)
    else:
        pathlib.Path(f"{ckpt}.seg0").unlink()
    proc = run_cli(*args)
    assert proc.returncode == 0, proc.stderr
    # The analysis may warn too (a 0.3 h walk's decoded half lies mostly away from the first half's places).
    warning = [l for l in proc.stderr.splitlines() if l.startswith("bvc3d: warning:") and ": decoding:" not in l]
    assert (len(warning) == 1 and f"checkpoint '{ckpt}'" in warning[0]
            and "starts again from the beginning" in warning[0])
    if damage == "missing segment":
        assert f"{ckpt}.seg0' is missing" in warning[0]
    reference = tmp_path / "ref.h5"
    run_cli("run", "--explore-hours", "0", "--sample-hours", "0.3", "--seed", "5", "--out", reference,
            "--checkpoint-minutes", "0", check=True)
    assert out.read_bytes() == reference.read_bytes()
    assert not ckpt.exists() and not pathlib.Path(f"{ckpt}.seg0").exists()


# ---- Ctrl-C in Python -----------------------------------------------------------------------------

INTERRUPT = textwrap.dedent("""
    import sys, time
    import numpy as np
    import bvc3d
    from bvc3d import analysis
    call = sys.argv[1]
    print("ready", flush=True)
    start = time.monotonic()
    try:
        if call == "run_trial":
            bvc3d.run_trial(explore_hours=50, sample_hours=1)
        elif call == "random_walk":
            bvc3d.random_walk(bvc3d.World.cross(), 800, 0)  # seconds of work; the signal comes at 0.3 s
        else:
            rng = np.random.default_rng(0)  # DBSCAN per cell over 20000 bins with ~600 neighbors each
            analysis.modality(rng.uniform(0, 100, (20000, 2)), np.ones((20000, 300)), eps=10.0, min_samples=5)
        print("finished", flush=True)
    except KeyboardInterrupt:
        print(f"interrupted after {time.monotonic() - start:.2f} s", flush=True)
""")


@pytest.mark.parametrize("call", ["run_trial", "random_walk", "modality"])
def test_ctrl_c_interrupts_long_python_calls(call):
    proc = subprocess.Popen([PYTHON, "-c", INTERRUPT, call], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            env=dict(os.environ, PYTHONPATH=PYTHONPATH))
    assert proc.stdout.readline().strip() == "ready"
    time.sleep(0.3)  # inside the call (each runs for seconds at least)
    sent = time.monotonic()
    proc.send_signal(signal.SIGINT)
    out, err = proc.communicate(timeout=60)
    waited = time.monotonic() - sent
    assert "interrupted after" in out, (out, err)
    # Functional, not a timing test: the call would run for minutes; it came back at once.
    assert waited < 20, waited


# ---- progress, seeds, summaries, extents, memory ------------------------------------------------

def test_non_terminal_runs_print_a_line_per_trial(tmp_path):
    proc = run_cli("paper", "--hours", "0.02", "--models", "2d,3d-0.2", "--tilts", "0,30", "--jobs", "2", "--no-report",
                   "--out", tmp_path / "p", check=True)
    done = [l for l in proc.stderr.splitlines() if l.startswith("bvc3d: ") and "trials done (" in l]
    assert len(done) == 4, proc.stderr
    assert all("simulated hours" in l and "s left" in l for l in done)
    assert "\r" not in proc.stderr
    assert "4/4 trials done, 0.08 simulated hours in" in proc.stderr  # two walks, each shared by two models


def test_the_largest_seed_round_trips(tmp_path):
    seed = 2**64 - 1
    out = tmp_path / "s"
    run_cli("run", "--hours", "0.02", "--seed", seed, "--out", out / "t.h5", check=True)
    with h5py.File(out / "t.h5") as f:
        assert f.attrs["seed"] == seed and f.attrs["seed"].dtype == np.uint64
        assert f.attrs["name"].endswith(f"_seed{seed}")
    run_cli("summarize", out, "--no-report", check=True)
    rows = list(csv.DictReader(open(out / "trials.csv")))
    assert rows[0]["seed"] == str(seed)
    trial = run_cli("analyze", out / "t.h5", check=True)
    assert f"seed{seed}" in trial.stdout
    sweep = tmp_path / "sweep.yaml"
    sweep.write_text(f"grid: {{world.tilt_deg: [0]}}\nseeds: [0, {seed}]\n")
    listed = run_cli("sweep", sweep, "--dry-run", check=True).stdout
    assert f"seed{seed}" in listed


def test_trials_csv_carries_the_protocol_and_durations(tmp_path):
    out = tmp_path / "p"
    run_cli("paper", "--hours", "0.02", "--models", "2d", "--tilts", "0", "--protocol", "online", "--no-report",
            "--out", out, check=True)
    row = list(csv.DictReader(open(out / "trials.csv")))[0]
    assert row["protocol"] == "online" and float(row["explore_hours"]) == 0.02 and float(row["sample_hours"]) == 0.02


def test_summarize_refuses_or_skips_unreadable_files_and_refuses_mixtures(tmp_path):
    out = tmp_path / "p"
    run_cli("paper", "--hours", "0.02", "--models", "2d", "--tilts", "0,30", "--no-report", "--out", out, check=True)
    (out / "junk.h5").write_bytes(b"not a trial")
    refused = run_cli("summarize", out, "--no-report")
    assert refused.returncode == 2
    assert "junk.h5" in one_error_line(refused.stderr) and "--skip-unreadable" in refused.stderr
    skipped = run_cli("summarize", out, "--no-report", "--skip-unreadable", check=True)
    assert "bvc3d: warning: skipping" in skipped.stderr and "junk.h5" in skipped.stderr
    assert len(list(csv.DictReader(open(out / "trials.csv")))) == 2
    (out / "junk.h5").unlink()
    # Another duration in the same folder: refused unless told.
    run_cli("run", "--hours", "0.03", "--model", "2d", "--world", "cross", "--tilt", "45", "--out",
            out / "other.h5", check=True)
    mixed = run_cli("summarize", out, "--no-report")
    assert mixed.returncode == 2 and "differ in" in one_error_line(mixed.stderr)
    run_cli("summarize", out, "--no-report", "--allow-mixed", check=True)
    assert len(list(csv.DictReader(open(out / "trials.csv")))) == 3


def test_extent_is_one_flag_with_the_same_values_everywhere(tmp_path):
    bounds = [-4.0, 4.0, -3.0, 3.0]
    run_cli("run", "--hours", "0.02", "--model", "2d", "--extent", ",".join(map(str, bounds)),
            "--out", tmp_path / "b.h5",
            check=True)
    with h5py.File(tmp_path / "b.h5") as f:
        assert list(f["metrics/extent"][:]) == bounds and "extent: [-4, 4, -3, 3]" in f.attrs["config"]
    run_cli("paper", "--hours", "0.02", "--models", "2d", "--tilts", "0", "--extent", "arena", "--no-report",
            "--out", tmp_path / "p", check=True)
    with h5py.File(tmp_path / "p" / "cross-0_2d_seed0.h5") as f:
        assert list(f["metrics/extent"][:]) == [-5.0, 5.0, -5.0, 5.0]
    for extent in ("arena", "data", "-5,5,-5,5"):
        run_cli("analyze", tmp_path / "b.h5", "--extent", extent, check=True)
    run_cli("analyze", tmp_path / "b.h5", "--extent", "arena", "--out", tmp_path / "arena.csv", check=True)
    run_cli("analyze", tmp_path / "p" / "cross-0_2d_seed0.h5", "--out", tmp_path / "same.csv", check=True)
    arena, same = (open(tmp_path / n).read().splitlines()[0] for n in ("arena.csv", "same.csv"))
    assert arena == same


def test_a_run_that_cannot_fit_in_memory_is_refused_before_it_starts():
    proc = run_cli("run", "--sample-hours", "9000", "--explore-hours", "0")
    assert proc.returncode == 2
    line = one_error_line(proc.stderr)
    assert "this trial needs about" in line and "MemAvailable" in line and "--no-memory-check" in line


def test_the_memory_check_counts_every_recorded_population(tmp_path):
    # A recorded population keeps one float per cell and sample: 800 grid cells recorded must add at least
    # samples × 800 × 4 bytes to the estimate of the same model with them not recorded, and a multiscale model (three
    # place-cell scales and HD cells recorded) at least its scales' rates beyond the paper's 250 cells.
    def needed(model):
        proc = run_cli("run", "--model", model, "--sample-hours", "9000", "--explore-hours", "0")
        assert proc.returncode == 2
        number, unit = re.search(r"needs about ([0-9.]+) ([kMGTPE]?B) of memory", one_error_line(proc.stderr)).groups()
        return float(number) * 1000 ** "BkMGTPE".index(unit[0])

    def with_grid(recorded):
        path = tmp_path / f"grid-{recorded}.yaml"
        path.write_text(f"name: g{recorded}\nbase: 2d\npopulations:\n"
                        f"  - {{name: g, kind: grid, n: 800, recorded: {str(recorded).lower()}}}\n")
        return str(path)

    samples = 9000 * 3600 / 0.288
    assert needed(with_grid(True)) - needed(with_grid(False)) >= samples * 800 * 4 * 0.99  # 3 digits printed
    scales = 2000 + 1000 + 500 + 8  # place, place-m, place-l, hd (the grid modules are not recorded)
    assert needed("ms-2d") - needed("2d") >= samples * (scales - 250) * 4


def test_jobs_zero_means_one_per_core_in_the_help():
    for command in ("paper", "sweep"):
        assert "0 (the default): one per core" in run_cli(command, "--help").stdout


def test_usage_errors_exit_2_with_one_message():
    for args in (["nosuchcommand"], ["run", "--nosuchflag"], ["scan"], ["walk", "--hours"], ["paper", "--jobs", "x"]):
        proc = run_cli(*args)
        assert proc.returncode == 2, (args, proc.returncode)
        assert proc.stderr.startswith("bvc3d: usage error: "), proc.stderr
    assert run_cli("--help").returncode == 0 and run_cli("--version").returncode == 0
