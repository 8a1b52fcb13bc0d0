"""The authors' protocol (SPEC §17.3, navigation's `protocol: authors`) against the numpy oracle of their planner
(numpy_oracles.authors_*): the blocked cells of their worlds' grids and the optimal path's length from random starts;
then starts the same for every learning run, drawn and measured as theirs."""
import math
import pathlib

import numpy as np
import pytest

import bvc3d
from numpy_oracles import authors_blocked_grid, authors_cell, authors_optimal_path

WORLDS = pathlib.Path(__file__).resolve().parents[2] / "configs" / "worlds"
# The authors' rectangles ((x0, y0), (x1, y1)), webots_worlds.py @19ec63c6 (as test_authors_paths.py has them).
CROSS = [((-6.0, -0.5), (6.0, 0.0)), ((-0.5, -6.0), (0.0, 6.0))]
MAZE = [((-10.0, 2.75), (-0.5, 3.25)), ((0.5, -3.45), (10.0, -2.95)), ((-4.25, -3.4), (-3.75, 3.0)),
        ((2.75, -2.7), (3.25, 3.7)), ((0.25, -10.0), (0.75, -7.0)), ((-1.25, 7.0), (-0.75, 10.0))]
# The later worlds' walls (cx, cy, length, thickness, yaw): 7 × 0.4 m at yaw −134.9545° (authors_worlds.py).
YAW = math.radians(-134.9545)
ONE = [(0.0, 0.0, 7.0, 0.4, YAW)]
TWO = [(4.0, 0.0, 7.0, 0.4, YAW), (-4.0, 0.0, 7.0, 0.4, YAW)]
CASES = {"authors-open": ([], ()), "authors-cross": (CROSS, ()), "authors-maze": (MAZE, ()),
         "authors-one-obstacle": ([], ONE), "authors-two-obstacles": ([], TWO)}


@pytest.mark.parametrize("world", sorted(CASES))
def test_the_grid_blocks_the_cells_their_planner_blocks(world):
    rects, oriented = CASES[world]
    grid = bvc3d.authors.authors_grid(WORLDS / f"{world}.yaml")
    assert (grid["west"], grid["north"], grid["cell"]) == (-10.0, 10.0, 0.1)
    expected = authors_blocked_grid(rects, oriented=oriented)
    mismatch = np.argwhere(grid["blocked"] != expected)
    assert len(mismatch) == 0, f"{len(mismatch)} cells differ, e.g. (row, col) {mismatch[:5].tolist()}"
    assert expected.sum() > 0 or world == "authors-open"


@pytest.mark.parametrize("world", ["authors-cross", "authors-maze", "authors-two-obstacles"])
def test_the_optimal_path_is_the_oracles_from_random_starts(world):
    rects, oriented = CASES[world]
    rng = np.random.default_rng(17)
    blocked = authors_blocked_grid(rects, oriented=oriented)
    checked = 0
    for goal in [(7, 7), (-7, 7), (7, -7), (-7, -7)]:
        for _ in range(4):
            start = rng.uniform(-9.5, 9.5, 2)
            c, r = authors_cell(start)
            mine = bvc3d.authors.authors_path(WORLDS / f"{world}.yaml", start, goal)
            oracle = authors_optimal_path(rects, start, goal, oriented=oriented)
            assert mine["found"] == (oracle is not None) == (not blocked[r, c])
            if oracle is None:
                continue
            checked += 1
            assert mine["length"] == pytest.approx(oracle[0], rel=1e-12)
            assert tuple(mine["cells"][0]) == (c, r)
    assert checked >= 10


def test_the_protocols_starts_are_the_same_for_every_learning_run_and_policy_and_scored_by_their_path():
    world = WORLDS / "authors-cross.yaml"
    kw = dict(protocol="authors", max_learn_hours=0.05, starts=3, goal_visits=0, coverage=0.1, reward_map_cell=0,
              max_path_ratio=2.0)
    runs = [bvc3d.navigate(world, [[7, 7], [-7, -7]], seed=seed, policy=policy, navigation=kw)
            for seed, policy in [(0, "rollout8"), (1, "rollout8"), (1, "authors")]]
    for key in ("start_x", "start_y", "shortest_m", "goal_x"):
        np.testing.assert_array_equal(runs[0][key], runs[1][key])
        np.testing.assert_array_equal(runs[0][key], runs[2][key])
    a = runs[0]
    for x, y, gx, gy, shortest in zip(a["start_x"], a["start_y"], a["goal_x"], a["goal_y"], a["shortest_m"]):
        # On a cell's centre, inside the square less 0.5 m, at least 6 m from the goal, off the inflated walls.
        assert abs(x) <= 9.5 and abs(y) <= 9.5 and math.hypot(x - gx, y - gy) >= 6.0 - 0.08
        assert (x + 10) / 0.1 % 1 == pytest.approx(0.5) and (10 - y) / 0.1 % 1 == pytest.approx(0.5)
        oracle = authors_optimal_path(CROSS, (x, y), (gx, gy))
        assert oracle is not None and shortest == pytest.approx(oracle[0], rel=1e-12)
    # Another learning run: other choices (its own streams), the same starts.
    assert any(not np.array_equal(p, q) for p, q in zip(runs[0]["paths"], runs[1]["paths"]))
    with pytest.raises(ValueError, match="protocol"):
        bvc3d.navigate("flight-room", [[1.5, 1.0, 1.6]], model="fly-5l", navigation=kw)
