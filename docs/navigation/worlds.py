"""Writes the navigation worlds of SPEC §17 (the authors' 20 × 20 m family) into configs/worlds/.

The authors describe, without coordinates, an open room with goals at (±7, ±7), a cross of two 12 m walls, a maze
of six internal walls and a 9 m wall with a goal behind it at (−2, 2); the walls below are drawn from that
description (0.3 m thick, floor to the 2.5 m ceiling). Run: /usr/bin/python3 docs/navigation/worlds.py
"""

import pathlib

ROOT = pathlib.Path(__file__).resolve().parents[2]
H = 2.5
T = 0.3

SHELL = f"""  - quad: [[-10, -10, 0], [10, -10, 0], [10, 10, 0], [-10, 10, 0]]          # floor
  - quad: [[-10, -10, {H}], [-10, 10, {H}], [10, 10, {H}], [10, -10, {H}]]  # ceiling
  - quad: [[-10, -10, 0], [-10, 10, 0], [-10, 10, {H}], [-10, -10, {H}]]    # x = -10
  - quad: [[10, -10, 0], [10, -10, {H}], [10, 10, {H}], [10, 10, 0]]        # x = +10
  - quad: [[-10, -10, 0], [-10, -10, {H}], [10, -10, {H}], [10, -10, 0]]    # y = -10
  - quad: [[-10, 10, 0], [10, 10, 0], [10, 10, {H}], [-10, 10, {H}]]        # y = +10
"""


def wall(x0, y0, x1, y1):
    """An axis-aligned wall from (x0, y0) to (x1, y1), T thick, floor to ceiling."""
    cx, cy = (x0 + x1) / 2, (y0 + y1) / 2
    sx, sy = max(abs(x1 - x0), T), max(abs(y1 - y0), T)
    return f"  - box: {{center: [{cx:g}, {cy:g}, {H / 2:g}], size: [{sx:g}, {sy:g}, {H:g}]}}\n"


WORLDS = {
    "nav-open": ("an open 20 × 20 m room", [], "(7, 7); (-7, 7); (-7, -7); (7, -7)"),
    "nav-cross": ("two 12 m walls crossing at the centre", [wall(-6, 0, 6, 0), wall(0, -6, 0, 6)],
                  "(7, 7); (-7, 7); (-7, -7); (7, -7)"),
    "nav-maze": ("six internal walls", [wall(-10, 5, -3, 5), wall(3, 5, 10, 5), wall(-5, 0, 5, 0),
                                        wall(-10, -5, -3, -5), wall(3, -5, 10, -5), wall(0, -10, 0, -5)],
                 "(7, 7); (-7, 7); (-7, -7); (7, -7)"),
    "nav-wall": ("a 9 m wall with the goal (-2, 2) behind it", [wall(-6.5, 0.5, 2.5, 0.5)], "(-2, 2)"),
}

for name, (what, walls, goals) in WORLDS.items():
    text = (f"# Navigation world (docs/navigation.md#worlds): {what}, inside a 20 × 20 × {H} m room;\n"
            f"# written by docs/navigation/worlds.py. Goals: {goals}.\n"
            f"name: {name}\nobjects:\n{SHELL}{''.join(walls)}"
            "walkable: {rect: [-10, -10, 10, 10]}\nstart: {rect: [-9.5, -9.5, 9.5, 9.5]}\n")
    (ROOT / "configs" / "worlds" / f"{name}.yaml").write_text(text)
