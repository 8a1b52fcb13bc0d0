"""Issue 32: weights are loaded only into the model that trained them (finding 'place-cell weights of
another model accepted because the shapes agree'), and place-cell metrics are written only where the
place cells learned (finding 5: a frozen replay with the seed's random weights wrote 'decoding median
12.84 m')."""
import h5py
import numpy as np
import pytest

from conftest import run_cli

bvc3d = pytest.importorskip("bvc3d")
METRICS = ("frac_active", "msai", "decode_median_m")


@pytest.fixture(scope="module")
def trained(tmp_path_factory):
    """A short 3d-0.1 trial (learning on) and a track at the model step in the cross arena."""
    folder = tmp_path_factory.mktemp("weights")
    out = folder / "trained.h5"
    run_cli("run", "--model", "3d-0.1", "--protocol", "online", "--sample-hours", "0.01", "--out", out,
            "--checkpoint-minutes", "0", check=True)
    track = folder / "track.csv"
    t = np.arange(40) * 0.288
    track.write_text("t,x,y,heading\n" + "".join(f"{a},{-4 + 0.1 * i},-3,0.3\n" for i, a in enumerate(t)))
    return out, track


def test_weights_record_their_model(trained):
    out, _ = trained
    with h5py.File(out) as f:
        assert f["weights"].attrs["model"] == "3d-0.1"
        assert "elevations: [0, 0.1]" in f["weights"].attrs["model_config"]
        assert f.attrs["place_weights"] == "learned"
        assert all(k in f["metrics"].attrs for k in METRICS)


def test_weights_of_another_model_are_refused(trained, tmp_path):
    out, track = trained
    replay = ["replay", "--world", "cross", "--trajectory", track, "--sensor", "spherical", "--weights", out]
    proc = run_cli(*replay, "--model", "3d-0.2", "--out", tmp_path / "r.h5")
    assert proc.returncode == 2, proc.stderr
    assert f"weights from '{out}' were trained by model '3d-0.1'" in proc.stderr
    assert "bvc.elevations is [0, 0.1] in the model that trained them, [0, 0.2] here" in proc.stderr
    assert not (tmp_path / "r.h5").exists()
    with pytest.raises(ValueError, match=r"trained by model '3d-0.1'.*bvc\.elevations"):
        bvc3d.replay_simulated("cross", str(track), "spherical", model="3d-0.2", weights=str(out))
    # The model that trained them takes them, frozen: the replay's weights are the file's.
    proc = run_cli(*replay, "--model", "3d-0.1", "--out", tmp_path / "ok.h5")
    assert proc.returncode == 0, proc.stderr
    with h5py.File(out) as a, h5py.File(tmp_path / "ok.h5") as b:
        np.testing.assert_array_equal(a["weights"][:], b["weights"][:])
        assert b.attrs["place_weights"] == "trained" and b.attrs["place_weights_source"] == str(out)
        assert all(k in b["metrics"].attrs for k in METRICS)


def test_files_without_a_recorded_model_are_checked_by_shape_only(trained, tmp_path):
    out, track = trained
    old = tmp_path / "old.h5"
    old.write_bytes(out.read_bytes())
    with h5py.File(old, "r+") as f:  # no model recorded anywhere: not on /weights, not on the root (issue 43, 13)
        del f["weights"].attrs["model"]
        del f["weights"].attrs["model_config"]
        del f.attrs["model"]
        del f.attrs["config"]
    r = bvc3d.replay_simulated("cross", str(track), "spherical", model="3d-0.2", weights=str(old))
    assert r["rates"].shape[1] == 250


def test_untrained_place_cells_write_no_metrics(trained, tmp_path):
    _, track = trained
    out = tmp_path / "frozen.h5"
    proc = run_cli("replay", "--world", "cross", "--trajectory", track, "--sensor", "spherical", "--model", "3d-0.2",
                   "--out", out)
    assert proc.returncode == 0, proc.stderr
    assert "place_weights: untrained" in proc.stdout
    with h5py.File(out) as f:
        assert f.attrs["place_weights"] == "untrained"
        assert not any(k in f["metrics"].attrs for k in METRICS)
        assert f["samples/rates"].shape[0] == 40  # the rates are still recorded
    proc = run_cli("analyze", out)
    assert proc.returncode == 0 and "no place-cell metrics" in proc.stdout and "decode_median_m" not in proc.stdout
    # The same class in `run` and Python: no exploration and no weights given.
    proc = run_cli("run", "--explore-hours", "0", "--sample-hours", "0.005", "--out", tmp_path / "r.h5",
                   "--checkpoint-minutes", "0")
    assert proc.returncode == 0 and "no place-cell metrics" in proc.stdout and "msai" not in proc.stdout
    r = bvc3d.run_trial(explore_hours=0, sample_hours=0.005)
    assert r["metrics"] == {} and r["place_weights"] == "untrained"
    r = bvc3d.run_trial(explore_hours=0.002, sample_hours=0.005)
    assert "msai" in r["metrics"] and r["place_weights"] == "learned"
