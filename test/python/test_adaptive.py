"""Adaptive elevations: `bvc3d choose-elevations` and `bvc3d.choose_elevations` (docs/adaptive.md).

The oracle for the criterion: the chosen model run as an ordinary trial on the chooser's own walk
(twice: learning, then frozen) through `run_trial` with a trajectory, and its MSAI computed here
with numpy from the returned rates (hexbin bins from matplotlib, the SAI sum written out).
"""
import math
import re

import numpy as np
import pytest
import yaml

import bvc3d
from conftest import CLI, SOURCE_DIR

SETS = "0,0.2;0.1"
ROW = re.compile(r"^\s*(\d+)\s+([-\d., ]+?)\s+(\d+)\s+([-\d.]+|nan)\s+([-\d.]+|nan)\s+([-\d.]+|nan)\s*$")


def printed_table(stdout):
    """{elevations: criterion} from the program's table of candidates."""
    rows = [ROW.match(l) for l in stdout.splitlines()]
    return {tuple(float(v) for v in m.group(2).split(",")): float(m.group(4)) for m in rows if m}


def test_cli_prints_every_candidate_and_writes_the_model_with_the_criterion(cli, tmp_path):
    out = tmp_path / "chosen.yaml"
    res = cli("choose-elevations", "--world", "cross", "--tilt", 45, "--sets", SETS, "--explore-minutes", 4,
              "--seed", 3, "--jobs", 2, "--out", out, check=True)
    table = printed_table(res.stdout)
    assert set(table) == {(0.0, 0.2), (0.1,)}
    text = out.read_text()
    best = min(table, key=table.get)
    assert "criterion (MSAI of the network on the walk): " in text
    crit = float(text.split("criterion (MSAI of the network on the walk): ")[1].split()[0])
    assert crit == pytest.approx(table[best], abs=5e-5)  # the table prints 4 decimals
    model = yaml.safe_load(text)
    assert model["bvc"]["elevations"] == list(best)
    assert model["bvc"]["n_per_axis"] == 960 // (8 * len(best))
    # The written file is a model the program reads.
    cli("config", "--model", out, check=True)


def test_python_binding_matches_the_program(cli, tmp_path):
    res = bvc3d.choose_elevations("cross", 45.0, seed=3, sets=[[0.0, 0.2], [0.1]], jobs=1, explore_minutes=4)
    by_set = {tuple(c["elevations"]): c["msai"] for c in res["candidates"]}
    out = cli("choose-elevations", "--world", "cross", "--tilt", 45, "--sets", SETS, "--explore-minutes", 4,
              "--seed", 3, "--jobs", 1, "--out", tmp_path / "m.yaml", check=True).stdout
    printed = printed_table(out)
    assert set(printed) == set(by_set)
    for key, v in printed.items():
        assert by_set[key] == pytest.approx(v, abs=5e-5)
    assert res["elevations"] == list(min(by_set, key=by_set.get))
    assert yaml.safe_load(res["model_yaml"])["bvc"]["elevations"] == res["elevations"]


def test_validation_script_reads_what_the_program_prints():
    """scripts/adaptive_validation.py (docs/adaptive.md's validation tables and scatter) reads the
    criterion and the BVC population's MSAI of each set from the program's table: the same values
    the Python binding returns, to the 4 printed decimals."""
    import importlib.util

    spec = importlib.util.spec_from_file_location("adaptive_validation",
                                                  SOURCE_DIR / "scripts" / "adaptive_validation.py")
    av = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(av)
    sets = [(0.0, 0.2), (0.1,)]
    read = av.criterion(CLI, 45.0, sets, 3, 4, 1)
    res = bvc3d.choose_elevations("cross", 45.0, seed=3, sets=[list(s) for s in sets], jobs=1, explore_minutes=4)
    assert set(read) == set(sets)
    for c in res["candidates"]:
        crit, bvc_msai = read[tuple(c["elevations"])]
        assert crit == pytest.approx(c["msai"], abs=5e-5) and bvc_msai == pytest.approx(c["bvc_msai"], abs=5e-5)
        assert 0 < c["bvc_msai"] < 1


def numpy_msai(x, y, rates, gridsize=50, q=10.0, d_th=2.0):
    """MSAI as docs/analysis.md defines it, from matplotlib's hexbin and numpy alone."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    maps = []
    fig, ax = plt.subplots()
    for c in range(rates.shape[1]):
        hb = ax.hexbin(x, y, C=rates[:, c].astype(np.float64), gridsize=gridsize, reduce_C_function=np.mean)
        v = np.ma.getdata(hb.get_array()).astype(np.float64)
        centers = hb.get_offsets().copy()
        hb.remove()
        v[v < np.percentile(v, q)] = 0
        m = v.max()
        maps.append(v / m if m > 0 else v)
    plt.close(fig)
    a = np.array(maps).T  # bins × cells
    norm = np.linalg.norm(a, axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        cos = (a @ a.T) / np.outer(norm, norm)
    cos[~np.isfinite(cos)] = 0
    far = np.linalg.norm(centers[:, None, :] - centers[None, :, :], axis=2) > d_th
    return float((cos * far).sum(axis=1).mean() / len(a))


def test_criterion_against_numpy_on_the_walk_run_as_a_trial(tmp_path):
    res = bvc3d.choose_elevations("cross", 60.0, seed=2, sets=[[0.0, 0.3]], jobs=1, explore_minutes=3)
    walk = bvc3d.random_walk(bvc3d.World.cross(tilt_deg=60.0), 3 / 60, 2)
    t = np.asarray(walk["t"]) - walk["t"][0]
    period = t[-1] + (t[-1] - t[-2])
    both = {k: np.concatenate([np.asarray(walk[k])] * 2) for k in ("x", "y", "heading")}
    both["t"] = np.concatenate([t, t + period])
    last, before = t[-1], t[-2]
    model = tmp_path / "chosen.yaml"
    model.write_text(res["model_yaml"])
    trial = bvc3d.run_trial(str(model), "cross", 60.0, seed=2, trajectory=both, record_bvc=True,
                            explore_hours=0.5 * (last + before) / 3600, sample_hours=2 * (last + 1) / 3600)
    assert len(trial["x"]) == len(t)
    assert numpy_msai(trial["x"], trial["y"], trial["rates"]) == pytest.approx(res["msai"], rel=1e-9, abs=1e-12)
    # Beside it, the BVC population's aliasing: the same index over the BVCs' rate maps.
    bvc_msai = res["candidates"][0]["bvc_msai"]
    assert numpy_msai(trial["x"], trial["y"], trial["bvc_rates"]) == pytest.approx(bvc_msai, rel=1e-9, abs=1e-12)
    assert bvc_msai > res["msai"]  # BVCs fire along every wall at their distance: they alias more


@pytest.mark.parametrize("args, words", [
    (["--budget", "40", "--layers", "1-4"], "too small for 4 layers"),
    (["--min-elevation", "0.3", "--max-elevation", "0.1"], "empty candidate range"),
    (["--explore-minutes", "0.05"], "explore longer"),
    (["--layers", "3-2"], "exceeds max_layers"),
    (["--layers", "two"], "--layers"),
    (["--agent", "submarine"], "--agent"),
    (["--sets", "0,0.2;;0.1"], "empty set"),
    (["--sensor", "no-such-sensor"], "no-such-sensor"),
])
def test_bad_input_is_refused_with_exit_2_and_no_file(cli, tmp_path, args, words):
    out = tmp_path / "m.yaml"
    res = cli("choose-elevations", "--world", "cross", "--tilt", 30, *args, "--out", out)
    assert res.returncode == 2, res.stderr
    assert words in res.stderr
    assert not out.exists()
    assert not list(tmp_path.iterdir())


def test_python_bad_input_raises_input_error():
    with pytest.raises(bvc3d.InputError, match="empty candidate range"):
        bvc3d.choose_elevations("cross", 30.0, elevation_min=0.3, elevation_max=0.1)
    with pytest.raises(bvc3d.InputError, match="unknown argument"):
        bvc3d.choose_elevations("cross", 30.0, elevations_max=0.1)
    assert math.isfinite(bvc3d.choose_elevations("cross", 30.0, sets=[[0.0]], explore_minutes=3, jobs=1)["msai"])


def test_flying_criterion_against_numpy_voxels_on_the_flight_run_as_a_trial(tmp_path):
    """A flying agent's chooser scores each set on the flight volume's 0.5 m voxels: the chosen model
    run on the chooser's own flight (twice, as a trajectory) and its MSAI computed here in numpy."""
    from numpy_oracles import numpy_rate_maps
    from test_flying import VOLUME, numpy_voxel_means, sai_brute3

    res = bvc3d.choose_elevations("flight-room", agent="flying", seed=2, sets=[[-0.2, 0.2]], jobs=1,
                                  explore_minutes=3)
    assert yaml.safe_load(res["model_yaml"])["sensor"]["name"] == "spherical-full"
    walk = bvc3d.flying_walk(bvc3d.World.preset("flight-room"), 3 / 60, 2)
    assert len(walk["x"]) == res["walk_steps"] and np.ptp(walk["z"]) > 0.5
    t = np.asarray(walk["t"]) - walk["t"][0]
    period = t[-1] + (t[-1] - t[-2])
    both = {k: np.concatenate([np.asarray(walk[k])] * 2) for k in ("x", "y", "z", "heading")}
    both["t"] = np.concatenate([t, t + period])
    model = tmp_path / "chosen.yaml"
    model.write_text(res["model_yaml"])
    trial = bvc3d.run_trial(str(model), "flight-room", seed=2, trajectory=both,
                            explore_hours=0.5 * (t[-1] + t[-2]) / 3600, sample_hours=2 * (t[-1] + 1) / 3600)
    np.testing.assert_array_equal(trial["z"], walk["z"])
    p = np.column_stack([walk["x"], walk["y"], walk["z"]])
    centers, means, _ = numpy_voxel_means(p, trial["rates"], 0.5, VOLUME)
    maps = numpy_rate_maps(means, 0.1)
    assert np.mean(sai_brute3(centers, maps, 2.0)) == pytest.approx(res["msai"], rel=1e-9, abs=1e-12)
    # The ground robot cannot explore a flight-only world.
    with pytest.raises(bvc3d.InputError, match="flight-only"):
        bvc3d.choose_elevations("flight-room", sets=[[0.0]], explore_minutes=3)


def test_cli_flying_candidates_look_down_as_far_as_up(cli, tmp_path):
    out = tmp_path / "fly.yaml"
    res = cli("choose-elevations", "--agent", "flying", "--world", "flight-room", "--sets", "-0.2,0.2;0",
              "--explore-minutes", 3, "--jobs", 1, "--out", out, check=True)
    assert "candidate elevations -0.4, -0.35," in res.stdout and ", 0.35, 0.4 rad" in res.stdout
    assert set(printed_table(res.stdout)) == {(-0.2, 0.2), (0.0,)}
    assert "agent flying, sensor spherical-full" in out.read_text()
    cli("config", "--model", out, check=True)


HALL = SOURCE_DIR.parent / "shared" / "data" / "hall-lidar"


@pytest.mark.skipif(not (HALL / "poses.csv").exists(), reason=f"the hall-lidar recording is not at {HALL}")
def test_choice_on_a_recording_against_its_replay(cli, tmp_path):
    """On recorded scans the recording is the walk: the criterion of a set is the MSAI of the network
    replayed over the scans learning, then frozen. Oracle: `bvc3d replay --learn`, then a frozen
    `bvc3d replay` from those weights, MSAI in numpy. Not bit-equal: in the chooser the network's
    activity carries over from the first pass into the second, while the frozen replay starts at rest."""
    rec = ["--scans", HALL, "--poses", HALL / "poses.csv"]
    out = tmp_path / "hall.yaml"
    res = cli("choose-elevations", *rec, "--sets", "0,0.2;0.1", "--jobs", 2, "--out", out, check=True)
    table = printed_table(res.stdout)
    assert set(table) == {(0.0, 0.2), (0.1,)}
    assert "recording" in out.read_text() and "(60 scans)" in out.read_text()
    # Threads do not change the result (each has its own reader of the scans).
    again = cli("choose-elevations", *rec, "--sets", "0,0.2;0.1", "--jobs", 1, "--out", tmp_path / "b.yaml", check=True)
    assert printed_table(again.stdout) == table

    one = tmp_path / "one.yaml"
    cli("choose-elevations", *rec, "--sets", "0,0.2", "--out", one, check=True)
    cli("replay", *rec, "--model", one, "--learn", "--out", tmp_path / "learn.h5", check=True)
    cli("replay", *rec, "--model", one, "--weights", tmp_path / "learn.h5", "--out", tmp_path / "frozen.h5", check=True)
    import h5py
    with h5py.File(tmp_path / "frozen.h5", "r") as f:
        x, y, rates = f["samples/x"][:], f["samples/y"][:], f["samples/rates"][:]
    crit = float(one.read_text().split("criterion (MSAI of the network on the walk): ")[1].split()[0])
    assert crit == pytest.approx(table[(0.0, 0.2)], abs=5e-5)  # the table prints 4 decimals
    assert numpy_msai(x, y, rates) == pytest.approx(crit, rel=2e-3)

    # Python: the same choice on the same recording.
    py = bvc3d.choose_elevations(recording=bvc3d.Recording.open(HALL, HALL / "poses.csv"), sets=[[0.0, 0.2], [0.1]],
                                 jobs=1, max_range=20.0)
    assert {tuple(c["elevations"]): c["msai"] for c in py["candidates"]} == pytest.approx(table, abs=5e-5)
    assert py["walk_steps"] == 60
    with pytest.raises(bvc3d.InputError, match="not both"):
        bvc3d.choose_elevations("cross", recording=bvc3d.Recording.open(HALL, HALL / "poses.csv"))
    with pytest.raises(bvc3d.InputError, match="unknown argument 'max_rnage'"):
        bvc3d.choose_elevations(recording=bvc3d.Recording.open(HALL, HALL / "poses.csv"), max_rnage=3.0)

    # A recording is its own walk: no world or agent beside it, and poses need scans.
    for args, words in ((rec + ["--world", "cross"], "not both"),
                        (["--poses", HALL / "poses.csv"], "--poses needs --scans")):
        bad = tmp_path / "bad.yaml"
        r = cli("choose-elevations", *args, "--out", bad)
        assert r.returncode == 2 and words in r.stderr and not bad.exists()
