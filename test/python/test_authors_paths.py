"""The authors' optimal path (SPEC §17.3, their path_planning.py @26c3ab19) as numpy_oracles.py searches it, against
answers known another way: the octile distance in an open room, a relaxation to the fixed point over the same grid
in their cross and maze worlds, and hand-made grids (corner cutting, walls without a gap). numpy only (no bvc3d)."""
import math

import numpy as np
import pytest

from numpy_oracles import (authors_blocked_grid, authors_cell, authors_cell_centres, authors_goal_cells,
                           authors_optimal_path, grid_shortest_path)

# The authors' rectangles ((x0, z0), (x1, z1)), webots_worlds.py @19ec63c6; their z is bvc3d's y.
CROSS = [((-6.0, -0.5), (6.0, 0.0)), ((-0.5, -6.0), (0.0, 6.0))]
MAZE = [((-10.0, 2.75), (-0.5, 3.25)), ((0.5, -3.45), (10.0, -2.95)), ((-4.25, -3.4), (-3.75, 3.0)),
        ((2.75, -2.7), (3.25, 3.7)), ((0.25, -10.0), (0.75, -7.0)), ((-1.25, 7.0), (-0.75, 10.0))]
GOALS = [(7, 7), (-7, 7), (7, -7), (-7, -7)]


def relaxed_distances(blocked, targets, cell=0.1):
    """Every cell's distance to the nearest target by relaxing all 8 moves at once until nothing changes."""
    D = np.where(targets & ~blocked, 0.0, np.inf)
    rows, cols = D.shape
    while True:
        best = D.copy()
        for dc in (-1, 0, 1):
            for dr in (-1, 0, 1):
                if not (dc or dr):
                    continue
                w = cell * (math.sqrt(2) if dc and dr else 1.0)
                shifted = np.full_like(D, np.inf)  # shifted[r, c] = D[r + dr, c + dc]
                shifted[max(0, -dr):rows - max(0, dr), max(0, -dc):cols - max(0, dc)] = \
                    D[max(0, dr):rows + min(0, dr), max(0, dc):cols + min(0, dc)]
                best = np.minimum(best, shifted + w)
        best[blocked] = np.inf
        if np.array_equal(best, D):
            return D
        D = best


def test_cells_and_centres_follow_the_authors_conversion():
    assert authors_cell((0.05, -0.05)) == (100, 100)
    assert authors_cell((-9.95, 9.95)) == (0, 0)
    xs, ys = authors_cell_centres()
    assert xs[0, 0] == pytest.approx(-9.95) and ys[0, 0] == pytest.approx(9.95) and ys[199, 0] == pytest.approx(-9.95)
    goal = authors_goal_cells((7, 7))
    # Centres lie at odd multiples of 0.05 from the goal: inside the disc iff (2a+1)² + (2b+1)² < 400.
    assert goal.sum() == sum(1 for a in range(-11, 11) for b in range(-11, 11) if (2 * a + 1)**2 + (2 * b + 1)**2 < 400)


def test_the_cross_is_marked_as_the_authors_mark_it():
    blocked = authors_blocked_grid(CROSS)
    # Horizontal wall grown by 0.5 m: x in [−6.5, 6.5] → columns int(35.0) … int(165.0); y in [−1, 0.5] → rows
    # int(9.5/0.1) = 95 … int(11/0.1) = 110, both ends included (so one cell more on the +x and −y sides).
    horizontal = np.zeros_like(blocked)
    horizontal[95:111, 35:166] = True
    vertical = np.zeros_like(blocked)
    vertical[35:166, 90:106] = True
    assert np.array_equal(blocked, horizontal | vertical)
    assert blocked.sum() == 131 * 16 * 2 - 16 * 16


@pytest.mark.parametrize("start", [(5.05, -5.05), (-9.45, -9.45), (0.35, 9.05), (9.45, 0.05)])
def test_in_the_open_room_the_path_is_the_octile_distance_to_the_nearest_goal_cell(start):
    goal = (-7, 7)
    length, path = authors_optimal_path([], start, goal)
    xs, ys = authors_cell_centres()
    inside = authors_goal_cells(goal)
    c, r = authors_cell(start)
    dx = np.abs(np.round((xs[inside] - xs[r, c]) / 0.1))
    dy = np.abs(np.round((ys[inside] - ys[r, c]) / 0.1))
    octile = 0.1 * (np.maximum(dx, dy) - np.minimum(dx, dy)) + 0.1 * math.sqrt(2) * np.minimum(dx, dy)
    assert length == pytest.approx(octile.min(), abs=1e-9)
    assert path[0] == (c, r) and inside[path[-1][1], path[-1][0]]


@pytest.mark.parametrize("world", ["cross", "maze"])
def test_the_search_agrees_with_a_relaxation_over_the_same_grid(world):
    rects = CROSS if world == "cross" else MAZE
    blocked = authors_blocked_grid(rects)
    rng = np.random.default_rng(7)
    free = np.argwhere(~blocked)
    for goal in GOALS[::3]:  # (7, 7) and (−7, −7): a relaxation costs a second each
        targets = authors_goal_cells(goal)
        D = relaxed_distances(blocked, targets)
        for r, c in free[rng.choice(len(free), 5, replace=False)]:
            found = grid_shortest_path(blocked, (c, r), targets)
            assert found is not None, f"{world}: no path from cell {(c, r)} to {goal}"
            length, path = found
            assert length == pytest.approx(D[r, c], abs=1e-9)
            # A path of allowed moves: neighbours, none blocked, ending in a goal cell, as long as its steps.
            steps = np.diff(np.array(path), axis=0)
            assert np.all(np.abs(steps) <= 1) and np.all(np.abs(steps).sum(axis=1) >= 1)
            assert not any(blocked[rr, cc] for cc, rr in path) and targets[path[-1][1], path[-1][0]]
            assert length == pytest.approx(0.1 * np.hypot(steps[:, 0], steps[:, 1]).sum(), abs=1e-9)


def test_behind_the_cross_the_path_goes_round_the_grown_wall():
    # From (5.05, −5.05) to the disc round (−7, 7): the straight line crosses both walls' corner region; the path
    # must pass the grown cross outside its blocked cells, so it is longer than the straight distance less 1 m.
    length, path = authors_optimal_path(CROSS, (5.05, -5.05), (-7, 7))
    straight = math.hypot(5.05 + 7, -5.05 - 7) - 1.0
    assert length > straight + 0.5
    xs, ys = authors_cell_centres()
    blocked = authors_blocked_grid(CROSS)
    assert not any(blocked[r, c] for c, r in path)
    # It passes beyond one of the arms' grown ends (|x| or |y| ≥ 6.5 where it crosses the other axis).
    assert any(abs(xs[r, c]) >= 6.5 or abs(ys[r, c]) >= 6.5 for c, r in path)


def test_corner_cutting_and_walls_without_a_gap_on_hand_made_grids():
    blocked = np.zeros((3, 3), dtype=bool)
    blocked[0, 1] = blocked[1, 0] = True  # two blocked cells touching at a corner
    targets = np.zeros((3, 3), dtype=bool)
    targets[1, 1] = True
    length, path = grid_shortest_path(blocked, (0, 0), targets)
    assert length == pytest.approx(0.1 * math.sqrt(2)) and path == [(0, 0), (1, 1)]  # through the corner

    wall = np.zeros((5, 5), dtype=bool)
    wall[:, 2] = True
    targets = np.zeros((5, 5), dtype=bool)
    targets[2, 4] = True
    assert grid_shortest_path(wall, (0, 2), targets) is None  # no gap: unreachable
    wall[4, 2] = False  # a gap at the bottom row
    length, _ = grid_shortest_path(wall, (0, 2), targets)
    assert length == pytest.approx(0.1 * (2 * 2 * math.sqrt(2)))  # down two diagonals, up two diagonals
    assert grid_shortest_path(wall, (2, 0), targets) is None  # a blocked start
    assert grid_shortest_path(wall, (7, 0), targets) is None  # outside the grid


def test_oriented_rectangles_block_the_cells_inside_them_grown():
    # A 7 × 0.4 m wall at 45° through the origin (the later "one obstacle" world), grown by 0.5 m.
    blocked = authors_blocked_grid([], oriented=[(0.0, 0.0, 7.0, 0.4, math.radians(45))])
    xs, ys = authors_cell_centres()
    on_line = np.abs(xs - ys) / math.sqrt(2)
    along = np.abs(xs + ys) / math.sqrt(2)
    assert np.array_equal(blocked, (on_line <= 0.7) & (along <= 4.0))


@pytest.mark.parametrize("name, rects", [("authors-cross", CROSS), ("authors-maze", MAZE), ("authors-open", [])])
def test_the_world_files_hold_the_planners_rectangles_inside_their_outer_walls(source_dir, name, rects):
    import yaml

    world = yaml.safe_load((source_dir / "configs" / "worlds" / f"{name}.yaml").read_text())
    boxes = [o["box"] for o in world["objects"] if "box" in o]
    outer, inner = boxes[:4], boxes[4:]
    # The outer walls: 0.3 m thick, centred on ±10 m, so the walkable square ends at their inner faces, ±9.85 m.
    assert sorted((abs(b["center"][0]) + abs(b["center"][1]), min(b["size"][:2])) for b in outer) == [(10, 0.3)] * 4
    assert world["walkable"]["rect"] == [-9.85, -9.85, 9.85, 9.85]
    footprints = [((b["center"][0] - b["size"][0] / 2, b["center"][1] - b["size"][1] / 2),
                   (b["center"][0] + b["size"][0] / 2, b["center"][1] + b["size"][1] / 2)) for b in inner]
    assert np.allclose(np.array(footprints, dtype=float).reshape(-1, 4), np.array(rects, dtype=float).reshape(-1, 4))
