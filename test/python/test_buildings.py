"""Buildings on real Gazebo worlds (docs/buildings.md): the AWS RoboMaker hospital and small house, read
from ../shared/data/gazebo beside the source tree (skipped when absent).

Oracles: gazebo_oracle.py reads the SDF poses and Collada meshes with xml.etree and numpy (no
SDFormat, no assimp); clearance, coverage and revisits of a tour are computed here in numpy from the
world's triangles; the real sensors' beam elevations come from SPEC §14's numbers written out here.
"""
import math
import os

import numpy as np
import pytest
from scipy import ndimage
from sklearn.neighbors import KDTree

import bvc3d
import gazebo_oracle
from conftest import SOURCE_DIR

GAZEBO = SOURCE_DIR.parent / "shared" / "data" / "gazebo"
HOSPITAL = GAZEBO / "aws-robomaker-hospital-world"
HOUSE = GAZEBO / "aws-robomaker-small-house-world"
needs_data = pytest.mark.skipif(
    not HOSPITAL.is_dir() or not HOUSE.is_dir(),
    reason=f"the Gazebo worlds are not in {GAZEBO} (shared data, not part of the repository)")

RADIUS, HEIGHT, STEP = 0.25, 0.10, 0.02  # the robot's body and the buildings' step height


@pytest.fixture(scope="module")
def hospital():
    return bvc3d.World.from_sdf(HOSPITAL / "worlds" / "hospital.world", missing_models="skip")


def world_triangles(world, part):
    t = world.triangles[part["first_triangle"]:part["first_triangle"] + part["triangle_count"]]
    return t + np.array([0.0, 0.0, world.floor_z])  # back in the file's frame


def nondegenerate(tri):
    area = 0.5 * np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1)
    return tri[area > 1e-12], area[area > 1e-12]


@needs_data
@pytest.mark.parametrize("world_file, models", [
    (HOSPITAL / "worlds" / "hospital.world", HOSPITAL / "models"),
    (HOUSE / "worlds" / "small_house.world", HOUSE / "models"),
], ids=["hospital", "small_house"])
def test_every_mesh_is_where_its_sdf_pose_puts_it(world_file, models):
    world = bvc3d.World.from_sdf(world_file, missing_models="skip")
    parts = {p["name"]: p for p in world.parts}
    geometry, missing = gazebo_oracle.world_geometry(str(world_file), [str(models)])
    meshes = [g for g in geometry if g.kind == "mesh"]
    assert len(meshes) > 30
    cache = {}
    for g in meshes:
        assert g.path in parts, f"{g.path} is not a part of the world (parts: {sorted(parts)[:5]} ...)"
        mine, my_area = nondegenerate(world_triangles(world, parts[g.path]))
        theirs, their_area = nondegenerate(gazebo_oracle.placed_mesh(g, [str(models)], cache))
        # The same surface: the same total area, every vertex of one a vertex of the other (assimp reads
        # floats and may triangulate polygons along other diagonals, so triangles are not compared).
        assert my_area.sum() == pytest.approx(their_area.sum(), rel=1e-5, abs=1e-6), g.path
        mv, tv = mine.reshape(-1, 3), theirs.reshape(-1, 3)
        for a, b in ((mv, tv), (tv, mv)):
            d, _ = KDTree(b).query(a, k=1)
            assert d.max() < 2e-5, f"{g.path}: a vertex {d.max():.2e} m from the other's"
    # Every part the oracle places is there, nothing more (Gazebo's own ground plane aside).
    named = {g.path for g in geometry}
    extra = {n for n in parts if n not in named and not n.endswith("ground_plane/link/visual")}
    assert not extra
    # The missing models are the Fuel models the worlds name but do not ship.
    assert len(missing) == (110 if "hospital" in str(world_file) else 0)


def slab_segments(triangles, z_lo, z_hi):
    """The floor-plane outline of every triangle's part within z_lo <= z <= z_hi, as 2-D segments
    (the body's obstacles, clipped here independently of the library)."""
    segs = []
    for tri in triangles:
        z = tri[:, 2]
        if z.max() < z_lo or z.min() > z_hi:
            continue
        poly = list(tri)
        for z0, sign in ((z_lo, 1.0), (z_hi, -1.0)):
            out = []
            for i in range(len(poly)):
                a, b = poly[i], poly[(i + 1) % len(poly)]
                da, db = sign * (a[2] - z0), sign * (b[2] - z0)
                if da >= 0:
                    out.append(a)
                if (da >= 0) != (db >= 0):
                    out.append(a + (da / (da - db)) * (b - a))
            poly = out
            if not poly:
                break
        for i in range(len(poly)):
            segs.append((poly[i][:2], poly[(i + 1) % len(poly)][:2]))
    return np.array(segs).reshape(-1, 2, 2)


def distance_to_segments(points, segs, within=1.0):
    """Exact distance from each point to the nearest segment, for distances up to `within` (inf
    beyond): segments cut into pieces of at most 0.5 m, the pieces near each point checked."""
    counts = np.maximum(1, np.ceil(np.linalg.norm(segs[:, 1] - segs[:, 0], axis=1) / 0.5).astype(int))
    whole = np.repeat(np.arange(len(segs)), counts)
    j = np.arange(len(whole)) - np.repeat(np.cumsum(counts) - counts, counts)  # piece's index in its segment
    a, ab, n = segs[whole, 0], segs[whole, 1] - segs[whole, 0], counts[whole][:, None]
    segs = np.stack([a + (j[:, None] / n) * ab, a + ((j[:, None] + 1) / n) * ab], axis=1)
    tree = KDTree(segs.mean(axis=1))
    out = np.full(len(points), np.inf)
    for start in range(0, len(points), 20000):  # every (point, nearby piece) pair at once, in chunks
        chunk = points[start : start + 20000]
        near = tree.query_radius(chunk, r=within + 0.25)
        owner = np.repeat(np.arange(len(chunk)), [len(idx) for idx in near])
        if len(owner) == 0:
            continue
        piece = np.concatenate(near)
        a, ab, p = segs[piece, 0], segs[piece, 1] - segs[piece, 0], chunk[owner]
        t = np.clip(np.einsum("ij,ij->i", p - a, ab) / np.maximum(np.einsum("ij,ij->i", ab, ab), 1e-300), 0, 1)
        d = np.linalg.norm(p - (a + t[:, None] * ab), axis=1)
        first = np.r_[0, np.flatnonzero(np.diff(owner)) + 1]  # owner is sorted: each point's pairs in a row
        out[start + owner[first]] = np.minimum.reduceat(d, first)
    out[out > within] = np.inf
    return out


@needs_data
def test_a_tour_of_the_hospital_is_clear_covers_the_floor_and_drives_back(hospital):
    tour = bvc3d.tour(hospital)
    x, y, h = tour["x"], tour["y"], tour["heading"]
    path = np.c_[x, y]
    assert np.all(np.diff(tour["t"]) > 0)
    assert np.hypot(x[0] - x[-1], y[0] - y[-1]) == 0  # closed

    # Clear of geometry by the body's radius at every step: the obstacles are the triangles' parts
    # between the step height and the body's top, and the drop edges where the floor ends. (Between
    # steps the path is straight or an arc: a chord between two steps would cut the arc's corner.)
    obstacles = np.concatenate([slab_segments(hospital.triangles, STEP, HEIGHT), hospital.drop_edges])
    clearance = distance_to_segments(path, obstacles)
    assert clearance.min() >= RADIUS - 1e-6, f"the body comes {RADIUS - clearance.min():.3g} m into geometry"

    # Coverage: the walkable region on a 0.1 m grid (cells where the body fits, inside the walkable
    # rectangle, connected to the start), and the part of it within 1 m of the path.
    lo, hi = hospital.walkable.min(axis=0), hospital.walkable.max(axis=0)
    xs, ys = np.arange(lo[0] + 0.05, hi[0], 0.1), np.arange(lo[1] + 0.05, hi[1], 0.1)
    cx, cy = np.meshgrid(xs, ys)
    centers = np.c_[cx.ravel(), cy.ravel()]
    room = distance_to_segments(centers, obstacles).reshape(cx.shape)
    fits = room >= RADIUS
    labels, _ = ndimage.label(fits, structure=np.ones((3, 3)))
    start = labels[np.argmin(np.abs(ys - y[0])), np.argmin(np.abs(xs - x[0]))]
    assert start > 0
    region = labels == start
    dense = np.concatenate([np.linspace(path[i], path[i + 1], 6, endpoint=False) for i in range(len(path) - 1)])
    near, _ = KDTree(dense).query(centers[region.ravel()], k=1)
    coverage = np.mean(near[:, 0] <= 1.0)
    assert coverage >= 0.9, coverage
    assert coverage == pytest.approx(tour["stats"]["coverage"], abs=0.02)
    assert region.sum() * 0.01 > 800  # m²: most of the floor, not a pocket

    # Part of the building driven again in the opposite direction: steps within 1 m of a step at
    # least 3 m of path earlier, heading at least 135° from it.
    along = np.r_[0, np.cumsum(np.hypot(np.diff(x), np.diff(y)))]
    tree = KDTree(path)
    reverse = 0.0
    for i, idx in enumerate(tree.query_radius(path, r=1.0)):
        earlier = idx[along[idx] <= along[i] - 3.0]
        if len(earlier) and np.any(np.abs(np.angle(np.exp(1j * (h[earlier] - h[i])))) >= math.radians(135)):
            reverse += along[i] - along[i - 1]
    assert reverse >= 10.0
    assert reverse == pytest.approx(tour["stats"]["reverse_length"], rel=0.05)


def spec_elevations_deg(name):
    """SPEC §14: top to bottom, evenly spaced."""
    top, bottom, n = {"vlp16": (15, -15, 16), "hdl32": (10.67, -30.67, 32), "hdl64": (2.0, -24.9, 64),
                      "os1-64": (22.5, -22.5, 64), "os1-128": (22.5, -22.5, 128)}[name]
    return np.linspace(top, bottom, n)


@needs_data
@pytest.mark.parametrize("name", ["vlp16", "hdl32", "hdl64", "os1-64", "os1-128"])
def test_scans_of_each_real_sensor_carry_the_tables_elevations(hospital, name):
    table = {m["name"]: m for m in bvc3d.lidar_models()}[name]
    np.testing.assert_allclose(table["elevations_deg"], spec_elevations_deg(name), rtol=0, atol=1e-12)
    # Raised to 1.5 m in a corridor (3 m high), so that no beam meets floor or ceiling within its
    # minimum range: a closed building, so most beams return.
    scan = hospital.scan(name, -2.0, -12.0, 0.3, noise_seed=1, z=1.5 - table["height"])
    assert len(scan) > 0.9 * table["columns"] * len(table["elevations_deg"])
    elevations = np.unique(scan[:, 2])
    np.testing.assert_allclose(np.sort(np.degrees(elevations))[::-1], spec_elevations_deg(name), atol=1e-9)
    assert scan[:, 0].min() >= table["min_range"] and scan[:, 0].max() <= table["max_range"]


@needs_data
def test_three_storeys_load_and_walk_on_the_chosen_floor():
    world = bvc3d.World.from_sdf(HOSPITAL / "worlds" / "hospital_three_floors.world", missing_models="skip",
                                 floor_z=3.0, flight_volume=True)
    assert world.floor_z == pytest.approx(3.0, abs=1e-3)
    walk = bvc3d.random_walk(world, 0.1, 3)
    # On the second storey (now z = 0): a ray down from the robot meets its floor just below.
    for i in range(0, len(walk["x"]), 100):
        scan = world.scan(bvc3d.Sensor(elevations=[-math.pi / 2], azimuth_count=1, height=0.5, max_range=2),
                          walk["x"][i], walk["y"][i], 0.0)
        assert scan[0, 0] == pytest.approx(0.5, abs=0.01)
    fv = world.flight_volume
    assert fv["z_min"] == pytest.approx(0.2) and 2.5 < fv["z_max"] < 3.0  # a 3 m storey


ROOM_WORLD = """<?xml version="1.0"?>
<sdf version="1.6"><world name="room">{}</world></sdf>
"""


def box(name, center, size, yaw=0.0):
    return (f'<model name="{name}"><static>true</static><pose>{center[0]} {center[1]} {center[2]} 0 0 {yaw}</pose>'
            f'<link name="l"><visual name="v"><geometry><box><size>{size[0]} {size[1]} {size[2]}</size></box>'
            f'</geometry></visual></link></model>')


def test_routes_and_tours_of_a_hand_made_world_feed_the_rest(tmp_path, cli):
    """No shared data needed: a room of SDF boxes, a route and a tour through it, by Python and by the
    program, written and read back, and a trial that follows the route."""
    models = [box("floor", (0, 0, -0.1), (8, 8, 0.2)), box("n", (0, 4.05, 1), (8.2, 0.1, 2)),
              box("s", (0, -4.05, 1), (8.2, 0.1, 2)), box("e", (4.05, 0, 1), (0.1, 8, 2)),
              box("w", (-4.05, 0, 1), (0.1, 8, 2)), box("pillar", (1, 1, 1), (0.6, 0.6, 2), 0.4)]
    (tmp_path / "worlds").mkdir()
    world_file = tmp_path / "worlds" / "room.world"
    world_file.write_text(ROOM_WORLD.format("\n".join(models)))
    world = bvc3d.World.from_sdf(world_file)
    assert [p["name"] for p in world.parts] == [f"room/{m}/l/v" for m in ("floor", "n", "s", "e", "w", "pillar")]
    assert world.floor_z == 0.0 and len(world.triangles) == 6 * 12

    waypoints = np.array([[-3, -3], [3, -3], [3, 3], [-3, 3]], float)
    route = bvc3d.route(world, waypoints)
    assert (route["x"][0], route["y"][0]) == (-3, -3) and (route["x"][-1], route["y"][-1]) == (-3, 3)
    bvc3d.write_trajectory(tmp_path / "py.csv", route)
    (tmp_path / "points.txt").write_text("# x y\n-3 -3\n3,-3\n3 3\n-3 3\n")
    cli("route", "--world", world_file, "--waypoints", tmp_path / "points.txt", "--out", tmp_path / "cli.csv",
        check=True)
    assert (tmp_path / "cli.csv").read_text() == (tmp_path / "py.csv").read_text()
    back = bvc3d.read_trajectory(tmp_path / "cli.csv")
    for k in ("t", "x", "y", "heading"):
        np.testing.assert_array_equal(back[k], route[k])

    tour = bvc3d.tour(world)
    assert tour["stats"]["coverage"] >= 0.9 and tour["stats"]["reverse_length"] >= 10
    proc = cli("route", "--world", world_file, "--tour", "--out", tmp_path / "tour.csv", check=True)
    assert "passes within 1 m of" in proc.stdout
    np.testing.assert_array_equal(bvc3d.read_trajectory(tmp_path / "tour.csv")["x"], tour["x"])

    trial = bvc3d.run_trial(model="2d", world=str(world_file), trajectory=str(tmp_path / "cli.csv"),
                            explore_hours=0, sample_hours=0.005)
    np.testing.assert_array_equal(trial["x"], route["x"][:len(trial["x"])])
