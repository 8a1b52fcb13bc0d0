"""A user's trajectory is resampled to the model step (issue 32, finding 3): the place cells' time
constant and Oja's rate are per step, so rows every 0.05 s stepped once per row would run the dynamics
5.76 times as fast per second as the paper's 0.288 s step. The steps the model takes are checked
against an independent numpy interpolation (np.interp of positions, of np.unwrap'ed headings); rows at
the model step already (as `bvc3d walk` writes them) run bit for bit as they did before; the option
step_per_row (CLI, trial YAML, Python) steps once per row."""
import h5py
import numpy as np
import pytest

from conftest import run_cli

bvc3d = pytest.importorskip("bvc3d")
MODEL_DT = 0.288


def wrap(a):
    return (a + np.pi) % (2 * np.pi) - np.pi


def fast_track(n=600, dt=0.05, seed=1):
    """A wandering path in the cross arena sampled every `dt` s, its heading turning through ±π."""
    rng = np.random.default_rng(seed)
    t = 1.7e9 + np.arange(n) * dt  # Unix times: shifted to start at 0
    x = -3 + np.cumsum(rng.uniform(0, 0.02, n))
    y = -3 + 1.5 * np.sin(np.arange(n) / 40)
    heading = wrap(np.pi - 0.2 + np.arange(n) * 0.013 + rng.normal(0, 0.05, n))
    return {"t": t, "x": x, "y": y, "heading": heading}


def numpy_resampled(track, dt=MODEL_DT):
    t = track["t"] - track["t"][0]
    tk = np.arange(int(np.floor(t[-1] / dt + 1e-9)) + 1) * dt
    return {"t": tk, "x": np.interp(tk, t, track["x"]), "y": np.interp(tk, t, track["y"]),
            "heading": wrap(np.interp(tk, t, np.unwrap(track["heading"])))}


def write_track(path, track):
    cols = [track[k] for k in ("t", "x", "y", "heading")]
    np.savetxt(path, np.column_stack(cols), delimiter=",", header="t,x,y,heading", comments="", fmt="%.17g")


def samples(path):
    with h5py.File(path) as f:
        return {k: f["samples"][k][:] for k in ("t", "x", "y", "heading", "rates")}, f.attrs["config"]


def run_track(tmp_path, csv, name, *extra):
    out = tmp_path / f"{name}.h5"
    proc = run_cli("run", "--trajectory", csv, "--protocol", "online", "--sample-hours", "1", "--model", "2d",
                   "--out", out, "--checkpoint-minutes", "0", *extra)
    assert proc.returncode == 0, proc.stderr
    return proc, *samples(out)


def assert_steps_match(got, expected):
    n = len(expected["t"])
    assert len(got["t"]) == n
    np.testing.assert_allclose(got["t"], expected["t"], rtol=0, atol=1e-9)
    np.testing.assert_allclose(got["x"], expected["x"], rtol=0, atol=1e-9)
    np.testing.assert_allclose(got["y"], expected["y"], rtol=0, atol=1e-9)
    np.testing.assert_allclose(wrap(got["heading"] - expected["heading"]), 0, atol=1e-9)


def test_run_resamples_a_fast_track_to_the_model_step(tmp_path):
    track = fast_track()
    csv = tmp_path / "fast.csv"
    write_track(csv, track)
    proc, got, config = run_track(tmp_path, csv, "fast")
    expected = numpy_resampled(track)
    assert_steps_match(got, expected)
    assert len(expected["t"]) == 104  # 29.95 s of rows: steps at 0, 0.288, ..., 29.664 s
    note = f"600 rows every 0.05 s (median), resampled to {len(expected['t'])} model steps of 0.288 s"
    assert note in proc.stderr and note in proc.stdout, (proc.stderr, proc.stdout)
    assert "resampled_to: 0.288" in config


def test_step_per_row_steps_once_per_row(tmp_path):
    track = fast_track()
    csv = tmp_path / "fast.csv"
    write_track(csv, track)
    proc, got, config = run_track(tmp_path, csv, "rows", "--step-per-row")
    np.testing.assert_array_equal(got["x"], track["x"])
    np.testing.assert_allclose(got["t"], track["t"] - track["t"][0], atol=1e-6)
    assert "one model step per row (step_per_row)" in proc.stderr and "5.76 times as fast" in proc.stderr
    assert "resampled_to" not in config
    # The same from a trial YAML: trajectory as a mapping with the option's key.
    yaml = tmp_path / "trial.yaml"
    yaml.write_text("model: 2d\ntrajectory:\n  file: fast.csv\n  step_per_row: true\n"
                    "protocol:\n  kind: online\n  sample_hours: 1\n")
    out = tmp_path / "yaml.h5"
    run_cli("run", "--config", yaml, "--out", out, "--checkpoint-minutes", "0", check=True)
    from_yaml, _ = samples(out)
    np.testing.assert_array_equal(from_yaml["rates"], got["rates"])


def test_a_track_at_the_model_step_runs_as_before(tmp_path):
    """`bvc3d walk` writes rows at the model step (turns and bumps between them): they are the steps,
    bit for bit, resampled or not, and the trial's configuration text is what it always was."""
    walk = tmp_path / "walk.csv"
    run_cli("walk", "--hours", "0.01", "--seed", "4", "--out", walk, check=True)
    rows = np.genfromtxt(walk, delimiter=",", names=True)
    proc, default, config = run_track(tmp_path, walk, "default")
    assert "note" not in proc.stderr and "resampled" not in config
    _, per_row, config_per_row = run_track(tmp_path, walk, "per_row", "--step-per-row")
    for k in default:
        np.testing.assert_array_equal(default[k], per_row[k])
    assert config == config_per_row
    np.testing.assert_array_equal(default["x"], rows["x"][:len(default["x"])])


def test_python_run_trial_resamples_and_takes_step_per_row():
    track = fast_track(n=300, dt=0.02, seed=3)
    kw = dict(model="2d", protocol="online", sample_hours=1)
    r = bvc3d.run_trial(trajectory=track, **kw)
    assert_steps_match(r, numpy_resampled(track))
    r = bvc3d.run_trial(trajectory=track, model_dt=0.5, **kw)
    assert_steps_match(r, numpy_resampled(track, 0.5))
    r = bvc3d.run_trial(trajectory=track, step_per_row=True, **kw)
    np.testing.assert_array_equal(r["x"], track["x"])
    with pytest.raises(ValueError, match="step_per_row= goes with trajectory="):
        bvc3d.run_trial(step_per_row=True, **kw)
    with pytest.raises(ValueError, match="model_dt"):
        bvc3d.run_trial(trajectory=track, model_dt=0, **kw)


def test_bad_options_and_spans_are_refused(tmp_path):
    csv = tmp_path / "t.csv"
    csv.write_text("t,x,y,heading\n0,0,0,0\n0.1,0.1,0,0\n1e9,0.2,0,0\n")
    proc = run_cli("run", "--trajectory", csv, "--out", tmp_path / "t.h5")
    assert proc.returncode == 2 and f"trajectory '{csv}'" in proc.stderr and "more than the limit" in proc.stderr
    proc = run_cli("run", "--step-per-row", "--out", tmp_path / "t.h5")
    assert proc.returncode == 2 and "--step-per-row goes with --trajectory" in proc.stderr
    yaml = tmp_path / "trial.yaml"
    yaml.write_text("trajectory:\n  file: t.csv\n  step_per_row: maybe\n")
    proc = run_cli("run", "--config", yaml, "--out", tmp_path / "t.h5")
    assert proc.returncode == 2 and "trajectory.step_per_row" in proc.stderr, proc.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["t.csv", "trial.yaml"]


def test_simulated_replay_resamples(tmp_path):
    track = fast_track(n=120, dt=0.1)
    r = bvc3d.replay_simulated("cross", track, "horizontal", model="2d")
    assert_steps_match(r, numpy_resampled(track))
    r = bvc3d.replay_simulated("cross", track, "horizontal", model="2d", step_per_row=True)
    np.testing.assert_array_equal(r["x"], track["x"])
