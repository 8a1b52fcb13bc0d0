"""The growing place-cell network (SPEC §16, docs/model-reference.md#growing-place-cells) against a numpy
transcription of its rule on hand-made inputs, and against the paper's network (bvc3d.PlaceCellNetwork)."""
import numpy as np
import pytest

import bvc3d


def paper_step(W, s, v, b, learn, dt=0.5, gpb=0.3, gpp=0.5, eta=0.096, alpha=np.sqrt(0.5)):
    """SPEC §6 in float32: one Euler step of the membrane, the rates, then Oja's update (in place)."""
    b = b.astype(np.float32)
    inhibition = np.float32(gpb) * b.sum(dtype=np.float32) + np.float32(gpp) * v.sum(dtype=np.float32)
    s += np.float32(dt) * (-s + W @ b - inhibition)
    v[:] = np.tanh(np.maximum(s, 0))
    if learn:
        W += np.float32(eta) * v[:, None] * (b[None, :] - v[:, None] * W / np.float32(alpha))
    return v


def numpy_growing(inputs, learn, budget, threshold, sample_every, p_connect=0.25):
    """The recruitment rule of SPEC §16 as the header states it, starting from no cell: each recruited row is
    (p_connect·n_bvc)·b/Σb, its membrane 0, on every sample_every-th learning step where max rate < threshold."""
    n_bvc = inputs.shape[1]
    W = np.zeros((0, n_bvc), np.float32)
    s = np.zeros(0, np.float32)
    v = np.zeros(0, np.float32)
    count, recruited, rates, initial_rows = 0, [], [], []
    for b, on in zip(inputs, learn):
        paper_step(W, s, v, b, on)
        out = np.zeros(budget, np.float32)
        out[:len(v)] = v
        rates.append(out)
        if not on:
            continue
        count += 1
        if count % sample_every or len(v) >= budget or (len(v) and v.max() >= threshold) or b.sum() <= 0:
            continue
        row = (p_connect * n_bvc * b / np.cumsum(b)[-1]).astype(np.float32)
        initial_rows.append(row)
        W = np.vstack([W, row])
        s = np.append(s, np.float32(0))
        v = np.append(v, np.float32(0))
        recruited.append(count)
    return np.array(rates), W, recruited, initial_rows


def places(n_places, n_bvc, seed):
    """Hand-made BVC vectors of distinct places: each place lights a contiguous block of BVCs (a boundary at one
    distance), rates in [0, 0.5] as the paper normalises them."""
    rng = np.random.default_rng(seed)
    out = np.zeros((n_places, n_bvc))
    for k in range(n_places):
        start = rng.integers(0, n_bvc - 12)
        out[k, start:start + 12] = 0.5 * np.exp(-0.5 * ((np.arange(12) - 6) / 2.5) ** 2)
        out[k] += 0.02 * rng.random(n_bvc)
    return out


def tour(n_places, dwell, n_bvc=96, seed=1):
    """The agent stays `dwell` steps at each place in turn."""
    return np.repeat(places(n_places, n_bvc, seed), dwell, axis=0)


def run(net, inputs, learn):
    return np.array([net.step(b, bool(on)) for b, on in zip(inputs, learn)])


@pytest.mark.parametrize("places_, dwell, budget, threshold, every", [
    (12, 15, 8, 0.3, 6),  # the budget is reached: the test sees recruitment stop
    (90, 4, 70, 1.0, 4),  # past the rows the network holds at first (64): it regrows with its state
])
def test_matches_numpy_transcription(places_, dwell, budget, threshold, every):
    inputs = tour(places_, dwell)
    learn = np.ones(len(inputs), bool)
    learn[40:50] = False  # a frozen stretch: no step there counts toward sampling
    expect_rates, expect_W, expect_at, rows = numpy_growing(inputs, learn, budget, threshold, every)
    net = bvc3d.GrowingPlaceCells(inputs.shape[1], budget=budget, threshold=threshold, sample_every=every)
    got = run(net, inputs, learn)
    assert len(expect_at) == budget
    np.testing.assert_array_equal(net.recruited_at, expect_at)
    assert all(at % every == 0 for at in expect_at)
    np.testing.assert_allclose(got, expect_rates, rtol=2e-4, atol=2e-5)
    np.testing.assert_allclose(net.weights, expect_W, rtol=2e-4, atol=1e-5)
    assert got.shape == (len(inputs), budget)


def test_recruited_weights_are_the_bvc_vector():
    bump = 0.5 * np.exp(-0.5 * ((np.arange(12) - 6) / 2.5) ** 2)
    inputs = np.zeros((15, 40))
    for k in range(3):  # three places that light separate BVCs, 5 steps each
        inputs[5 * k:5 * k + 5, 12 * k:12 * k + 12] = bump
    inputs += 0.01
    net = bvc3d.GrowingPlaceCells(40, budget=10, threshold=0.5, sample_every=5)
    for k, b in enumerate(inputs):
        before = net.n_cells
        net.step(b, True)
        if net.n_cells > before:  # recruited after this step: its row is exactly the normalised vector
            expect = (0.25 * 40 * b / np.cumsum(b)[-1]).astype(np.float32)
            np.testing.assert_array_equal(net.weights[-1], expect)
            np.testing.assert_allclose(net.weights[-1].sum(), 0.25 * 40, rtol=1e-5)
            assert (k + 1) % 5 == 0
    assert net.n_cells == 3  # one per place: each new cell fires at its place by the next sample


def test_existing_cells_learn_as_the_paper_network():
    """Recruited cells are the paper's network of those cells, bit for bit (also past the first capacity, 64)."""
    n_bvc = 96
    inputs = tour(90, 4, n_bvc=n_bvc, seed=3)
    grow = bvc3d.GrowingPlaceCells(n_bvc, budget=80, threshold=1.0, sample_every=4)
    run(grow, inputs, np.ones(len(inputs), bool))
    n = grow.n_cells
    assert n == 80  # the budget: no cell is recruited from here on
    paper = bvc3d.PlaceCellNetwork(n_bvc, n_place=n)
    paper.weights = grow.weights
    grow.reset()
    for b in np.repeat(places(20, n_bvc, seed=4), 3, axis=0):
        np.testing.assert_array_equal(grow.step(b, True), paper.step(b, True))
        np.testing.assert_array_equal(grow.weights, paper.weights)
    assert np.any(grow.weights != np.repeat(grow.weights[:1], n, axis=0))


def test_never_recruiting_is_the_paper_network():
    inputs = tour(6, 10, n_bvc=96)
    grow = bvc3d.GrowingPlaceCells(96, seed=7, budget=300, n_initial=250, threshold=0.0)
    paper = bvc3d.PlaceCellNetwork(96, seed=7)
    np.testing.assert_array_equal(grow.weights, paper.weights)
    for b in inputs:
        np.testing.assert_array_equal(grow.step(b, True)[:250], paper.step(b, True))
    np.testing.assert_array_equal(grow.weights, paper.weights)
    assert grow.n_cells == 250 and np.all(grow.rates[250:] == 0)


def test_deterministic_for_a_seed_and_within_budget():
    inputs = tour(40, 3, n_bvc=64, seed=5)
    learn = np.ones(len(inputs), bool)
    a = bvc3d.GrowingPlaceCells(64, seed=11, budget=30, n_initial=5, threshold=1.0, sample_every=3)
    b = bvc3d.GrowingPlaceCells(64, seed=11, budget=30, n_initial=5, threshold=1.0, sample_every=3)
    c = bvc3d.GrowingPlaceCells(64, seed=12, budget=30, n_initial=5, threshold=1.0, sample_every=3)
    ra, rb, rc = run(a, inputs, learn), run(b, inputs, learn), run(c, inputs, learn)
    np.testing.assert_array_equal(ra, rb)
    np.testing.assert_array_equal(a.weights, b.weights)
    np.testing.assert_array_equal(a.recruited_at, b.recruited_at)
    assert not np.array_equal(ra, rc)
    assert a.n_cells == 30 and ra.shape[1] == 30
    assert list(a.recruited_at[:5]) == [0] * 5


def test_silent_input_recruits_nothing():
    net = bvc3d.GrowingPlaceCells(16, sample_every=1)
    for _ in range(5):
        assert not net.step(np.zeros(16)).any()
    assert net.n_cells == 0 and net.learning_steps == 5


@pytest.mark.parametrize("kwargs, message", [
    ({"budget": 0}, "budget"),
    ({"budget": 4, "n_initial": 5}, "n_initial must be <= budget"),
    ({"threshold": 1.5}, "threshold"),
    ({"gamma_pp": -0.1}, "gamma_pp"),
    ({"n_place": 3}, "n_place"),
    ({"colour": 3}, "colour"),
])
def test_bad_parameters(kwargs, message):
    with pytest.raises(ValueError, match=message):
        bvc3d.GrowingPlaceCells(8, **kwargs)
