"""Place cells fed by BVCs and grid cells (SPEC §16; docs/model-reference.md#place-cells-fed-by-grid-cells) against a
numpy transcription of their equation on hand-made inputs; g = 0 gives the paper's network bit for bit; the grid
mask is seeded; the multiscale presets are built as the SPEC gives them."""
import numpy as np
import pytest

import bvc3d

F = np.float32


def transcription(net, b_steps, c_steps, learn, p):
    """The network's equation, written again in float32 numpy from its initial weights and mask."""
    Wb = net.weights.astype(F).copy()
    Wg = net.grid_mask.astype(F)
    assert set(np.unique(Wg)) <= {0.0, 1.0}
    g = p["grid_influence"]
    s = np.zeros(Wb.shape[0], F)
    v = np.zeros(Wb.shape[0], F)
    out = []
    for b, c in zip(b_steps, c_steps):
        b, c = b.astype(F), c.astype(F)
        drive = F(1 - g) * (Wb @ b) + F(g) * (Wg @ c)
        inhibition = F((1 - g) * p["gamma_pb"]) * b.sum() + F(g * p["gamma_pg"]) * c.sum() + F(p["gamma_pp"]) * v.sum()
        s = s + F(0.5) * (-s + drive - inhibition)
        v = np.tanh(np.maximum(s, 0)).astype(F)
        if learn:
            Wb = Wb + F((1 - g) * p["eta"]) * v[:, None] * (b[None, :] - v[:, None] * Wb / F(p["alpha_pb"]))
        out.append(v)
    return np.array(out), Wb


def hand_made_inputs(n_bvc, n_grid, steps, seed=1):
    rng = np.random.default_rng(seed)
    # A bump of BVC activity that moves along the layer, and grid rates in [0, 1] with most cells silent.
    idx = np.arange(n_bvc)
    b = np.array([0.5 * np.exp(-0.5 * ((idx - 3 * t) / 4.0) ** 2) for t in range(steps)])
    c = np.clip(rng.uniform(-1, 1, (steps, n_grid)), 0, 1)
    return b, c


@pytest.mark.parametrize("learn", [False, True])
def test_grid_fed_network_follows_its_equation(learn):
    p = dict(grid_influence=0.35, gamma_pb=0.35, gamma_pg=0.25, gamma_pp=0.7, eta=0.096, alpha_pb=0.5 ** 0.5)
    net = bvc3d.PlaceCellNetwork(96, seed=4, n_grid=40, n_place=30, grid_p_connect=0.3,
                                 **{k: v for k, v in p.items()})
    b, c = hand_made_inputs(96, 40, 25)
    want, want_w = transcription(net, b, c, learn, p)
    got = np.array([net.step(bi, learn=learn, grid_rates=ci) for bi, ci in zip(b, c)])
    assert want.max() > 0.1  # the inputs wake cells
    np.testing.assert_allclose(got, want, rtol=2e-5, atol=2e-6)
    np.testing.assert_allclose(net.weights, want_w, rtol=2e-5, atol=2e-6)


def test_g_zero_is_the_papers_network_bit_for_bit():
    b, c = hand_made_inputs(120, 64, 300, seed=7)
    b = b + np.random.default_rng(2).uniform(0, 0.05, b.shape)
    paper = bvc3d.PlaceCellNetwork(120, seed=11)
    fed = bvc3d.PlaceCellNetwork(120, seed=11, n_grid=64, grid_influence=0.0, gamma_pg=0.9)
    assert fed.grid_mask.sum() > 0
    for t, (bi, ci) in enumerate(zip(b, c)):
        learn = t % 3 != 0
        want = paper.step(bi, learn=learn)
        got = fed.step(bi, learn=learn, grid_rates=ci)
        assert np.array_equal(got, want), t
    assert np.array_equal(paper.weights, fed.weights)
    assert paper.rates.max() > 0
    # And with g > 0 the grid cells count.
    other = bvc3d.PlaceCellNetwork(120, seed=11, n_grid=64, grid_influence=0.3)
    rates = np.array([other.step(bi, grid_rates=ci) for bi, ci in zip(b, c)])
    assert not np.array_equal(rates[-1], paper.rates)


def test_the_mask_is_seeded():
    def mask(seed, p=0.3):
        return bvc3d.PlaceCellNetwork(50, seed=seed, n_grid=400, n_place=200, grid_influence=0.3,
                                      grid_p_connect=p).grid_mask
    a, b = mask(5), mask(5)
    assert np.array_equal(a, b)
    assert not np.array_equal(a, mask(6))
    n = a.size
    for p in (0.2, 0.3):
        count = mask(9, p).sum()
        assert abs(count - p * n) < 5 * np.sqrt(n * p * (1 - p))
    # Not the BVC weights' draws: the mask has its own stream.
    net = bvc3d.PlaceCellNetwork(400, seed=5, n_grid=400, n_place=200, grid_influence=0.3, p_connect=0.3)
    assert not np.array_equal(net.weights, net.grid_mask)


def test_bad_arguments_are_refused():
    with pytest.raises(ValueError, match="grid_influence"):
        bvc3d.PlaceCellNetwork(10, grid_influence=1.5, n_grid=4)
    with pytest.raises(ValueError, match="grid cells"):
        bvc3d.PlaceCellNetwork(10, grid_influence=0.3)
    net = bvc3d.PlaceCellNetwork(10, n_grid=4, grid_influence=0.3)
    with pytest.raises(ValueError, match="grid"):
        net.step(np.zeros(10))
    with pytest.raises(ValueError, match="4 grid rates"):
        net.step(np.zeros(10), grid_rates=np.zeros(5))
    with pytest.raises(ValueError, match="not finite"):
        net.step(np.zeros(10), grid_rates=np.array([0, np.nan, 0, 0]))


def test_multiscale_presets():
    assert {"ms-2d", "ms-3d"} <= set(bvc3d.model_presets())
    for name, layers in (("ms-2d", 1), ("ms-3d", 3)):
        layer = bvc3d.BoundaryVectorLayer.preset(name)  # the first scale's
        assert layer.n_cells == layers * 8 * 100
        assert layer.sigma_r == 0.5 and layer.max_dist == 25
        np.testing.assert_allclose(layer.sigma_theta, np.radians(1))


def test_a_multiscale_trial_records_and_analyses_each_scale_and_the_fusion(cli, tmp_path):
    h5py = pytest.importorskip("h5py")
    out = tmp_path / "ms.h5"
    cli("run", "--model", "ms-2d", "--hours", "0.05", "--seed", "3", "--out", out, check=True)
    with h5py.File(out) as f:
        n = f["samples/x"].shape[0]
        assert f["samples/rates"].shape == (n, 2000)
        pops = f["populations"]
        assert pops["place-m/rates"].shape == (n, 1000)
        assert pops["place-l/rates"].shape == (n, 500)
        assert pops["hd/rates"].shape == (n, 8)
        assert "rates" not in pops["grid-s"] and "rates" not in pops["bvc-m"]
        assert pops["place-m/weights"].shape == (1000, 400)
        assert pops["place-l/weights"].shape == (500, 600)
        # Each scale and the fusion analysed: a localization error per population.
        errors = {}
        for name in ("place-m", "place-l", "place-fused"):
            metrics = pops[name]["metrics"].attrs
            errors[name] = metrics["decode_median_m"]
            assert np.isfinite(errors[name]) and metrics["n_decoded"] > 0, name
        assert "rates" not in pops["place-fused"]
        # The scales draw their own weights and masks (seed hashed with the name).
        assert not np.array_equal(f["weights"][:1000, :400], pops["place-m/weights"][:])


def test_run_trial_gives_each_scale_and_the_fusion():
    r = bvc3d.run_trial(model="ms-2d", explore_hours=0.03, sample_hours=0.03, seed=2)
    n = r["x"].shape[0]
    assert r["rates"].shape == (n, 2000)
    pops = r["populations"]
    assert pops["place-m"]["rates"].shape == (n, 1000) and pops["place-l"]["rates"].shape == (n, 500)
    assert "rates" not in pops["grid-s"]
    for name in ("place-m", "place-l", "place-fused"):
        assert np.isfinite(pops[name]["metrics"]["decode_median_m"]), name
