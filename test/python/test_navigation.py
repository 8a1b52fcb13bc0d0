"""Navigation to goals (docs/navigation.md) against a numpy transcription of SPEC §16-§17: the HD-conditioned
adjacency's update on a hand-made sequence, replay and the reward read-out on a hand-made chain of cells, the
direction choice, the shortest path against the arena's geometry, and `bvc3d navigate` on bad input."""
import hashlib
import math
import signal
import subprocess
import time

import h5py
import numpy as np
import pytest

import bvc3d

from conftest import CLI


def hd(heading, n=8):
    return np.cos(heading - 2 * np.pi * np.arange(n) / n)


def adjacency_numpy(sequence, n, eta=0.096, tau_x=3.0, tau_hd=0.1, rate=0.3, decay=1e-4):
    """SPEC §16 written out: traces first, then the antisymmetric update (not on bumps), then the decay."""
    W = np.zeros((8, n, n))
    x = np.zeros(n)
    u = np.zeros(8)
    for v, heading, bumped in sequence:
        x += eta / tau_x * (v - x)
        u += eta / tau_hd * (hd(heading) - u)
        if not bumped:
            W += rate * u[:, None, None] * (np.outer(v, x) - np.outer(x, v))[None]
        W *= 1 - decay
    return W, x, u


def test_adjacency_update_matches_numpy_on_a_hand_made_sequence():
    rng = np.random.default_rng(4)
    n = 6
    sequence = []
    for t in range(40):
        v = np.zeros(n)
        cells = rng.choice(n, size=2, replace=False)
        v[cells] = rng.uniform(0.1, 1.0, size=2)
        sequence.append((v, rng.uniform(-np.pi, np.pi), t % 7 == 3))
    adj = bvc3d.HdAdjacency(n)
    for v, heading, bumped in sequence:
        adj.learn(v, hd(heading), bumped)
    W, x, u = adjacency_numpy(sequence, n)
    scale = np.abs(W).max()
    assert scale > 0.01
    np.testing.assert_allclose(adj.weights, W, atol=1e-6 * scale, rtol=1e-5)
    np.testing.assert_allclose(adj.weights, -np.transpose(adj.weights, (0, 2, 1)), atol=1e-7 * scale)
    np.testing.assert_allclose(adj.place_trace, x, rtol=1e-12)
    np.testing.assert_allclose(adj.hd_trace, u, rtol=1e-12)


def chain(n):
    W = np.zeros((8, n, n), dtype=np.float32)
    for i in range(n - 1):
        W[0, i + 1, i], W[0, i, i + 1] = 1, -1
        W[4, i, i + 1], W[4, i + 1, i] = 1, -1
    return W


# The C library's tanh, as the library calls it: numpy's own tanh may differ in the last bit, and replay's
# hundreds of steps of tanh([·]+) amplify such differences (to 1e-6 relative at λ = 20, 1e-3 at 60).
libm_tanh = np.vectorize(math.tanh)


def replay_numpy(W, goal, lam=20.0):
    n = W.shape[1]
    amp = 5 / lam
    w = np.zeros(n)
    x = np.zeros(n)
    x[goal] = 1
    for t in range(math.ceil(8 * lam) + 1):
        norm = np.linalg.norm(x)
        if norm == 0:
            break
        w += amp * np.exp(-t / lam) * x / norm
        x = libm_tanh(np.maximum((W.astype(float) @ x).max(axis=0) + x, 0))
    return w


def reward_numpy(w, v):
    return w @ v / max(np.abs(v).sum(), 1e-4)


def returns_numpy(W, w, v, steps=3, gamma=0.7):
    out = np.zeros(8)
    for k in range(8):
        x = v.copy()
        for t in range(steps):
            x = libm_tanh(np.maximum(W[k].astype(float) @ x - x, 0))
            out[k] += gamma**t * reward_numpy(w, x)
    return out


@pytest.mark.parametrize("lam", [20.0, 30.0, 60.0])
def test_replay_and_reward_readout_match_numpy_on_a_chain(lam):
    n = 30
    adj = bvc3d.HdAdjacency(n)
    adj.weights = chain(n)
    w = adj.replay(n - 1, **{"lambda": lam})
    expected = replay_numpy(chain(n), n - 1, lam)
    np.testing.assert_allclose(w, expected, rtol=1e-10)
    if lam == 20.0:  # the default: value falls with the distance from the goal (longer replays fill the chain)
        assert np.all(np.diff(w[-12:]) > 0)
    v = np.zeros(n)
    v[[17, 18]] = [0.3, 0.6]
    assert bvc3d.reward_readout(w, v) == pytest.approx(reward_numpy(w, v), rel=1e-12)
    assert bvc3d.reward_readout(w, np.zeros(n)) == 0.0


def test_direction_returns_match_numpy_and_point_to_the_goal():
    n = 30
    adj = bvc3d.HdAdjacency(n)
    adj.weights = chain(n)
    w = adj.replay(n - 1)
    v = np.zeros(n)
    v[20] = 1.0
    r = adj.direction_returns(w, v)
    np.testing.assert_allclose(r, returns_numpy(chain(n), w, v), rtol=1e-10)
    assert np.argmax(r) == 0  # east, along the chain toward the goal


def combine_numpy(returns, allowed, scores=None, beta=500.0, scale_beta=2.0, f=0.25):
    """SPEC §17's combination of scales, as docs/navigation.md#multiscale reads it, written out."""
    returns, allowed = np.asarray(returns, float), np.asarray(allowed, bool)
    probs, fresh = [], []
    for r in returns:
        z = np.where(allowed, beta * r, -np.inf)
        p = np.exp(z - z.max())
        p /= p.sum()
        h = -sum(q * math.log(q) for q in p if q > 0)
        probs.append(p)
        fresh.append(r[allowed].mean() / max(h, 1e-3))
    fresh = np.array(fresh)
    scores = fresh if scores is None else (1 - f) * np.asarray(scores) + f * fresh
    a = np.exp(scale_beta * (scores - scores.max()))
    a /= a.sum()
    return a @ np.array(probs), scores


def test_combine_scales_matches_numpy_on_hand_made_returns():
    # Scale 0 is sure of east (a clear gradient), scale 1 is unsure between north and east: the sure scale's
    # score (mean return over a small entropy) is the larger, so its choice gets most of the weight.
    returns = np.array([[0.030, 0.020, 0.010, 0.0, 0.0, 0.0, 0.0, 0.005],
                        [0.040, 0.041, 0.042, 0.0, 0.0, 0.0, 0.0, 0.040]])
    allowed = np.array([1, 1, 1, 1, 1, 1, 0, 1])
    prob, scores = bvc3d.combine_scales(returns, allowed)
    expected, expected_scores = combine_numpy(returns, allowed)
    np.testing.assert_allclose(prob, expected, rtol=1e-12, atol=1e-300)
    np.testing.assert_allclose(scores, expected_scores, rtol=1e-12)
    assert prob.sum() == pytest.approx(1.0) and prob[6] == 0.0
    # By hand: scale 0's softmax(500 R) over the offered directions and its entropy; scale 1's likewise.
    p0 = np.exp(500 * (returns[0] - 0.03)) * allowed
    p0 /= p0.sum()
    p1 = np.exp(500 * (returns[1] - 0.042)) * allowed
    p1 /= p1.sum()
    h0, h1 = (-np.sum(p[p > 0] * np.log(p[p > 0])) for p in (p0, p1))
    c = np.array([returns[0][allowed == 1].mean() / h0, returns[1][allowed == 1].mean() / h1])
    a0 = 1 / (1 + math.exp(2 * (c[1] - c[0])))
    np.testing.assert_allclose(prob, a0 * p0 + (1 - a0) * p1, rtol=1e-9)
    assert a0 > 0.5 and np.argmax(prob) == 0
    # The next decision smooths the scores: 0.75 of the carried, 0.25 of the new.
    later = np.array([[0.0, 0.0, 0.0, 0.0, 0.01, 0.0, 0.0, 0.0], returns[1]])
    prob2, scores2 = bvc3d.combine_scales(later, allowed, scores)
    expected2, expected_scores2 = combine_numpy(later, allowed, expected_scores)
    np.testing.assert_allclose(scores2, expected_scores2, rtol=1e-12)
    np.testing.assert_allclose(prob2, expected2, rtol=1e-12, atol=1e-300)
    # One scale: exactly its own softmax(β R) (the single-scale model's choice, bit for bit).
    one, _ = bvc3d.combine_scales(returns[:1], allowed)
    np.testing.assert_allclose(one, p0, rtol=1e-12, atol=1e-300)


def test_shortest_path_in_the_cross_arena_goes_round_the_wall():
    world = bvc3d.World.cross()
    # Straight across the open corner: the segment's own length, on the 0.1 m grid's octile moves (≤ 8 % longer).
    p = bvc3d.shortest_path(world, [-4.0, 4.0], [-2.0, 4.0])
    assert p["found"] and p["length"] == pytest.approx(2.0, abs=0.15)
    # From one side of wall A to the other (x = -2, y = ±1.5): every path crosses y = 0 beyond the wall's end
    # inflated by 0.5 m (x ≤ -4.0), so at least 2·hypot(2, 1.5) = 5 m. The polyline (-2, -1.5), (-4, -0.65),
    # (-4, 0.65), (-2, 1.5) keeps 0.5 m from the wall (|y| ≤ 0.15) and is 5.646 m; 8-neighbour moves make a path up
    # to 8.24 % longer than a straight one (octile metric), plus a cell at each end.
    p = bvc3d.shortest_path(world, [-2.0, -1.5], [-2.0, 1.5])
    polyline = 2 * math.hypot(2.0, 0.85) + 1.3
    assert p["found"] and 5.0 <= p["length"] <= polyline * 1.0824 + 0.2


def run(*args):
    return subprocess.run([CLI, *args], capture_output=True, text=True)


@pytest.mark.parametrize("goals, named", [("30,0", "goal 1 (30, 0)"), ("2,2;0,0.1", "goal 2 (0, 0.1)"),
                                          ("", "no goals")])
def test_navigate_refuses_bad_goals(tmp_path, goals, named):
    r = run("navigate", "--world", "cross", "--goals", goals, "--out", str(tmp_path / "out"))
    assert r.returncode == 2, r.stderr
    assert named in r.stderr
    assert not (tmp_path / "out").exists()


def test_navigate_refuses_an_unknown_policy_naming_the_list(tmp_path):
    r = run("navigate", "--world", "cross", "--goals", "3,3", "--policy", "nonesuch", "--out", str(tmp_path / "out"))
    assert r.returncode == 2 and "policy 'nonesuch' is not one of rollout8" in r.stderr, r.stderr
    assert not (tmp_path / "out").exists()
    config = tmp_path / "nav.yaml"
    config.write_text("world: cross\ngoals: [[3, 3]]\npolicy: nonesuch\n")
    r = run("navigate", "--config", str(config), "--out", str(tmp_path / "out"))
    assert r.returncode == 2 and "nav.yaml" in r.stderr and "policy" in r.stderr, r.stderr


def test_navigate_from_python_is_seeded_and_measures_against_the_shortest_path():
    world = bvc3d.World.cross()
    kw = dict(max_learn_hours=0.2, starts=2, min_start_distance=3.0, goal_visits=1, reward_map_cell=0)
    a = bvc3d.navigate(world, [[3.5, 3.5]], seed=1, **kw)
    b = bvc3d.navigate(world, [[3.5, 3.5]], seed=1, **kw)
    assert len(a["start_x"]) == 2
    for key in ("start_x", "start_y", "path_m", "shortest_m", "time_s", "success"):
        np.testing.assert_array_equal(a[key], b[key])
    for i, path in enumerate(a["paths"]):
        start = [a["start_x"][i], a["start_y"][i]]
        assert np.hypot(start[0] - 3.5, start[1] - 3.5) >= 3.0
        assert a["shortest_m"][i] == pytest.approx(bvc3d.shortest_path(world, start, [3.5, 3.5])["length"])
        steps = np.hypot(*np.diff(path, axis=0).T)
        assert np.all(steps <= 0.25 + 1e-9) and a["path_m"][i] == pytest.approx(steps.sum())
    with pytest.raises(ValueError, match="goal 1"):
        bvc3d.navigate(world, [[30.0, 0.0]])
    # The world by name (as navigate's --world), the YAML's sections as dicts, the policy by name: the same run.
    c = bvc3d.navigate("cross", [[3.5, 3.5]], seed=1, policy="rollout8", navigation=kw)
    for key in ("start_x", "path_m", "time_s"):
        np.testing.assert_array_equal(a[key], c[key])
    pruned = bvc3d.navigate(world, [[3.5, 3.5]], seed=1, adjacency=dict(prune=0.01), reward=dict(rollout_steps=3),
                            **kw)
    flat = bvc3d.navigate(world, [[3.5, 3.5]], seed=1, prune=0.01, **kw)
    np.testing.assert_array_equal(pruned["path_m"], flat["path_m"])
    with pytest.raises(ValueError, match="policy 'nonesuch' is not one of rollout8"):
        bvc3d.navigate(world, [[3.5, 3.5]], policy="nonesuch", **kw)
    with pytest.raises(ValueError, match="adjacency must be a dict"):
        bvc3d.navigate(world, [[3.5, 3.5]], adjacency=0.01, **kw)
    with pytest.raises(ValueError, match="unknown argument 'prun'"):
        bvc3d.navigate(world, [[3.5, 3.5]], adjacency=dict(prun=0.01), **kw)


def six_digits(text):
    """A CSV as the writer before exact numbers printed it: every number with 6 significant digits (C++'s ostream
    default, printf's %g)."""
    def field(f):
        try:
            return "%g" % float(f)
        except ValueError:
            return f
    return "".join(",".join(field(f) for f in line.split(",")) + "\n" for line in text.splitlines())


FAILURE_CLASSES = {"", "blocked", "closing-in", "plateau", "wrong-basin", "loop", "wander"}


def without_failure_column(text):
    """starts.csv without its last column, `failure`, and each row's failure class with the row (a dict)."""
    lines = text.splitlines()
    header = lines[0].split(",")
    assert header[-1] == "failure", header
    rows = [dict(zip(header, line.split(","))) for line in lines[1:]]
    assert {row["failure"] for row in rows} <= FAILURE_CLASSES, rows
    return "".join(line.rsplit(",", 1)[0] + "\n" for line in lines), [(row["failure"], row) for row in rows]


def test_navigate_on_the_floor_keeps_the_numbers_it_wrote_before(tmp_path):
    """A small run's starts.csv and paths.csv: the digests the code wrote before navigation became trials of the
    engine (issue 41; before that, the digests of the code before goals in 3-D, issue 30), from today's exact numbers
    printed with the 6 digits that code printed; and today's exact files, pinned."""
    out = tmp_path / "out"
    r = run("navigate", "--world", "cross", "--tilt", "60", "--goals", "3.5,3.5;-3.5,-3.5", "--max-learn-hours",
            "0.2", "--starts", "3", "--seeds", "2", "--out", str(out), "--no-report")
    assert r.returncode == 0, r.stderr
    texts = {name: (out / name).read_text() for name in ("starts.csv", "paths.csv")}
    # The failure class (issue 46) is a column after the ones pinned: the pinned bytes are those before it.
    texts["starts.csv"], failures = without_failure_column(texts["starts.csv"])
    assert all((f == "") == (row["success"] == "1") for f, row in failures), failures
    # ... written from the trial files' /navigation/failure (0: reached, then the classes in the order above).
    names = ["", "blocked", "closing-in", "plateau", "wrong-basin", "loop", "wander"]
    written = []
    for seed in (0, 1):
        with h5py.File(next(out.glob(f"*seed{seed}.h5")), "r") as f:
            written += [names[c] for c in f["navigation/failure"][()]]
            assert f["navigation/walls"].shape[1] == 4 and len(f["navigation/walls"]) > 4  # the cross and the room
    assert written == [f for f, _ in failures]
    digest = lambda text: hashlib.sha256(text.encode()).hexdigest()
    assert {name: digest(six_digits(t)) for name, t in texts.items()} == {
        "starts.csv": "e600565f279eff431d74855ac1dffb396389c3d8aeb0576f6799413a55a27b71",
        "paths.csv": "cb27ac3dfb4df6bea6b86551c483eb056cad94b502bd8cfa4d806dfd2eda082a"}
    assert {name: digest(t) for name, t in texts.items()} == {
        "starts.csv": "a35c34cf5f5f68ebdf15f6260cb09c3b764cee2ab4ccd5ab3417cec93225886b",
        "paths.csv": "f91ac95de38e64e6fd3412fd99810b6e615c6fcccc51c11db7467675b4cb62c0"}


def test_navigate_flies_to_goals_in_3d_seeded_with_3d_paths():
    world = bvc3d.World.preset("flight-room")
    goal = [1.5, 1.0, 1.6]
    kw = dict(max_learn_hours=0.15, coverage=0.8, goal_visits=2, starts=2, min_start_distance=3.0)
    a = bvc3d.navigate(world, [goal], model="fly-5l", seed=2, **kw)
    b = bvc3d.navigate(world, [goal], model="fly-5l", seed=2, **kw)
    for key in ("start_x", "start_y", "start_z", "path_m", "shortest_m", "time_s", "success"):
        np.testing.assert_array_equal(a[key], b[key])
    np.testing.assert_array_equal(a["goal_z"], [1.6, 1.6])
    for i, path in enumerate(a["paths"]):
        assert path.shape[1] == 3
        start = np.array([a["start_x"][i], a["start_y"][i], a["start_z"][i]])
        np.testing.assert_array_equal(path[0], start)
        assert np.linalg.norm(start - goal) >= 3.0 and a["shortest_m"][i] >= np.linalg.norm(start - goal) - 1e-9
        steps = np.linalg.norm(np.diff(path, axis=0), axis=1)
        assert np.all(steps <= 0.25 + 1e-9) and a["path_m"][i] == pytest.approx(steps.sum())
        assert np.ptp(path[:, 2]) > 0  # it flies up and down, not in a plane
        if a["success"][i]:
            assert np.linalg.norm(path[-1] - goal) <= 1.0 + 1e-9
    with pytest.raises(ValueError, match=r"goal 1 \(1, 1\).*no walkable floor"):
        bvc3d.navigate(world, [[1.0, 1.0]], model="fly-5l")
    with pytest.raises(ValueError, match=r"goal 1 \(0, 0, 9\).*flight volume"):
        bvc3d.navigate(world, [[0.0, 0.0, 9.0]], model="fly-5l")
    with pytest.raises(ValueError, match="fly-5l"):
        bvc3d.navigate(bvc3d.World.cross(), [[3.5, 3.5]], model="fly-5l")
    # The flying agent's parameters as YAML's `flight:` section: a start's time is its path at the flight's speed plus
    # its turns, and the learning walk (0.288 s a step) ends at another time when the speed changes.
    assert np.all(a["time_s"] >= a["path_m"] - 1e-9)
    fast = bvc3d.navigate(world, [goal], model="fly-5l", seed=2, flight={"speed": 2.0}, **kw)
    assert np.all(fast["time_s"] >= fast["path_m"] / 2 - 1e-9) and fast["learn_s"] != a["learn_s"]
    with pytest.raises(ValueError, match="unknown argument 'sped'"):
        bvc3d.navigate(world, [goal], model="fly-5l", flight={"sped": 2.0})
    with pytest.raises(ValueError, match="flight must be a dict"):
        bvc3d.navigate(world, [goal], model="fly-5l", flight=2.0)


def test_navigate_in_3d_writes_z_and_resumes_its_runs_to_the_same_bytes(tmp_path):
    out = tmp_path / "out"
    args = ["navigate", "--world", "atrium", "--model", "fly-5l", "--goals", "2.5,2.5,0.8", "--starts", "1",
            "--max-learn-hours", "0.05", "--out", str(out), "--no-report"]
    first = run(*args)
    assert first.returncode == 0, first.stderr
    starts, paths = ((out / n).read_text() for n in ("starts.csv", "paths.csv"))
    header = starts.splitlines()[0].split(",")
    assert header == ("world,model,seed,goal_x,goal_y,start_x,start_y,success,path_m,shortest_m,path_ratio,time_s,"
                      "goal_z,start_z,failure").split(",")
    assert paths.splitlines()[0] == "model,seed,start,x,y,z"
    row = dict(zip(header, starts.splitlines()[1].split(",")))
    assert float(row["goal_z"]) == 0.8 and 0.4 < float(row["start_z"]) < 5.6
    z = [float(line.split(",")[5]) for line in paths.splitlines()[1:]]
    assert z[0] == float(row["start_z"]) and len(set(z)) > 1
    for name in ("starts.csv", "paths.csv"):
        (out / name).unlink()
    again = run(*args)
    assert again.returncode == 0 and "1 already complete" in again.stdout, again.stdout
    assert (out / "starts.csv").read_text() == starts and (out / "paths.csv").read_text() == paths


def test_navigate_killed_inside_a_learning_run_resumes_there_and_writes_the_same_files(tmp_path):
    """Navigation's learning is a trial's run: a navigate run killed (SIGKILL) in the middle of a learning run, after
    a periodic checkpoint, resumes from that checkpoint and writes byte for byte what an uninterrupted run writes;
    other options start afresh."""
    def options(starts):
        return ["navigate", "--world", "cross", "--goals", "3.5,3.5", "--seeds", "2", "--starts", starts,
                "--max-learn-hours", "0.15", "--checkpoint-minutes", "1", "--jobs", "1", "--no-report"]
    args = options("2")
    whole = tmp_path / "whole"
    assert run(*args, "--out", str(whole)).returncode == 0
    part = tmp_path / "part"
    proc = subprocess.Popen([CLI, *args, "--out", str(part)], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    deadline = time.monotonic() + 300
    checkpoints = part / ".checkpoints"
    while not list(checkpoints.glob("*seed0*.h5")) and proc.poll() is None and time.monotonic() < deadline:
        time.sleep(0.01)
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    assert proc.returncode == -signal.SIGKILL, "the run ended before it could be killed"
    assert list(checkpoints.glob("*seed0*.h5")) and not list(part.glob("*.h5")), "not killed inside a learning run"
    again = run(*args, "--out", str(part))
    assert again.returncode == 0, again.stderr
    assert "2 run" in again.stdout, again.stdout
    names = sorted(p.relative_to(whole) for p in whole.rglob("*") if p.is_file())
    assert names == sorted(p.relative_to(part) for p in part.rglob("*") if p.is_file())
    assert {"starts.csv", "cross_2d_seed0.h5"} <= set(map(str, names)), names
    for name in names:
        assert (whole / name).read_bytes() == (part / name).read_bytes(), name
    same = run(*args, "--out", str(part))
    assert same.returncode == 0 and "0 run, 2 already complete" in same.stdout, same.stdout
    other = run(*options("1"), "--out", str(part))
    assert other.returncode == 0 and "2 run" in other.stdout, other.stdout


def test_navigate_config_runs_several_models_as_the_options_would(tmp_path):
    """A YAML file with two models gives, for each, what the command-line options give for that model alone; and
    its four learning runs one at a time (--jobs 1) what two at a time give (--jobs 2)."""
    (tmp_path / "nav.yaml").write_text(
        "world: cross\ngoals: [[3.5, 3.5]]\nmodels: [2d, 3d-0.2]\nseeds: 2\nfirst_seed: 4\n"
        "navigation: {starts: 1, max_learn_hours: 0.05}\n")
    r = run("navigate", "--config", str(tmp_path / "nav.yaml"), "--out", str(tmp_path / "yaml"), "--no-report",
            "--jobs", "1")
    assert r.returncode == 0, r.stderr
    rows = (tmp_path / "yaml" / "starts.csv").read_text().splitlines()
    assert [row.split(",")[1:3] for row in rows[1:]] == [["2d", "4"], ["2d", "5"], ["3d-0.2", "4"], ["3d-0.2", "5"]]
    for model in ("2d", "3d-0.2"):
        one = tmp_path / model
        r = run("navigate", "--world", "cross", "--goals", "3.5,3.5", "--model", model, "--seeds", "2",
                "--first-seed", "4", "--starts", "1", "--max-learn-hours", "0.05", "--out", str(one), "--no-report",
                "--jobs", "2")
        assert r.returncode == 0, r.stderr
        alone = (one / "starts.csv").read_text().splitlines()
        assert [row for row in rows if row.split(",")[1] == model] == alone[1:]
    summary = (tmp_path / "yaml" / "summary.csv").read_text().splitlines()
    assert [row.split(",")[1] for row in summary[1:]] == ["2d", "3d-0.2"]


def test_navigate_config_refuses_unknown_keys_and_options_beside_it(tmp_path):
    (tmp_path / "nav.yaml").write_text("world: cross\ngoals: [[3.5, 3.5]]\nreward: {betta: 5}\n")
    r = run("navigate", "--config", str(tmp_path / "nav.yaml"), "--out", str(tmp_path / "out"))
    assert r.returncode == 2 and "reward.betta" in r.stderr and "unknown key" in r.stderr, r.stderr
    assert not (tmp_path / "out").exists()
    r = run("navigate", "--config", str(tmp_path / "nav.yaml"), "--world", "cross", "--out", str(tmp_path / "out"))
    assert r.returncode != 0 and "--world" in r.stderr, r.stderr


def test_a_sweep_of_navigation_trials_writes_what_navigate_writes(tmp_path):
    """A navigation experiment under `bvc3d sweep` (and so under MPI): the trial YAML's navigation: section gives the
    trials `bvc3d navigate` makes from the same world, goals and parameters, and the same numbers in starts.csv."""
    nav = run("navigate", "--world", "cross", "--tilt", "60", "--goals", "3.5,3.5", "--model", "2d", "--seeds", "2",
              "--starts", "2", "--max-learn-hours", "0.1", "--out", str(tmp_path / "nav"), "--no-report")
    assert nav.returncode == 0, nav.stderr
    (tmp_path / "sweep.yaml").write_text(
        "base:\n  world: {source: cross, tilt_deg: 60}\n"
        "  navigation: {goals: [[3.5, 3.5]], starts: 2, max_learn_hours: 0.1}\n"
        "grid:\n  model: [2d]\nseeds: 2\n")
    sweep = run("sweep", str(tmp_path / "sweep.yaml"), "--out", str(tmp_path / "sweep"), "--no-report")
    assert sweep.returncode == 0, sweep.stderr
    def columns(folder):  # the numbers of each start (the world and model labels are each command's own)
        rows = (folder / "starts.csv").read_text().splitlines()
        return [row.split(",")[2:] for row in rows[1:]]
    assert columns(tmp_path / "sweep") == columns(tmp_path / "nav") and len(columns(tmp_path / "nav")) == 4
    with h5py.File(next((tmp_path / "sweep").glob("*seed1.h5"))) as h:
        g = h["navigation"]
        assert g.attrs["dims"] == 2 and g["path_start"][-1] == len(g["path"])
        assert h["populations/reward/reward_weights"].shape == (1, 250)
    # A navigation trial takes no protocol, and its goals are checked against the world before anything runs.
    (tmp_path / "bad.yaml").write_text(
        "base:\n  world: cross\n  protocol: {explore_hours: 1}\n  navigation: {goals: [[3.5, 3.5]]}\n"
        "grid:\n  model: [2d]\n")
    bad = run("sweep", str(tmp_path / "bad.yaml"), "--out", str(tmp_path / "bad"))
    assert bad.returncode == 2 and "protocol" in bad.stderr, bad.stderr
    (tmp_path / "wall.yaml").write_text(
        "base:\n  world: cross\n  navigation: {goals: [[30, 0]]}\ngrid:\n  model: [2d]\n")
    wall = run("sweep", str(tmp_path / "wall.yaml"), "--out", str(tmp_path / "wall"))
    assert wall.returncode == 2 and "goal 1 (30, 0)" in wall.stderr, wall.stderr
    assert not list((tmp_path / "wall").glob("*.h5"))
