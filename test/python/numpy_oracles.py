"""Oracles written out in numpy, shared by the tests (they share no code with bvc3d)."""
import numpy as np


def numpy_rate_maps(means, quantile):
    """docs/model-reference.md#analysis maps from per-bin means, written out in numpy: per cell, values below
    numpy.percentile(cell, 100 q) set to 0, then divided by the cell's maximum (silent: zeros)."""
    maps = means.copy()
    for k in range(maps.shape[1]):
        col = maps[:, k]
        col[col < np.percentile(col, 100 * quantile)] = 0
        top = col.max()
        maps[:, k] = col / top if top > 0 else 0.0
    return maps


# ---- The authors' optimal path (SPEC §17.3; their path_planning.py @26c3ab19), searched another way ----------------
# Their grid: cells of `cell` m over the square floor [−w/2, w/2] × [−h/2, h/2]; column int((x + w/2)/cell), row
# int((−y + h/2)/cell) (y inverted). An axis-aligned rectangle [x0, x1] × [y0, y1] inflated by `clearance` blocks
# columns int((x0 − c + w/2)/cell) … int((x1 + c + w/2)/cell) and rows int((−(y1 + c) + h/2)/cell) …
# int((−(y0 − c) + h/2)/cell), both ends included, clamped to the grid (the same float expressions, so the same
# cells). The floor's outer walls are not obstacles. Moves: 8 neighbours, a diagonal allowed between two blocked cells
# (corner cutting). The path runs from the start's cell to the nearest cell whose centre lies within `radius` of the
# goal; its length is the sum of the straight steps between cell centres. They search with A* (diagonal cost 1.414,
# an in-place decrease of keys); this is Dijkstra with the exact costs, so it gives the true minimum over the same
# grid and moves.


def authors_cell(p, size=(20.0, 20.0), cell=0.1):
    """(column, row) of the point p = (x, y) on the authors' grid."""
    return int((p[0] + size[0] / 2) / cell), int((-p[1] + size[1] / 2) / cell)


def authors_blocked_grid(rectangles, size=(20.0, 20.0), cell=0.1, clearance=0.5, oriented=()):
    """Blocked cells (rows × columns, bool) for axis-aligned rectangles ((x0, y0), (x1, y1)) as the authors mark them,
    and, for `oriented` rectangles (cx, cy, length, thickness, yaw_rad) their planner never had, the cells whose
    centre lies inside the rectangle grown by `clearance` on each side (square corners, as for the others)."""
    cols, rows = int(size[0] / cell), int(size[1] / cell)
    blocked = np.zeros((rows, cols), dtype=bool)
    half_w, half_h = size[0] / 2, size[1] / 2
    for (x0, y0), (x1, y1) in rectangles:
        x0, y0, x1, y1 = x0 - clearance, y0 - clearance, x1 + clearance, y1 + clearance
        c0, c1 = max(0, int((x0 + half_w) / cell)), min(cols - 1, int((x1 + half_w) / cell))
        r0, r1 = max(0, int((-y1 + half_h) / cell)), min(rows - 1, int((-y0 + half_h) / cell))
        blocked[r0:r1 + 1, c0:c1 + 1] = True
    if oriented:
        xs, ys = authors_cell_centres(size, cell)
        for cx, cy, length, thickness, yaw in oriented:
            u = (xs - cx) * np.cos(yaw) + (ys - cy) * np.sin(yaw)
            v = -(xs - cx) * np.sin(yaw) + (ys - cy) * np.cos(yaw)
            blocked |= (np.abs(u) <= length / 2 + clearance) & (np.abs(v) <= thickness / 2 + clearance)
    return blocked


def authors_cell_centres(size=(20.0, 20.0), cell=0.1):
    """x and y of every cell's centre (rows × columns arrays)."""
    cols, rows = int(size[0] / cell), int(size[1] / cell)
    col, row = np.meshgrid(np.arange(cols), np.arange(rows))
    return col * cell - size[0] / 2 + cell / 2, -(row * cell - size[1] / 2 + cell / 2)


def authors_goal_cells(goal, radius=1.0, size=(20.0, 20.0), cell=0.1):
    """The cells whose centre lies within `radius` of the goal (rows × columns, bool)."""
    xs, ys = authors_cell_centres(size, cell)
    return np.hypot(xs - goal[0], ys - goal[1]) <= radius


def grid_shortest_path(blocked, start, targets, cell=0.1):
    """Dijkstra over 8 neighbours (corner cutting allowed) from the start cell (column, row) to the nearest target
    cell (targets: rows × columns, bool), costs cell and cell·√2. Returns (length, [(column, row), ...]), or None
    when the start is blocked or outside the grid, or no target can be reached."""
    import heapq

    rows, cols = blocked.shape
    c0, r0 = start
    if not (0 <= c0 < cols and 0 <= r0 < rows) or blocked[r0, c0]:
        return None
    steps = [(dc, dr, cell * (np.sqrt(2.0) if dc and dr else 1.0)) for dc in (-1, 0, 1) for dr in (-1, 0, 1)
             if dc or dr]
    dist = np.full((rows, cols), np.inf)
    parent = {}
    dist[r0, c0] = 0.0
    heap = [(0.0, c0, r0)]
    while heap:
        d, c, r = heapq.heappop(heap)
        if d > dist[r, c]:
            continue
        if targets[r, c]:
            path = [(c, r)]
            while path[-1] in parent:
                path.append(parent[path[-1]])
            return d, path[::-1]
        for dc, dr, w in steps:
            cn, rn = c + dc, r + dr
            if 0 <= cn < cols and 0 <= rn < rows and not blocked[rn, cn] and d + w < dist[rn, cn]:
                dist[rn, cn] = d + w
                parent[(cn, rn)] = (c, r)
                heapq.heappush(heap, (d + w, cn, rn))
    return None


def authors_optimal_path(rectangles, start, goal, radius=1.0, size=(20.0, 20.0), cell=0.1, clearance=0.5,
                         oriented=()):
    """SPEC §17.3's optimal path from the point `start` to the goal disc: (length in m, cells) or None."""
    blocked = authors_blocked_grid(rectangles, size, cell, clearance, oriented)
    return grid_shortest_path(blocked, authors_cell(start, size, cell), authors_goal_cells(goal, radius, size, cell),
                              cell)
