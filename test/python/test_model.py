"""The model stage through the Python API and the CLI (issue 3)."""
import math

import numpy as np
import pytest

import bvc3d
from conftest import run_cli


def reference_raw(returns, elevations, n_dir, n_per_axis, max_dist, sr, st, sp):
    """docs/model-reference.md#boundary-vector-cells written with numpy broadcasting over every return and every
    cell."""
    g = lambda x, s: np.exp(-x ** 2 / (2 * s * s)) / math.sqrt(2 * math.pi * s * s)
    r, th, ph = returns[:, 0], returns[:, 1], returns[:, 2]
    theta = np.arange(n_dir) * 2 * math.pi / n_dir
    d = np.arange(n_per_axis) * max_dist / (n_per_axis - 1)
    dth = np.angle(np.exp(1j * (th[:, None] - theta[None, :])))
    A = g(dth, st)                                  # (J, K)
    D = g(r[:, None] - d[None, :], sr)              # (J, M)
    E = g(ph[:, None] - np.asarray(elevations)[None, :], sp) if elevations else np.ones((len(r), 1))
    return np.einsum("jl,jk,jm->lkm", E, A, D).ravel()


@pytest.mark.parametrize("elevations, n_per_axis", [([0.0, 0.2], 60), ([0.0, 0.1, 0.2], 40), ([], 120)])
def test_layer_matches_numpy_reference(elevations, n_per_axis):
    rng = np.random.default_rng(0)
    returns = np.column_stack([rng.uniform(0, 15, 500), rng.uniform(-math.pi, math.pi, 500),
                               rng.uniform(-0.1, 0.4, 500)])
    layer = bvc3d.BoundaryVectorLayer(elevations=elevations, n_per_axis=n_per_axis)
    raw = reference_raw(returns, elevations, 8, n_per_axis, 12.0, 0.75, 0.1, 0.01)
    assert layer.n_cells == raw.size
    np.testing.assert_allclose(layer.raw(returns), raw, rtol=0, atol=1e-7 * raw.max())
    rates = layer.rates(returns)
    assert rates.max() == 0.5
    np.testing.assert_allclose(rates, raw / (2 * raw.max()), rtol=0, atol=1e-6 * 0.5)


def test_preset_layers_on_real_scans():
    world = bvc3d.World.cross(60)
    for name in ["2d", "3d-0.1", "3d-0.2", "3d-3l"]:
        layer = bvc3d.BoundaryVectorLayer.preset(name)
        sensor = bvc3d.model_sensor(name)
        scan = world.scan(sensor, -2.0, 3.0, 1.0)
        assert layer.n_cells == 960
        v = layer.rates(scan)
        assert v.shape == (960,) and v.dtype == np.float64 and v.max() == 0.5 and v.min() >= 0
    pref = bvc3d.BoundaryVectorLayer.preset("3d-3l").preferred
    assert sorted(set(pref["elevation"])) == [0.0, 0.1, 0.2]
    assert pref["distance"].max() == pytest.approx(12.0)


def test_elevation_selects_layer_and_2d_ignores_it():
    layer = bvc3d.BoundaryVectorLayer(elevations=[0.0, 0.2])
    v = layer.rates(np.array([[4.0, 0.0, 0.2]]))
    assert v[:480].max() < 1e-80 and v[480:].max() == 0.5
    flat = bvc3d.BoundaryVectorLayer(elevations=None, n_per_axis=120)
    np.testing.assert_array_equal(flat.rates(np.array([[4.0, 0.0, 0.2]])), flat.rates(np.array([[4.0, 0.0, 0.0]])))


def test_input_hygiene():
    layer = bvc3d.BoundaryVectorLayer.preset("3d-0.2")
    assert np.all(layer.rates(np.zeros((0, 3))) == 0)
    clean = layer.rates(np.array([[3.0, 0.2, 0.0]]))
    with_gaps = layer.rates(np.array([[3.0, 0.2, 0.0], [np.nan, 0.0, 0.0], [np.inf, 1.0, 0.0]]))
    np.testing.assert_array_equal(clean, with_gaps)
    with pytest.raises(ValueError, match="return 0: negative range"):
        layer.rates(np.array([[-1.0, 0.0, 0.0]]))
    with pytest.raises(ValueError, match="azimuth is not finite"):
        layer.rates(np.array([[1.0, np.nan, 0.0]]))
    with pytest.raises(ValueError, match=r"\(N, 3\)"):
        layer.rates(np.zeros((4, 2)))
    with pytest.raises(ValueError, match="sigma_r"):
        bvc3d.BoundaryVectorLayer(sigma_r=0)
    with pytest.raises(ValueError, match="normalization"):
        bvc3d.BoundaryVectorLayer(normalization="softmax")


def test_place_cell_network_api():
    net = bvc3d.PlaceCellNetwork(960, n_place=250, seed=0)
    w0 = net.weights
    assert w0.shape == (250, 960) and w0.dtype == np.float32
    assert set(np.unique(w0)) <= {0.0, 1.0}
    np.testing.assert_array_equal(w0, bvc3d.PlaceCellNetwork(960, seed=0).weights)
    vb = bvc3d.BoundaryVectorLayer.preset("3d-0.2").rates(bvc3d.World.cross(45).scan("spherical", 1, 1, 0))
    v = net.step(vb, learn=False)
    assert v.shape == (250,)
    np.testing.assert_array_equal(net.weights, w0)
    for _ in range(5):
        net.step(vb, learn=True)
    assert not np.array_equal(net.weights, w0)
    trained = net.weights.copy()
    net2 = bvc3d.PlaceCellNetwork(960, seed=99)
    net2.weights = trained
    net.reset()
    np.testing.assert_array_equal(net.step(vb, learn=False), net2.step(vb, learn=False))
    assert np.all(net.membrane == net2.membrane)
    with pytest.raises(ValueError, match="weights must have shape"):
        net.weights = np.zeros((3, 3))
    with pytest.raises(ValueError, match="expected 960 BVC rates"):
        net.step(np.zeros(10))


def test_cli_bvc_table(tmp_path):
    out = tmp_path / "cells.csv"
    proc = run_cli("bvc", "--model", "3d-0.2", "--world", "cross", "--tilt", 45, "--pose", "1,2,0", "--csv", out,
                   check=True)
    lines = proc.stdout.splitlines()
    assert "960 BVCs" in lines[0]
    assert len(lines) == 2 + 16  # header, column titles, 2 layers x 8 directions
    cells = np.genfromtxt(out, delimiter=",", names=True)
    assert len(cells) == 960
    layer = bvc3d.BoundaryVectorLayer.preset("3d-0.2")
    expected = layer.rates(bvc3d.World.cross(45).scan("spherical", 1, 2, 0))
    np.testing.assert_array_equal(cells["rate"], expected)


def test_cli_custom_models(tmp_path, source_dir):
    for name in ["3d-0.15-wide", "3d-0.2-noisy", "velodyne-64"]:
        proc = run_cli("bvc", "--model", source_dir / f"configs/models/{name}.yaml", "--pose", "2,-3,1", check=True)
        assert f"model {name}" in proc.stdout
    bad = {
        "bvc:\n  sigma_phi: -1\n": ("bvc.sigma_phi", "must be > 0"),
        "bvc:\n  layers: 3\n": ("bvc.layers", "unknown key"),
        "bvc:\n  n_dir: eight\n": ("bvc.n_dir", "expected an integer"),
        "base: 5d\n": ("base", "unknown model '5d'"),
        "place:\n  p_connect: 2\n": ("place.p_connect", "must be in [0"),
        "bvc:\n  reading: nearest_beam\n": ("bvc", "nearest_beam reading is a 2-D model"),
        "sensor: lidar\n": ("sensor", "expected horizontal, spherical"),
        "bvc: [1, 2\n": ("", "malformed YAML"),
    }
    for text, (key, reason) in bad.items():
        f = tmp_path / "model.yaml"
        f.write_text(text)
        proc = run_cli("bvc", "--model", f, "--pose", "0,0,0")
        assert proc.returncode == 2, text
        assert str(f) in proc.stderr and key in proc.stderr and reason in proc.stderr, proc.stderr
    proc = run_cli("bvc", "--model", "4d", "--pose", "0,0,0")
    assert proc.returncode == 2 and "unknown model '4d'" in proc.stderr


def test_python_example_runs(source_dir):
    import subprocess
    import os
    proc = subprocess.run(["/usr/bin/python3", str(source_dir / "example/python_api.py"), "0.1"],
                          capture_output=True, text=True, env=dict(os.environ))
    assert proc.returncode == 0, proc.stderr
    assert "MSAI" in proc.stdout and "decoding" in proc.stdout
