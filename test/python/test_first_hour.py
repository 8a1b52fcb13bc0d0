"""What a robotics engineer and a neuroscientist hit in their first hour with the newer features (issue 43):
bags and scan folders in place recognition, Python signatures as documented, grid cells fed by path
integration, one page of the Python API, worlds given as paths or objects, the analysis at a building's
scale, figures of routes, and messages that say what is wrong without printing the input."""
import csv
import inspect
import math
import pathlib
import re
import subprocess
import sys

import numpy as np
import pytest

import bvc3d
from conftest import CLI, SOURCE_DIR, run_cli


def read_table(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def error_line(proc):
    """The one `bvc3d: error:` line of a refused command (exit 2, nothing else gone wrong)."""
    assert proc.returncode == 2, proc.stderr
    lines = [l for l in proc.stderr.splitlines() if l.startswith("bvc3d: error:")]
    assert len(lines) == 1, proc.stderr
    return lines[0]


def plain_message(text):
    """A message that names what is wrong without printing an object's repr or an array."""
    assert "object at 0x" not in text and "array(" not in text and "Invoked with" not in text, text
    assert len(text) < 600, text


# ---- 1, 4: place recognition on bags and on scan folders ----------------------------------------------

@pytest.fixture(scope="module")
def exported(tmp_path_factory):
    """One walk of the cross arena exported three ways: a scan folder (with scans.txt and its times), a
    ROS 1 bag and an MCAP file."""
    d = tmp_path_factory.mktemp("exported")
    walk = ["--world", "cross", "--hours", "0.012", "--seed", "5", "--sensor", "horizontal"]
    run_cli("export-scans", *walk, "--format", "pcd-f8", "--out", d / "run", check=True)
    run_cli("export-scans", *walk, "--format", "ros1", "--out", d / "run.bag", check=True)
    run_cli("export-scans", *walk, "--format", "mcap", "--out", d / "run.mcap", check=True)
    return d


def place_recognition_cli(out, *source):
    proc = run_cli("place-recognition", *source, "--descriptors", "bvc:2d,scan-context", "--out", out,
                   "--no-figures", check=True)
    return proc.stdout, read_table(out / "summary.csv"), read_table(out / "queries.csv")


@pytest.mark.parametrize("bag", ["run.bag", "run.mcap"])
def test_place_recognition_reads_a_bag_as_its_help_says(exported, tmp_path, bag):
    """Finding 1: --bag with its topics is a recording, as in every other command that reads one; the
    bag's scans give what the same scans written as files give."""
    _, files, files_q = place_recognition_cli(tmp_path / "files", "--scans", exported / "run" / "scans.txt",
                                              "--poses", exported / "run" / "poses.txt")
    _, bags, bags_q = place_recognition_cli(tmp_path / "bag", "--bag", exported / bag, "--cloud-topic", "/points",
                                            "--pose-topic", "/odom")
    assert [(r["descriptor"], r["queries"], r["revisits"]) for r in bags] == \
        [(r["descriptor"], r["queries"], r["revisits"]) for r in files]
    assert [q["match"] for q in bags_q] == [q["match"] for q in files_q]
    np.testing.assert_allclose([float(q["distance"]) for q in bags_q], [float(q["distance"]) for q in files_q],
                               atol=1e-4)
    proc = run_cli("place-recognition", "--bag", exported / bag, "--cloud-topic", "/points", "--pose-topic", "/odom",
                   "--scans", exported / "run", "--descriptors", "scan-context", "--out", tmp_path / "both")
    assert "not both" in error_line(proc) and not (tmp_path / "both").exists()


def kitti_poses(exported, path):
    """The export's poses without their times: KITTI rows (the 3 x 4 matrix), as the KITTI conversion writes."""
    m = np.loadtxt(exported / "run" / "poses.txt", delimiter=",", usecols=range(4)).reshape(-1, 4, 4)
    np.savetxt(path, m[:, :3, :].reshape(-1, 12), fmt="%.17g")
    return path


def test_a_scan_folder_reads_its_times_file(exported, tmp_path):
    """Finding 4: a folder holding scans.txt (as export-scans and the KITTI conversion write it) is read
    with the list's times, as the list itself is: the same queries, the exclusion window in seconds."""
    poses = kitti_poses(exported, tmp_path / "poses.kitti")
    out_list, list_summary, list_q = place_recognition_cli(tmp_path / "list", "--scans",
                                                           exported / "run" / "scans.txt", "--poses", poses)
    out_dir, dir_summary, dir_q = place_recognition_cli(tmp_path / "dir", "--scans", exported / "run", "--poses",
                                                        poses)
    assert dir_q == list_q
    assert [{k: v for k, v in r.items() if not k.endswith("_s")} for r in dir_summary] == \
        [{k: v for k, v in r.items() if not k.endswith("_s")} for r in list_summary]
    assert all(r["timed"] == "1" for r in dir_summary)
    # Scans 0.288 s apart: the 30 s window (104 scans) leaves fewer queries than 50 scans would.
    t = np.array([float(r["t"]) for r in read_table(tmp_path / "dir" / "scans.csv")])
    np.testing.assert_allclose(t, np.loadtxt(exported / "run" / "scans.txt", usecols=1))
    assert int(dir_summary[0]["queries"]) < len(t) - 51
    assert "no times" not in out_dir
    rec = bvc3d.Recording.open(exported / "run", poses)
    np.testing.assert_array_equal(rec.times, t)


def test_a_recording_without_times_says_so(exported, tmp_path):
    """Finding 4: scans without times (a list without them, KITTI poses) are excluded by scan count only and
    counted one a second for the drift; the output and the summary say so."""
    listing = tmp_path / "untimed.txt"
    listing.write_text("".join(f"{p}\n" for p in sorted((exported / "run").glob("*.pcd"))))
    out, summary, _ = place_recognition_cli(tmp_path / "untimed", "--scans", listing, "--poses",
                                            kitti_poses(exported, tmp_path / "poses.kitti"))
    assert "no times" in out, out
    assert all(r["timed"] == "0" for r in summary)
    assert all(r["timed"] == "0" for r in read_table(tmp_path / "untimed" / "details.csv"))


# ---- 2: Python signatures as documented ----------------------------------------------------------------

PYTHON_PAGE = SOURCE_DIR / "docs" / "python.md"
CLASSES = ["Sensor", "BoundaryVectorLayer", "PlaceCellNetwork", "HeadDirectionCells", "GridCells",
           "GrowingPlaceCells"]
REQUIRED = {"n_bvc": 48}  # values for the parameters documented without a default


def documented_signature(name):
    """The parameters of `name(...)` as docs/python.md writes them: [(key, default or REQUIRED)]."""
    text = PYTHON_PAGE.read_text()
    m = re.search(r"`" + name + r"\(([^`]*)\)`", text)
    assert m, f"docs/python.md gives no signature `{name}(...)`"
    params = []
    for part in re.split(r",\s*(?![^\[]*\])", m.group(1)):
        key, _, value = part.partition("=")
        key = key.strip()
        value = re.sub(r"√([\d.]+)", r"math.sqrt(\1)", value)
        params.append((key, eval(value, {"math": math}) if value else REQUIRED[key]))
    return params


def attributes(obj, keys):
    out = {}
    for k in keys:
        if k == "seed" or not hasattr(obj, k):
            continue
        v = getattr(obj, k)
        out[k] = list(v) if isinstance(v, (list, tuple, np.ndarray)) else v
    return out


def same(a, b):
    assert a.keys() == b.keys()
    for k in a:
        np.testing.assert_allclose(np.asarray(a[k], dtype=float) if not isinstance(a[k], str) else 0,
                                   np.asarray(b[k], dtype=float) if not isinstance(b[k], str) else 0, err_msg=k)
        if isinstance(a[k], str):
            assert a[k] == b[k], k


@pytest.mark.parametrize("name", CLASSES)
def test_every_class_takes_its_documented_signature_positionally_and_by_keyword(name):
    """Finding 2: each class's signature in docs/python.md, every parameter with its documented default,
    works by keyword and positionally in the documented order, and each parameter with an attribute
    holds the documented default."""
    cls = getattr(bvc3d, name)
    params = documented_signature(name)
    keys = [k for k, _ in params]
    by_keyword = cls(**dict(params))
    positional = cls(*[v for _, v in params])
    attrs = attributes(by_keyword, keys)
    same(attrs, attributes(positional, keys))
    for k, v in params:
        if k in attrs and k not in REQUIRED:
            same({k: attrs[k]}, {k: v})
    # The documented signature is the whole signature: one positional argument more is refused.
    with pytest.raises((ValueError, TypeError), match="positional"):
        cls(*[v for _, v in params], 1)


def test_positional_arguments_mean_what_the_docs_say():
    """Finding 2's cases: GridCells' first argument is the spacing, not the seed; GrowingPlaceCells'
    third is the budget."""
    assert bvc3d.GridCells(6).spacing == 6.0
    assert bvc3d.GridCells(4, 0.1).orientation == 0.1
    np.testing.assert_array_equal(bvc3d.GridCells(4, 0, 8, 800, "pose", 0.01, 7).phases,
                                  bvc3d.GridCells(seed=7).phases)
    assert not np.array_equal(bvc3d.GridCells(seed=7).phases, bvc3d.GridCells(seed=0).phases)
    g = bvc3d.GrowingPlaceCells(960, 0, 500)
    assert g.budget == 500 and g.n_bvc == 960
    assert bvc3d.GrowingPlaceCells(960, 3, 500, 10, 0.7).threshold == 0.7
    net = bvc3d.PlaceCellNetwork(48, 1, 0, 40, 0.3)
    assert net.n_place == 40 and net.p_connect == 0.3
    with pytest.raises(ValueError, match="given twice"):
        bvc3d.GridCells(5, spacing=4)


# ---- 3: grid cells fed by path integration -------------------------------------------------------------

def test_grid_cells_fed_by_the_path_integrate_it_with_noise():
    """Finding 3: with input='path' the rates are those of the integrated estimate, which starts at the
    path's first position and adds each step's displacement plus N(0, path_noise²) per axis (SPEC §16):
    the estimate's error increments are independent normals of that sd, and the rates are the true
    position's rates at the estimate."""
    rng = np.random.default_rng(1)
    n, sd = 20000, 0.05
    xy = np.cumsum(rng.normal(0, 0.1, (n, 2)), axis=0)
    pose = bvc3d.GridCells(input="pose", seed=3)
    path = bvc3d.GridCells(input="path", path_noise=sd, seed=3)
    estimate = path.integrate(xy)
    assert estimate.shape == (n, 2)
    np.testing.assert_array_equal(estimate[0], xy[0])
    noise = np.diff(estimate - xy, axis=0)
    assert abs(noise.mean()) < 4 * sd / math.sqrt(2 * n)
    assert abs(noise.std() / sd - 1) < 4 / math.sqrt(2 * n)
    assert abs(np.corrcoef(noise[:-1, 0], noise[1:, 0])[0, 1]) < 4 / math.sqrt(n)
    assert abs(np.corrcoef(noise[:, 0], noise[:, 1])[0, 1]) < 4 / math.sqrt(n)
    rates = path.rates(xy)
    np.testing.assert_array_equal(rates, pose.rates(estimate))
    assert not np.array_equal(rates, pose.rates(xy))
    # Seeded: the same seed, the same path; another seed, another.
    np.testing.assert_array_equal(bvc3d.GridCells(input="path", path_noise=sd, seed=3).integrate(xy), estimate)
    assert not np.array_equal(bvc3d.GridCells(input="path", path_noise=sd, seed=4).integrate(xy), estimate)
    # Without noise the estimate is the path (to rounding), and fed the true position nothing is integrated.
    np.testing.assert_allclose(bvc3d.GridCells(input="path", path_noise=0).integrate(xy), xy, atol=1e-9)
    np.testing.assert_array_equal(pose.integrate(xy), xy)


# ---- 9: the analysis at a building's scale ----------------------------------------------------------------

HALL_YAML = """name: hall
objects:
  - box: {center: [0, -10.1, 1.5], size: [40.4, 0.2, 3]}
  - box: {center: [0, 10.1, 1.5], size: [40.4, 0.2, 3]}
  - box: {center: [-20.1, 0, 1.5], size: [0.2, 20.4, 3]}
  - box: {center: [20.1, 0, 1.5], size: [0.2, 20.4, 3]}
  - box: {center: [0, 0, 1.5], size: [24, 8, 3]}
  - box: {center: [-14, 4, 1.5], size: [1, 1, 3]}
  - box: {center: [12, -6, 1.5], size: [2, 1, 3]}
walkable: {rect: [-20, -10, 20, 10]}
"""


def laps(n_laps):
    """Laps of a 32 x 14 m rectangle around the hall's central block, 0.144 m a model step: lines, not areas."""
    corners = np.array([[-16, -7], [16, -7], [16, 7], [-16, 7], [-16, -7]], dtype=float)
    pts = [corners[0]]
    for a, b in zip(corners[:-1], corners[1:]):
        k = int(round(np.linalg.norm(b - a) / 0.144))
        pts += [a + (b - a) * (i + 1) / k for i in range(k)]
    lap = np.array(pts[:-1])
    xy = np.tile(lap, (n_laps, 1))
    heading = np.arctan2(*np.diff(np.r_[xy, xy[:1]], axis=0).T[::-1])
    return {"t": np.arange(len(xy)) * 0.288, "x": xy[:, 0], "y": xy[:, 1], "heading": heading}, len(lap)


def warnings_of(**kw):
    import warnings
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        r = bvc3d.run_trial(model="2d", **kw)
    return r, [str(w.message) for w in caught if issubclass(w.category, UserWarning)]


def test_analysis_settings_that_cannot_work_in_a_building_are_named(tmp_path):
    """Finding 9: the arena's settings in a 40 x 20 m hall walked along lines: the hexagons (gridsize 50) are
    several times the arena's and the path covers lines, so no bin has 20 visited bins within 1 m and DBSCAN
    can find no field. The warning names the keys and values to give; with them the metrics mean something.
    One lap only: the decoded half lies where the first half never was, and the warning says so."""
    world = tmp_path / "hall.yaml"
    world.write_text(HALL_YAML)
    path, n_lap = laps(3)
    r, messages = warnings_of(world=str(world), trajectory=path, explore_hours=n_lap * 0.288 / 3600,
                              sample_hours=2 * n_lap * 0.288 / 3600)
    field = [m for m in messages if "min_samples = 20" in m]
    assert len(field) == 1, messages
    assert "no visited bin has 20 visited bins within eps = 1 m" in field[0] and "frac_active" in field[0]
    gridsize = int(re.search(r"analysis key gridsize: (\d+)", field[0]).group(1))
    suggested = re.search(r"analysis key min_samples, e\.g\. (\d+)", field[0])
    min_samples = int(suggested.group(1)) if suggested else 20
    assert r["metrics"]["frac_active"] == 0  # what the warning is about
    # The hexagons the suggestion gives are the paper's arena's within 20 %.
    a = bvc3d.analysis.analyze(r["x"], r["y"], r["rates"], gridsize=gridsize, min_samples=min_samples)
    assert 0.8 < a["bin_area_m2"] / (0.5 * (9.2 / 50) * (9.2 / 28)) < 1.2
    assert a["modality_summary"]["frac_active"] > 0.2
    assert not any("decoding:" in m for m in messages), messages  # the second lap comes back to the first's places
    _, one_lap = warnings_of(world=str(world), trajectory=laps(1)[0], protocol="online",
                             sample_hours=n_lap * 0.288 / 3600)
    decoding = [m for m in one_lap if m.startswith("decoding:") or ": decoding:" in m]
    assert len(decoding) == 1 and "from every place the first half visited" in decoding[0] \
        and "comes back" in decoding[0], one_lap


# ---- 10: figures of routes over their floor plan ---------------------------------------------------------

def test_route_draws_its_figure_over_the_floor_plan(tmp_path):
    """Finding 10: route --figure writes the route over the world's plan at the body's height; the plan is the
    body's collision outline (World.floor_plan), here the hall's walls and blocks exactly."""
    world = tmp_path / "hall.yaml"
    world.write_text(HALL_YAML)
    waypoints = tmp_path / "points.txt"
    waypoints.write_text("-16 -7\n16 -7\n16 7\n")
    proc = run_cli("route", "--world", world, "--waypoints", waypoints, "--out", tmp_path / "r.csv",
                   "--figure", tmp_path / "r.png", check=True)
    png = (tmp_path / "r.png").read_bytes()
    assert png[:8] == b"\x89PNG\r\n\x1a\n" and len(png) > 20000
    # Every printed number is rounded for people (finding 12).
    assert not re.search(r"\d\.\d{3,}", proc.stdout), proc.stdout
    plan = bvc3d.World.from_yaml(world).floor_plan(height=0.1)
    seg = plan["segments"]
    assert seg.shape[1:] == (2, 2) and np.all(plan["radii"] == 0)
    # The central block's outline (24 x 8 m) is in the plan: its four edges' x and y extents.
    block = seg[(np.abs(seg[:, :, 0]) <= 12 + 1e-9).all(axis=1) & (np.abs(seg[:, :, 1]) <= 4 + 1e-9).all(axis=1)]
    assert np.isclose(block[:, :, 0].min(), -12) and np.isclose(block[:, :, 0].max(), 12)
    assert np.isclose(block[:, :, 1].min(), -4) and np.isclose(block[:, :, 1].max(), 4)
    # A cut above everything holds only the walkable region's edge.
    high = bvc3d.World.from_dict({"objects": [{"box": {"center": [0, 0, 2], "size": [1, 1, 1]}}],
                                  "walkable": {"rect": [-3, -3, 3, 3]}}).floor_plan(height=0.1)["segments"]
    assert len(high) == 4 and np.allclose(np.abs(high).max(), 3)


def test_view_draws_a_trajectory_over_its_world(tmp_path):
    """Finding 10: view WORLD --trajectory FILE: the page gets the path and the model's view at its steps (the
    exported replies are what the server gives)."""
    import base64
    import json
    world = tmp_path / "hall.yaml"
    world.write_text(HALL_YAML)
    path, _ = laps(1)
    track = tmp_path / "lap.csv"
    np.savetxt(track, np.column_stack([path["t"], path["x"], path["y"], path["heading"]]), delimiter=",",
               header="t,x,y,heading", comments="", fmt="%.17g")
    run_cli("view", world, "--trajectory", track, "--export", tmp_path / "page", "--export-steps", 3, check=True)
    index = (tmp_path / "page" / "data" / "index.js").read_text()
    files = json.loads(re.search(r"files: (\{.*?\}), steps", index).group(1))
    steps = json.loads(re.search(r"steps: (\{.*?\}), index", index).group(1))
    assert json.loads(re.search(r"index: (\{.*?\}), data", index).group(1))["trajectory"] == "lap.csv"
    assert steps["#trajectory"] == [0, (len(path["t"]) - 1) // 2, len(path["t"]) - 1]

    def reply(key):
        text = (tmp_path / "page" / "data" / files[key]).read_text()
        blob = base64.b64decode(re.search(r',"([A-Za-z0-9+/=]*)"\);', text).group(1))
        n = int.from_bytes(blob[4:8], "little")
        header = json.loads(blob[8:8 + n])
        arrays = {a["name"]: np.frombuffer(blob[8 + n + a["offset"]:8 + n + a["offset"] + a["bytes"]],
                                           dtype={"f64": "<f8", "f32": "<f4", "u8": "u1", "i32": "<i4"}[a["dtype"]])
                  for a in header["arrays"]}
        return header, arrays

    header, arrays = reply("trajectory")
    np.testing.assert_array_equal(arrays["x"], path["x"])
    np.testing.assert_array_equal(arrays["heading"], path["heading"])
    probe, _ = reply(f"probe?source=hall.yaml&step={steps['#trajectory'][1]}")
    i = steps["#trajectory"][1]
    assert probe["step"] == i and probe["x"] == path["x"][i] and probe["y"] == path["y"][i]
    # A path outside the world is refused; and a trajectory needs a world.
    far = tmp_path / "far.csv"
    far.write_text("t,x,y,heading\n0,100,0,0\n0.288,100.1,0,0\n")
    assert "outside world" in error_line(run_cli("view", world, "--trajectory", far, "--export", tmp_path / "x"))
    assert not (tmp_path / "x").exists()


# ---- 7: one page of the Python API ----------------------------------------------------------------------

def python_page_code():
    lines = PYTHON_PAGE.read_text().splitlines()
    code, inside = [], False
    for line in lines:
        if line.strip() == "```python":
            inside = True
        elif line.strip() == "```":
            inside = False
        elif inside:
            code.append(line)
    return "\n".join(code)


def test_the_python_page_has_a_runnable_example_of_every_class_and_call():
    """Finding 7: every public class and function of bvc3d and bvc3d.analysis is called in a ```python block
    of docs/python.md (test_doc_code.py runs them), navigation's too, and HdAdjacency's methods."""
    import types
    code = python_page_code()
    public = [n for n in dir(bvc3d) if not n.startswith("_") and callable(getattr(bvc3d, n))
              and not isinstance(getattr(bvc3d, n), types.ModuleType) and n != "InputError"]
    analysis = [n for n in dir(bvc3d.analysis) if not n.startswith("_")
                and isinstance(getattr(bvc3d.analysis, n), (types.FunctionType, types.BuiltinFunctionType))]
    missing = [n for n in public if not re.search(r"\b" + n + r"\b", code)]
    missing += [f"analysis.{n}" for n in analysis if not re.search(r"\b" + n + r"\(", code)]
    missing += [f"HdAdjacency.{n}" for n in ("learn", "replay", "direction_returns")
                if not re.search(r"\." + n + r"\(", code)]
    assert not missing, f"docs/python.md has no example calling: {missing}"


# ---- 8: worlds as paths or objects ----------------------------------------------------------------------

def test_every_call_takes_a_world_as_a_path_or_a_world(tmp_path):
    """Finding 8: a preset name, a world file's path and a World are the same world to every call."""
    cross = bvc3d.World.preset("cross")
    walks = [bvc3d.random_walk(w, 0.01, 3) for w in ("cross", cross, pathlib.Path(SOURCE_DIR / "configs" / "worlds"
                                                                                    / "cross-0.yaml"))]
    for w in walks[1:]:
        np.testing.assert_array_equal(w["x"], walks[0]["x"])
    np.testing.assert_array_equal(bvc3d.flying_walk("flight-room", 0.005, 1)["z"],
                                  bvc3d.flying_walk(bvc3d.World.preset("flight-room"), 0.005, 1)["z"])
    np.testing.assert_array_equal(bvc3d.route("cross", [[-4, -4], [4, -4]])["x"],
                                  bvc3d.route(cross, [[-4, -4], [4, -4]])["x"])
    np.testing.assert_array_equal(bvc3d.shortest_path("cross", [-4.0, 4.0], [-2.0, 4.0])["points"],
                                  bvc3d.shortest_path(cross, [-4.0, 4.0], [-2.0, 4.0])["points"])
    route = bvc3d.route(cross, [[-4, -4], [4, -4], [4, 4]])
    path = tmp_path / "route.csv"
    bvc3d.write_trajectory(path, route)
    by_path = bvc3d.place_recognition(world="cross", route=path, sensor="horizontal", descriptors="scan-context",
                                      exclude_scans=5, exclude_seconds=0)
    by_world = bvc3d.place_recognition(world=cross, route=route, sensor="horizontal", descriptors="scan-context",
                                       exclude_scans=5, exclude_seconds=0)
    np.testing.assert_array_equal(by_path["queries"]["distance"], by_world["queries"]["distance"])
    sim = [bvc3d.replay_simulated(w, path, "horizontal", model="2d")["bvc_rates"] for w in ("cross", cross)]
    np.testing.assert_array_equal(sim[0], sim[1])
    # run_trial takes a World made from a preset or a file (its trial file records that source).
    short = dict(model="2d", explore_hours=0.002, sample_hours=0.002)
    np.testing.assert_array_equal(bvc3d.run_trial(world=bvc3d.World.preset("cross-30"), **short)["rates"],
                                  bvc3d.run_trial(world="cross-30", **short)["rates"])


@pytest.mark.parametrize("call", [
    lambda bad: bvc3d.random_walk(bad, 0.01, 0),
    lambda bad: bvc3d.tour(bad),
    lambda bad: bvc3d.route(bad, [[0, 0], [1, 0]]),
    lambda bad: bvc3d.place_recognition(world=bad, route="r.csv", sensor="horizontal"),
    lambda bad: bvc3d.place_recognition(world="cross", route=bad, sensor="horizontal"),
    lambda bad: bvc3d.run_trial(world=bad),
    lambda bad: bvc3d.replay_simulated(bad, "r.csv", "horizontal"),
    lambda bad: bvc3d.shortest_path(bad, [0, 0], [1, 0]),
    lambda bad: bvc3d.navigate(bad, [[0, 0]]),
])
def test_a_wrong_world_or_route_is_named_not_printed(call):
    """Finding 8: an object that is not a world (or a route) is refused by its type, never printed."""
    for bad in (np.arange(5000.0), {"t": np.arange(5000.0)}, object()):
        with pytest.raises((ValueError, TypeError)) as e:
            call(bad)
        plain_message(str(e.value))


# ---- 12: messages and figures -------------------------------------------------------------------------

def test_head_direction_cells_say_their_count():
    """Finding 12: spherical HD cells are the icosahedron's 20: n says so, and an n for them is refused."""
    hd = bvc3d.HeadDirectionCells(space="spherical")
    assert hd.n == hd.n_cells == 20
    assert bvc3d.HeadDirectionCells().n == bvc3d.HeadDirectionCells().n_cells == 8
    with pytest.raises(ValueError, match="n"):
        bvc3d.HeadDirectionCells(space="spherical", n=12)


def test_growing_place_cells_document_only_what_they_take():
    doc = bvc3d.GrowingPlaceCells.__doc__
    assert "n_place=" not in doc and "budget=" in doc and "gamma_pb=" in doc
    with pytest.raises(ValueError, match="budget"):
        bvc3d.GrowingPlaceCells(48, n_place=250)


@pytest.mark.parametrize("make", [lambda: bvc3d.PlaceCellNetwork(960), lambda: bvc3d.GrowingPlaceCells(960)])
def test_a_wrong_learn_flag_is_named_not_printed(make):
    net = make()
    with pytest.raises((ValueError, TypeError), match="learn") as e:
        net.step(np.ones(960), learn="yes")
    plain_message(str(e.value))
    net.step(np.ones(960), learn=np.bool_(False))  # numpy's booleans are booleans


def test_each_world_loader_names_the_other(tmp_path):
    gazebo = tmp_path / "room.world"
    gazebo.write_text('<?xml version="1.0"?>\n<sdf version="1.6"><world name="w"></world></sdf>\n')
    with pytest.raises(ValueError, match="from_sdf") as e:
        bvc3d.World.from_yaml(gazebo)
    plain_message(str(e.value))
    yaml_world = tmp_path / "room.yaml"
    yaml_world.write_text(HALL_YAML)
    with pytest.raises(ValueError, match="from_yaml"):
        bvc3d.World.from_sdf(yaml_world)


def test_place_recognition_without_revisits_says_so(tmp_path):
    """Finding 12: a drive that never comes back has no revisit: the output says why recall is nan, the
    figure says it in words; and no part of the time printed exceeds the total."""
    route = tmp_path / "line.csv"
    n = 200
    np.savetxt(route, np.column_stack([np.arange(n) * 0.288, np.linspace(-4.5, 4.5, n), np.full(n, -4.0),
                                       np.zeros(n)]), delimiter=",", header="t,x,y,heading", comments="")
    out = tmp_path / "pr"
    proc = run_cli("place-recognition", "--world", "cross", "--route", route, "--sensor", "horizontal",
                   "--descriptors", "scan-context", "--exclude-seconds", 5, "--revisit-m", 0.01, "--out", out,
                   check=True)
    assert "no query has a revisit" in proc.stdout, proc.stdout
    total, part = map(float, re.search(r"([\d.]+) s in all \(([\d.]+) s describing", proc.stdout).groups())
    assert part <= total
    import matplotlib
    matplotlib.use("Agg")
    from bvc3d import place_recognition_figure
    fig = place_recognition_figure.draw(out)
    assert any("no query has a revisit" in t.get_text() for t in fig.axes[0].texts)


def test_view_names_the_input_a_bag_replay_differs_in(exported, tmp_path):
    """Finding 12: a bag replayed with its pose topic, viewed with the same bag's tf: the message says it is the
    poses that differ, and where each came from."""
    trial = tmp_path / "replay.h5"
    run_cli("replay", "--bag", exported / "run.bag", "--cloud-topic", "/points", "--pose-topic", "/odom", "--model",
            "2d", "--out", trial, check=True)
    proc = run_cli("view", trial, "--bag", exported / "run.bag", "--cloud-topic", "/points", "--tf-frames",
                   "map,sensor", "--export", tmp_path / "page")
    line = error_line(proc)
    assert "its poses come from" in line and "tf map sensor" in line and "/odom" in line, line
    assert "its scans" not in line and not (tmp_path / "page").exists()


def test_the_pages_agree_on_the_hospitals_floor():
    sizes = {page: re.findall(r"hospital[^.]*?(\d+ × \d+ m) floor", (SOURCE_DIR / "docs" / page).read_text())
             for page in ("buildings.md", "place-recognition.md")}
    assert all(sizes.values()) and len({s for v in sizes.values() for s in v}) == 1, sizes


def test_navigate_lists_the_files_it_writes(tmp_path):
    """Finding 12: navigate's output, its --out help and docs/navigation.md each name every file the run wrote:
    the trial file, the tables and the figures, no more and no fewer (compared with the folder itself)."""
    out = tmp_path / "nav"
    proc = run_cli("navigate", "--world", "cross", "--goals", "3.5,3.5", "--max-learn-hours", "0.05", "--starts", 1,
                   "--out", out, check=True)
    written = {p.name for p in out.rglob("*") if p.is_file()}
    trial_files = {n for n in written if n.endswith(".h5")}
    assert trial_files == {"cross_2d_seed0.h5"} and len(written - trial_files) == 9, written
    # The output's lines: the tables from the trial files, then the figures.
    listed = set()
    for line in proc.stdout.splitlines():
        tables = re.fullmatch(r"wrote (.*) in (.*) from its trial files \((.*)\)", line)
        figures = re.fullmatch(r"drew (.*) in (.*)", line)
        for m, groups in ((tables, (1, 3)), (figures, (1,))):
            if m:
                assert m.group(2) == str(out), line
                listed |= {n for g in groups for n in m.group(g).split(", ")}
    assert listed == written, proc.stdout
    # The help of --out and the page: every table and figure by its name, the trial file by its pattern.
    help_text = " ".join(run_cli("navigate", "--help", check=True).stdout.split())
    page = (SOURCE_DIR / "docs" / "navigation.md").read_text()
    for name in sorted(written - trial_files):
        assert name in help_text, name
        assert f"`{name}`" in page, name
    assert "WORLD_MODEL_seedN.h5" in help_text and "`<world>_<model>_seed<N>.h5`" in page

# ---- 13: the corpus's classes ----------------------------------------------------------------------

def test_replayed_weights_of_an_old_trial_file_for_another_model_are_refused(exported, tmp_path):
    """Finding 13: a trial file written before /weights named its model still records it at its root: weights
    of 3d-0.1 (the same shape as 3d-0.2's) are refused for 3d-0.2, naming the model."""
    import h5py
    trial = tmp_path / "old.h5"
    run_cli("run", "--model", "3d-0.1", "--hours", "0.003", "--out", trial, "--checkpoint-minutes", 0, check=True)
    with h5py.File(trial, "a") as f:
        for k in ("model", "model_config"):
            del f["weights"].attrs[k]
    proc = run_cli("replay", "--scans", exported / "run", "--poses", exported / "run" / "poses.txt", "--model",
                   "3d-0.2", "--weights", trial, "--out", tmp_path / "r.h5")
    line = error_line(proc)
    assert "3d-0.1" in line and "elevations" in line and not (tmp_path / "r.h5").exists()
    run_cli("replay", "--scans", exported / "run", "--poses", exported / "run" / "poses.txt", "--model", "3d-0.1",
            "--weights", trial, "--out", tmp_path / "ok.h5", check=True)


def test_aliasing_of_arrays_of_the_wrong_shape_raises():
    """Finding 13: maps of no cells (N, 0) have no population vector to compare: refused like the other shapes
    that are not (N, 2 or 3) centers and (N,) or (N, cells) maps."""
    centers, maps = np.zeros((10, 2)), np.zeros((10, 3))
    assert bvc3d.analysis.aliasing(centers, np.ones(10))[1] == 0  # (N,): one cell
    for c, m in [(np.zeros((10, 3, 1)), maps), (np.zeros(10), maps), (centers, np.zeros((9, 3))),
                 (centers, np.zeros((10, 0))), (np.zeros((10, 4)), maps), (centers, np.zeros((10, 3, 2)))]:
        with pytest.raises(ValueError) as e:
            bvc3d.analysis.aliasing(c, m)
        plain_message(str(e.value))


def test_localize_refuses_positions_that_are_not_finite():
    rng = np.random.default_rng(0)
    templates, queries = rng.random((20, 30)), rng.random((5, 30))
    tp, qp = rng.random((20, 3)), rng.random((5, 3))
    bvc3d.localize(templates, tp, queries, qp)
    for a, b in [(np.where(np.arange(60).reshape(20, 3) == 3, np.nan, tp), qp), (tp, np.full((5, 3), np.inf))]:
        with pytest.raises(ValueError, match="finite") as e:
            bvc3d.localize(templates, a, queries, b)
        plain_message(str(e.value))
