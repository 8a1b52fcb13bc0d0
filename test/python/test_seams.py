"""The architecture's seams from Python and the command line: user trajectories (arrays and files),
3-D analysis against scikit-learn, one metric table, parameters with C++ defaults, and the layering
of the source tree (a lower stage never includes a higher one)."""
import math
import pathlib
import re

import h5py
import numpy as np
import pytest
from sklearn.cluster import DBSCAN

import bvc3d
from conftest import SOURCE_DIR, run_cli


def square_loop(n=4000, offset=0.0):
    """A loop around the cross arena's central walls, one row per model step (0.144 m, 0.288 s)."""
    i = np.arange(n)
    s = np.mod(i * 0.144, 24.0)
    side = (s // 6.0).astype(int)
    u = s - 6.0 * side - 3.0
    x = np.choose(side, [u, np.full(n, 4.0), -u, np.full(n, -4.0)])
    y = np.choose(side, [np.full(n, -4.0), u, np.full(n, 4.0), -u])
    h = np.choose(side, [0.0, math.pi / 2, math.pi, -math.pi / 2])
    return {"t": offset + 0.288 * i, "x": x, "y": y, "heading": h}


def test_run_trial_follows_a_trajectory_given_as_arrays_or_a_file(tmp_path):
    path = square_loop(offset=1.7e9)  # Unix times: shifted to start at 0
    r = bvc3d.run_trial(model="2d", world="cross", tilt_deg=30, trajectory=path, protocol="online",
                        sample_hours=0.2)
    n = len(r["t"])
    assert n == int(np.searchsorted(path["t"] - path["t"][0], 0.2 * 3600)) + 1
    np.testing.assert_array_equal(r["x"], path["x"][:n])
    np.testing.assert_array_equal(r["y"], path["y"][:n])
    np.testing.assert_array_equal(r["t"], path["t"][:n] - path["t"][0])
    # The same path from a file, through the CLI and Python: identical rates.
    f = tmp_path / "loop.csv"
    np.savetxt(f, np.column_stack([path["t"], path["x"], path["y"], path["heading"]]), delimiter=",",
               header="t,x,y,heading", comments="")
    out = tmp_path / "loop.h5"
    run_cli("run", "--model", "2d", "--tilt", 30, "--trajectory", f, "--protocol", "online", "--sample-hours", 0.2,
            "--out", out, check=True)
    with h5py.File(out) as h:
        np.testing.assert_array_equal(h["samples/rates"][:], r["rates"])
        assert "trajectory:" in h.attrs["config"] and "loop.csv" in h.attrs["config"]
    from_file = bvc3d.read_trajectory(f)
    np.testing.assert_array_equal(from_file["x"], path["x"])
    assert from_file["t"][0] == 0
    with pytest.raises(ValueError, match="lacks 'heading'"):
        bvc3d.run_trial(trajectory={"t": [0, 1], "x": [0, 0], "y": [0, 0]})
    bad = tmp_path / "bad.txt"
    bad.write_text("0 1 2 0\n1 1 2\n")
    proc = run_cli("run", "--trajectory", bad, "--out", tmp_path / "x.h5")
    assert proc.returncode == 2 and str(bad) in proc.stderr and "line 2" in proc.stderr


@pytest.mark.parametrize("seed", range(6))
def test_3d_modality_is_scikit_learns_dbscan(seed):
    rng = np.random.default_rng(seed)
    centers = np.round(rng.uniform(0, 6, (300, 3)) * 2) / 2  # a 0.5 m lattice: points at exactly eps
    maps = (rng.uniform(size=(300, 8)) < rng.uniform(0.05, 0.6, 8)).astype(float)
    mi = bvc3d.analysis.modality(centers, maps, eps=1.0, min_samples=10)
    for c in range(8):
        pts = centers[maps[:, c] > 0]
        expect = 0 if len(pts) < 10 else len(set(DBSCAN(eps=1.0, min_samples=10).fit(pts).labels_) - {-1})
        assert mi[c] == expect, c


def test_3d_aliasing_is_the_double_loop():
    rng = np.random.default_rng(1)
    centers = rng.uniform(0, 5, (120, 3))
    maps = np.where(rng.uniform(size=(120, 20)) < 0.3, rng.uniform(size=(120, 20)), 0.0)
    sai, msai = bvc3d.analysis.aliasing(centers, maps, d_th=2.0)
    norm = np.linalg.norm(maps, axis=1)
    unit = np.divide(maps, norm[:, None], out=np.zeros_like(maps), where=norm[:, None] > 0)
    far = np.linalg.norm(centers[:, None] - centers[None], axis=2) > 2.0
    expect = (unit @ unit.T * far).sum(axis=1) / len(centers)
    np.testing.assert_allclose(sai, expect, atol=1e-13)
    assert msai == pytest.approx(expect.mean(), abs=1e-13)


def test_one_metric_table_names_what_files_summaries_and_figures_show(tmp_path):
    names = [m["name"] for m in bvc3d.metric_table]
    assert names[:4] == ["frac_active", "mean_mi_active", "frac_multimodal", "msai"]
    r = bvc3d.run_trial(model="2d", explore_hours=0.02, sample_hours=0.02)
    assert list(r["metrics"]) == [m["name"] for m in bvc3d.metric_table if m["dims"] in (0, 2)]
    # A flying agent's trial reports every metric, the 3-D ones (dims 3) too.
    r = bvc3d.run_trial(model="fly-up", world="flight-room", agent="flight", explore_hours=0.02, sample_hours=0.02)
    assert list(r["metrics"]) == [m["name"] for m in bvc3d.metric_table if m["dims"] in (0, 3)]
    from bvc3d import report
    assert set(report.METRICS) == {m["name"] for m in bvc3d.metric_table if m["title"]}


def test_summaries_read_files_that_predate_a_metric(tmp_path):
    out = tmp_path / "old"
    run_cli("paper", "--hours", 0.02, "--models", "2d", "--tilts", 0, "--out", out, "--no-report", check=True)
    f = next(out.glob("*.h5"))
    with h5py.File(f, "r+") as h:
        del h["metrics"].attrs["n_undecoded"]  # as if written before the metric existed
    proc = run_cli("summarize", out, "--no-report", check=True)
    assert "1 trials summarized" in proc.stdout
    row = (out / "trials.csv").read_text().splitlines()
    header, values = row[0].split(","), row[1].split(",")
    assert values[header.index("n_undecoded")] == "nan"
    # ... and a rerun does not take that file as complete: it lacks a metric.
    proc = run_cli("paper", "--hours", 0.02, "--models", "2d", "--tilts", 0, "--out", out, "--no-report", check=True)
    assert "(1 run, 0 already complete)" in proc.stdout


def test_python_defaults_are_the_cpp_structs():
    layer = bvc3d.BoundaryVectorLayer()
    preset = bvc3d.BoundaryVectorLayer.preset("3d-0.2")
    for key in ["elevations", "n_dir", "n_per_axis", "max_dist", "sigma_r", "sigma_theta", "sigma_phi"]:
        assert getattr(layer, key) == getattr(preset, key), key
    net = bvc3d.PlaceCellNetwork(10)
    assert net.alpha_pb == math.sqrt(0.5) and net.n_place == 250
    assert "alpha_pb=0.7071067811865476" in bvc3d.PlaceCellNetwork.__doc__
    with pytest.raises(ValueError, match="unknown argument 'sigma'"):
        bvc3d.BoundaryVectorLayer(sigma=1)
    with pytest.raises(ValueError, match="n_dir must be in"):
        bvc3d.BoundaryVectorLayer(n_dir=0)
    with pytest.raises(ValueError, match="'n_dir' must be an integer"):
        bvc3d.BoundaryVectorLayer(n_dir=2.5)


def printed_analysis(*config_args):
    """The analysis keys and values `bvc3d config` prints: the C++ table's defaults, by another path."""
    text = run_cli("config", *config_args, check=True).stdout
    section = text[text.index("\nanalysis:\n"):].splitlines()[2:]
    values = {}
    for line in section:
        m = re.match(r"  (\w+): (\S+)", line)
        if not m:
            break
        values[m.group(1)] = m.group(2)
    return values


def test_analysis_defaults_are_the_cpp_table(tmp_path):
    """bvc3d.analysis repeats no number: every keyword default of its functions is the value `bvc3d
    config` prints for a ground trial's analysis (2-D functions) or a flying one's (3-D functions)."""
    import inspect

    from bvc3d import analysis as A
    flying = tmp_path / "fly.yaml"
    flying.write_text("world: flight-room\nmodel: fly-up\nflight: {}\n")
    for dims, printed, functions in (
            (2, printed_analysis(), [A.hexbin, A.rate_maps, A.dbscan_cluster_count, A.modality, A.aliasing,
                                     A.decoding_error, A.cell_stats, A.analyze]),
            (3, printed_analysis("--trial", flying), [A.voxel_rate_maps, A.dbscan_labels, A.isotropy, A.analyze3d])):
        assert printed["min_samples"] == ("20" if dims == 2 else "10")
        checked = 0
        for f in functions:
            for name, p in inspect.signature(f).parameters.items():
                key = {"templates": "decoding_templates"}.get(name, name)
                # extent (None: the data's own bounds) and mi_quantile (None: -1) are said in Python's words.
                if key in printed and key not in ("extent", "mi_quantile"):
                    assert str(p.default) == printed[key] or p.default == float(printed[key]), (f.__name__, name)
                    checked += 1
        assert checked >= (20 if dims == 2 else 10)
    # mi_quantile None is the table's -1 (the same quantile as the maps): both give the same modality.
    rng = np.random.default_rng(0)
    x, y = rng.uniform(-4, 4, 400), rng.uniform(-4, 4, 400)
    rates = rng.random((400, 6))
    assert list(A.analyze(x, y, rates)["modality"]) == list(A.analyze(x, y, rates, mi_quantile=0.1)["modality"])
    voxel = inspect.signature(A.voxel_rate_maps).parameters["voxel"].default
    assert voxel == bvc3d._core.analysis.defaults(3)["voxel"] == 0.5  # docs/flying.md#analysis


# The stages from the bottom up; a stage may include only stages ranked below it (and itself).
STAGE_RANK = {"core": 0, "world": 1, "recording": 1, "agent": 2, "sensor": 2, "bvc": 3, "place": 4, "population": 5,
              "navigation": 6, "recorder": 7, "analysis": 8, "report": 9, "config": 10, "experiment": 11}


def test_lower_stages_never_include_higher_ones():
    src = SOURCE_DIR / "src" / "bvc3d"
    include = re.compile(r'#include "bvc3d/(\w+)/')
    stages = {p.name for p in src.iterdir() if p.is_dir()}
    assert stages <= set(STAGE_RANK), f"a stage without a rank: {stages - set(STAGE_RANK)}"
    offences = []
    for f in src.rglob("*.[ch]pp"):
        stage = f.relative_to(src).parts[0]
        for line_no, line in enumerate(f.read_text().splitlines(), 1):
            m = include.match(line)
            if m and m.group(1) != stage and STAGE_RANK[m.group(1)] >= STAGE_RANK[stage]:
                offences.append(f"{f.relative_to(SOURCE_DIR)}:{line_no} includes {m.group(1)}")
    assert not offences, "\n".join(offences)
