"""Writes the authors' own 20 × 20 m navigation worlds (SPEC §17.3) into configs/worlds/authors-*.yaml.

Read from their repository (bduke13/AlabiHippocampalModel): the obstacles as their path planner has them
(core/robot/webots_worlds.py; for the cross and the maze @19ec63c6) and the rest of each world (outer walls, heights,
arena) from its Webots file (webots/worlds/*.wbt). Their worlds use Webots' NUE frame (y up); a floor point (x, z)
of theirs is (x, y) here, so their coordinates (goals, walls, the planner's rectangles) keep their numbers. A wall
rotated by a about their y axis runs along (cos a, −sin a) in their (x, z): yaw −a here.
Run: /usr/bin/python3 docs/navigation/authors_worlds.py
"""

import math
import pathlib

ROOT = pathlib.Path(__file__).resolve().parents[2]

FOUR_GOALS = "(7, 7) red; (-7, 7) green; (7, -7) blue; (-7, -7) yellow (radius 1.0 when exploiting, 0.7 when learning)"

# The outer walls of the multi-goal worlds: Webots `Wall`s 0.3 m thick and 2.4 m high centred on ±10 m (north and
# south 20 m long, east and west 20.6 m), so their inner faces stand at ±9.85 m.
SHELL_WALLS = [((0, 10), (20, 0.3)), ((0, -10), (20, 0.3)), ((10, 0), (0.3, 20.6)), ((-10, 0), (0.3, 20.6))]
# The single-goal worlds have only the RectangleArena's own walls: 0.01 m thick, 0.5 m high, just outside its floor.
ARENA_WALLS = [((0, 10.005), (20.02, 0.01)), ((0, -10.005), (20.02, 0.01)), ((10.005, 0), (0.01, 20.02)),
               ((-10.005, 0), (0.01, 20.02))]

WORLDS = {
    "authors-open": dict(
        source="webots/worlds/20x20_multi_goal.wbt @26c3ab19; webots_worlds.py @19ec63c6 `20x20_multi_goal`",
        what="an open 20 × 20 m room", shell=(SHELL_WALLS, 2.4), walls=[], height=2.4, goals=FOUR_GOALS,
        start=[[1, 1]]),
    "authors-cross": dict(
        source="webots/worlds/20x20_cross_multi_goal.wbt @26c3ab19; webots_worlds.py @19ec63c6 "
        "`20x20_cross_multi_goal` (its two obstacles, `horizontal_wall` and `vertical_wall`)",
        what="two 12 × 0.5 m walls crossing near the centre", shell=(SHELL_WALLS, 2.4),
        walls=[((-6.0, -0.5), (6.0, 0.0)), ((-0.5, -6.0), (0.0, 6.0))], height=2.4, goals=FOUR_GOALS,
        start=[[1, 1]]),
    "authors-maze": dict(
        source="webots/worlds/20x20_maze_multi_goal.wbt @26c3ab19; webots_worlds.py @19ec63c6 "
        "`20x20_maze_multi_goal`",
        what="six 0.5 m thick internal walls", shell=(SHELL_WALLS, 2.4),
        walls=[((-10.0, 2.75), (-0.5, 3.25)), ((0.5, -3.45), (10.0, -2.95)), ((-4.25, -3.4), (-3.75, 3.0)),
               ((2.75, -2.7), (3.25, 3.7)), ((0.25, -10.0), (0.75, -7.0)), ((-1.25, 7.0), (-0.75, 10.0))],
        height=2.4, goals=FOUR_GOALS, start=[[1, 1]]),
    "authors-one-obstacle": dict(
        source="webots/worlds/20x20_1obstacle.wbt @01e669f5 (a later, single-goal world: not in the planner "
        "@26c3ab19; webots_worlds.py @552077b9 lists it with three walls 1 m thick, this file has one 0.4 m thick)",
        what="one 7 × 0.4 m wall, 1 m high, through the centre at 135°", shell=(ARENA_WALLS, 0.5),
        oriented=[((0.0, 0.0), (7.0, 0.4), 2.3554)], height=1.0, goals="(-7, 7) (radius 0.8 on its marker)"),
    "authors-two-obstacles": dict(
        source="webots/worlds/20x20_2obstacles.wbt @41d7602e (a later, single-goal world: not in the planner "
        "@26c3ab19; webots_worlds.py @552077b9 gives its walls 1 m thick, this file 0.4 m)",
        what="two parallel 7 × 0.4 m walls, 1 m high, at (±4, 0) at 135°", shell=(ARENA_WALLS, 0.5),
        oriented=[((4.0, 0.0), (7.0, 0.4), 2.3554), ((-4.0, 0.0), (7.0, 0.4), 2.3554)], height=1.0,
        goals="(-7, 7) (radius 0.8 on its marker)"),
}


def box(center, size, height, yaw_deg=None):
    yaw = "" if yaw_deg is None else f", yaw_deg: {yaw_deg:.4f}"
    return (f"  - box: {{center: [{center[0]:g}, {center[1]:g}, {height / 2:g}], "
            f"size: [{size[0]:g}, {size[1]:g}, {height:g}]{yaw}}}\n")


def world_text(name, w):
    walls, shell_height = w["shell"]
    inner = min(abs(c[0]) - s[0] / 2 if abs(c[0]) > 1 else abs(c[1]) - s[1] / 2 for c, s in walls)
    lines = [f"# The authors' navigation world {name}: {w['what']} (SPEC §17.3).\n",
             f"# From bduke13/AlabiHippocampalModel {w['source']}.\n",
             f"# Written by docs/navigation/authors_worlds.py. Their (x, z) is (x, y) here. Goals: {w['goals']}.\n",
             f"# Outer walls {shell_height:g} m high, inner faces at ±{inner:g} m; obstacles {w['height']:g} m high;"
             " no ceiling (their worlds have none).\n",
             "# Their path planner's obstacles are the boxes after the four outer walls.\n",
             f"name: {name}\nobjects:\n",
             "  - quad: [[-10, -10, 0], [10, -10, 0], [10, 10, 0], [-10, 10, 0]]  # floor\n"]
    lines += [box(c, s, shell_height) for c, s in walls]
    for (x0, y0), (x1, y1) in w.get("walls", []):
        lines.append(box(((x0 + x1) / 2, (y0 + y1) / 2), (x1 - x0, y1 - y0), w["height"]))
    for center, size, a in w.get("oriented", []):
        lines.append(box(center, size, w["height"], yaw_deg=-math.degrees(a)))
    lines.append(f"walkable: {{rect: [{-inner:g}, {-inner:g}, {inner:g}, {inner:g}]}}\n")
    if "start" in w:
        lines.append("start: {points: " + str(w["start"]).replace(" ", "") + "}  # where their learning walk starts\n")
    return "".join(lines)


if __name__ == "__main__":
    for name, w in WORLDS.items():
        (ROOT / "configs" / "worlds" / f"{name}.yaml").write_text(world_text(name, w))
