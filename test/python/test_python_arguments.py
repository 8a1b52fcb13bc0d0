"""Python arguments (issue 32, finding 7 and the class "Python"): run_trial's arguments each refused
by name or taken (bvc=, place=, analysis=), analysis parameters that cannot work at an arena's
scale warned about, sizes without a limit refused, scan indices past the end named, boolean arrays
refused wherever the docs say arrays hold real numbers."""
import warnings

import numpy as np
import pytest

import bvc3d
import bvc3d.analysis as an
from conftest import run_cli

SHORT = dict(explore_hours=0.01, sample_hours=0.02)


def test_a_world_built_in_python_is_refused_by_name():
    """A trial records where its world came from: a World made from a preset or a file is that source (issue
    43); one built in Python has none, and the message says what to give instead."""
    built = bvc3d.World.from_dict({"objects": [{"box": {"center": [0, 3, 1], "size": [6, 0.2, 2]}}],
                                   "walkable": {"rect": [-3, -3, 3, 3]}})
    with pytest.raises(ValueError, match=r"run_trial: world: this World was built in Python .* a preset name or a "
                                         r"world file"):
        bvc3d.run_trial(world=built)
    with pytest.raises(ValueError, match=r"world must be a World, a preset name or a world file's path, not int"):
        bvc3d.run_trial(world=3)
    with pytest.raises(ValueError, match=r"'tilt_deg' must be a number"):
        bvc3d.run_trial(tilt_deg="45")
    with pytest.raises(ValueError, match=r"model= must be .* not list"):
        bvc3d.run_trial(model=["3d-0.2"])


@pytest.mark.parametrize("kwargs, expect", [
    (dict(eps=0.5), r"'eps' is an analysis parameter: give analysis=dict\(eps=...\)"),
    (dict(n_per_axis=8), r"'n_per_axis' is a model parameter: give bvc=dict\(n_per_axis=...\)"),
    (dict(sensor="horizontal"), r"'sensor' is not a keyword of run_trial: .*model YAML"),
    (dict(frobnicate=1), r"unknown argument 'frobnicate' \(accepted: model, world, tilt_deg, seed, .*analysis"),
    (dict(bvc=[8]), r"bvc= must be a dict of keywords"),
    (dict(bvc=dict(colour=1)), r"BVC layer: unknown argument 'colour'"),
    (dict(analysis=dict(eps=-1)), r"analysis: eps must be in \(0, 1e\+06\], got -1"),
    (dict(authors_choices="all"), r"authors_choices= must be a list of names"),
    (dict(agent="flight", flight=0.5), r"flight= must be a dict of keywords"),
])
def test_every_wrong_argument_is_named(kwargs, expect):
    with pytest.raises(ValueError, match=expect):
        bvc3d.run_trial(**kwargs)


def test_bvc_and_place_parameters_change_the_model():
    r = bvc3d.run_trial(bvc=dict(n_per_axis=8), place=dict(n_place=40), **SHORT)
    preset = bvc3d.BoundaryVectorLayer.preset("3d-0.2")
    layer = bvc3d.BoundaryVectorLayer(elevations=list(preset.elevations), n_dir=preset.n_dir, n_per_axis=8)
    assert r["weights"].shape == (40, layer.n_cells)
    assert r["rates"].shape[1] == 40
    assert "3d-0.2-custom" in r["name"]


def test_analysis_parameters_are_those_the_metrics_use():
    params = dict(eps=0.4, min_samples=5, d_th=0.7, gridsize=30)
    r = bvc3d.run_trial(analysis=params, **SHORT)
    # The oracle: the same samples through the Python analysis with the same parameters.
    ref = an.analyze(r["x"], r["y"], r["rates"], **params)
    assert r["metrics"]["msai"] == pytest.approx(ref["msai"], rel=1e-9)
    assert r["metrics"]["frac_multimodal"] == pytest.approx(ref["modality_summary"]["frac_multimodal"])
    default = bvc3d.run_trial(**SHORT)
    assert default["metrics"]["msai"] != pytest.approx(r["metrics"]["msai"])


def box_walk(side, steps=3000, seed=0):
    """A path that covers a square of `side` metres in the middle of the cross arena."""
    rng = np.random.default_rng(seed)
    xy = np.cumsum(rng.normal(0, side / 20, (steps, 2)), axis=0)
    xy = np.abs((xy + side) % (2 * side) - side) - side / 2  # folded into [-side/2, side/2]
    t = np.arange(steps) * 0.288
    return {"t": t, "x": xy[:, 0], "y": xy[:, 1], "heading": np.zeros(steps)}


def test_metres_that_cannot_work_in_a_small_box_are_warned_about():
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        r = bvc3d.run_trial(trajectory=box_walk(1.0), protocol="online", sample_hours=0.2)
    messages = [str(w.message) for w in caught if issubclass(w.category, UserWarning)]
    assert any("d_th = 2 m" in m and "span only" in m and "MSAI mean nothing" in m for m in messages), messages
    assert any("eps = 1 m" in m and "no cell can be multimodal" in m for m in messages), messages
    assert abs(r["metrics"]["msai"]) < 1e-12  # what the warning is about: no pair of bins is compared
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        bvc3d.run_trial(trajectory=box_walk(1.0), analysis=dict(eps=0.1, d_th=0.2), protocol="online", sample_hours=0.2)
    assert not [w for w in caught if "span only" in str(w.message)]


def test_the_program_warns_as_well(tmp_path):
    track = box_walk(1.0, steps=800)
    path = tmp_path / "box.csv"
    np.savetxt(path, np.column_stack([track["t"], track["x"], track["y"], track["heading"]]), delimiter=",",
               header="t,x,y,heading", comments="")
    p = run_cli("run", "--trajectory", path, "--explore-hours", 0, "--sample-hours", 0.06, "--out", tmp_path / "box.h5")
    assert p.returncode == 0, p.stderr
    assert "bvc3d: warning:" in p.stderr and "d_th = 2 m" in p.stderr, p.stderr


def test_flying_walk_refuses_hours_beyond_the_limit():
    with pytest.raises(ValueError, match=r"flight: hours = 1e\+05 is more than the limit of 10000 simulated hours"):
        bvc3d.flying_walk(bvc3d.World.preset("flight-room"), 1e5, 0)


@pytest.fixture(scope="module")
def recording(tmp_path_factory):
    d = tmp_path_factory.mktemp("rec") / "walk"
    run_cli("export-scans", "--world", "cross", "--hours", 0.002, "--seed", 1, "--format", "pcd", "--out", d,
            check=True)
    return bvc3d.Recording.open(d, d / "poses.txt")


def test_scan_index_past_the_end_names_the_recording_and_the_index(recording):
    n = len(recording.times)
    for call in (recording.returns, recording.points):
        with pytest.raises(ValueError, match=rf"recording '{recording.name}': scan {n} does not exist \({n} scans\)"):
            call(n)
        with pytest.raises(ValueError, match=rf"scan -{n + 1} does not exist"):
            call(-n - 1)
        with pytest.raises(ValueError, match=r"a scan index must be an integer, not float"):
            call(1.0)
    np.testing.assert_array_equal(recording.returns(-1), recording.returns(n - 1))


def test_boolean_arrays_are_refused():
    rng = np.random.default_rng(0)
    with pytest.raises(ValueError, match=r"points must hold real numbers"):
        an.dbscan_labels(np.ones((30, 2), dtype=bool))
    with pytest.raises(ValueError, match=r"positions must hold real numbers"):
        an.analyze3d(np.ones((50, 3), dtype=bool), rng.random((50, 4)))
    with pytest.raises(ValueError, match=r"centers must hold real numbers"):
        an.isotropy(np.ones((5, 3), dtype=bool), rng.random((5, 2)), [1, 1])
    with pytest.raises(ValueError, match=r"templates must hold real numbers"):
        bvc3d.localize(np.ones((4, 3), dtype=bool), rng.random((4, 2)), rng.random((2, 3)), rng.random((2, 2)))
    with pytest.raises(ValueError, match=r"query_positions must hold real numbers"):
        bvc3d.localize(rng.random((4, 3)), rng.random((4, 2)), rng.random((2, 3)), np.ones((2, 2), dtype=bool))
    track = {"t": np.arange(5.0), "x": np.ones(5, dtype=bool), "y": np.zeros(5), "heading": np.zeros(5)}
    with pytest.raises(ValueError, match=r"trajectory\['x'\] must hold real numbers"):
        bvc3d.replay_simulated("cross", track, "spherical")
    with pytest.raises(ValueError, match=r"trajectory must be a file path or a dict"):
        bvc3d.replay_simulated("cross", [1, 2], "spherical")


# ---------------------------------------------------------------- nonsense accepted (issue 32)

@pytest.mark.parametrize("kind", ["trajectory", "waypoints"])
def test_a_number_with_a_nul_byte_is_no_number(tmp_path, kind):
    """strtod stops at the NUL: "1\\0junk" was read as 1. The field is refused, naming file and line."""
    path = tmp_path / f"{kind}.txt"
    if kind == "trajectory":
        path.write_bytes(b"t,x,y,heading\n0,0,-2,0\n1,0\x0099,-2,0\n")
        p = run_cli("run", "--trajectory", path, "--explore-hours", 0, "--sample-hours", 0.0002,
                    "--out", tmp_path / "t.h5")
    else:
        path.write_bytes(b"x y\n0 -2\n1\x007 -2\n")
        p = run_cli("route", "--world", "cross", "--waypoints", path, "--out", tmp_path / "r.csv")
    assert p.returncode == 2, p.stderr
    assert f"{kind}.txt', line 3: " in p.stderr and "\\x00" in p.stderr and "is not a number" in p.stderr, p.stderr
    assert not list(tmp_path.glob("[tr].*"))
