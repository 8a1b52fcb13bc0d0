"""The authors' controller in C++ (policy `authors`, navigation/authors_choice.hpp) against the numpy transcription of
SPEC §17.2 (authors_oracle.py) on hand-made adjacencies with the same random draws: the turning rollouts, the scale
mix, the heading rule, the safety sectors, the reliability and loop bookkeeping, and a whole decision; then whole
runs of the policy (seeded, the same twice; learning while exploiting on and off)."""
import math

import numpy as np
import pytest

import authors_oracle as ao
import bvc3d


def float32_adjacency(rng, n_hd, n, density=0.5, antisymmetric=True, scale=1.0):
    """Random weights exact in float32 (the C++ copy keeps float32), antisymmetric as learned, or not."""
    w = rng.normal(0, scale, (n_hd, n, n)) * (rng.random((n_hd, n, n)) < density)
    if antisymmetric:
        w = w - np.transpose(w, (0, 2, 1))
    return w.astype(np.float32).astype(np.float64)


def chain(n_hd=8):
    w = np.zeros((n_hd, 3, 3))
    w[0, 1, 0] = 2.0
    w[1, 2, 1] = 1.0
    return w


def test_rollouts_on_the_hand_made_chain_match_the_oracle_draw_for_draw():
    w, a0, wr = chain(), np.array([1.0, 0.0, 0.0]), np.array([0.0, 1.0, 0.5])
    rng = np.random.default_rng(3)
    for _ in range(5):
        u = rng.random((2, 8, 10))
        mine = bvc3d.authors.authors_rollouts(w, a0, wr, u.ravel())
        oracle = ao.sample_rollouts(w, a0, wr, u)
        np.testing.assert_allclose(mine["R"], oracle["R"], rtol=0, atol=1e-14)
        np.testing.assert_allclose(mine["V"], oracle["V"], rtol=0, atol=1e-14)
        np.testing.assert_allclose(mine["Var"], oracle["Var"], rtol=0, atol=1e-14)


@pytest.mark.parametrize("antisymmetric", [True, False])
def test_rollouts_on_random_adjacencies_match_the_oracle_and_share_paths(antisymmetric):
    rng = np.random.default_rng(11 + antisymmetric)
    n = 12
    for trial in range(6):
        w = float32_adjacency(rng, 8, n, antisymmetric=antisymmetric, scale=0.3 + trial)
        a0 = rng.random(n) * (rng.random(n) < 0.6)
        wr = rng.normal(0, 1, n)
        u = rng.random((2, 8, 10))
        mine = bvc3d.authors.authors_rollouts(w, a0, wr, u.ravel())
        oracle = ao.sample_rollouts(w, a0, wr, u)
        np.testing.assert_allclose(mine["R"], oracle["R"], rtol=1e-12, atol=1e-13)
        np.testing.assert_allclose(mine["V"], oracle["V"], rtol=0, atol=1e-13)
        np.testing.assert_allclose(mine["Var"], oracle["Var"], rtol=1e-10, atol=1e-13)
        # Each distinct path of directions is rolled out once: 8 first steps, then the distinct (d0, d1), (d0, d1, d2).
        paths = {tuple(oracle["dirs"][d0, j, :k + 1]) for d0 in range(8) for j in range(10) for k in range(3)}
        assert mine["products"] == len(paths)
    # Other sizes of K and T, and a temperature.
    w = float32_adjacency(rng, 8, n)
    a0, wr = rng.random(n), rng.normal(0, 1, n)
    u = rng.random((4, 8, 3))
    mine = bvc3d.authors.authors_rollouts(w, a0, wr, u.ravel(), samples=3, steps=5, discount=0.5, temperature=2.0)
    oracle = ao.sample_rollouts(w, a0, wr, u, samples=3, steps=5, discount=0.5, temperature=2.0)
    np.testing.assert_allclose(mine["R"], oracle["R"], rtol=1e-12, atol=1e-13)
    with pytest.raises(ValueError, match="uniforms"):
        bvc3d.authors.authors_rollouts(w, a0, wr, u.ravel()[:-1], samples=3, steps=5)


def test_the_scale_mix_matches_the_oracle():
    rng = np.random.default_rng(5)
    for trial in range(20):
        S = 1 + trial % 3
        R = rng.random((S, 8)) * 10.0 ** rng.integers(-4, 1)
        Var = rng.random((S, 8)) * 0.1
        rho = rng.uniform(0.1, 1.0, S)
        prev = None if trial % 2 else rng.random(S) * 3
        mine = bvc3d.authors.authors_mix(R, Var, rho, prev)
        oracle = ao.mix_scales(R, Var, rho, prev)
        for key in ("P_ds", "M", "H", "H_smoothed", "iota", "q", "P_s", "P"):
            np.testing.assert_allclose(mine[key], oracle[key], rtol=1e-12, atol=1e-300, err_msg=key)
    silent = bvc3d.authors.authors_mix(np.zeros((3, 8)), np.zeros((3, 8)), [1.0, 1.0, 1.0])
    np.testing.assert_allclose(silent["P_s"], [1 / 3] * 3)


def test_the_heading_rule_matches_the_oracle_in_every_case():
    rng = np.random.default_rng(9)
    rules = set()
    for trial in range(300):
        S = 1 + trial % 3
        P = rng.random((S, 8)) ** 8
        P /= P.sum()
        R = rng.random((S, 8))
        V = rng.normal(0, 1, (S, 8, 2)) * (rng.random((S, 8, 1)) < 0.9)
        if trial % 5 == 0:  # the best two pairs opposed
            order = np.argsort(-R.ravel())
            V.reshape(-1, 2)[order[1]] = -V.reshape(-1, 2)[order[0]]
        if trial % 7 == 0:  # a mean that cancels: the fallback
            V[:] = 0
            V[0, 0] = [1.0, 0.0]
            V[0, 4] = [-1.0, 0.0]
        safe = rng.random(8) < 0.7
        mine = bvc3d.authors.authors_heading(P, R, V, safe.astype(float))
        oracle = ao.heading_rule(P, R, V, safe)
        if oracle is None:
            assert mine is None
            continue
        rules.add(oracle["rule"])
        assert mine["rule"] == oracle["rule"]
        assert mine["heading"] == pytest.approx(oracle["heading"], abs=1e-12)
        np.testing.assert_allclose(mine["P_prime"], oracle["P_prime"], rtol=1e-12, atol=1e-300)
        np.testing.assert_allclose(mine["scale_weights"], oracle["scale_weights"], rtol=1e-12)
    assert rules == {"mix", "opposed", "fallback"}


@pytest.mark.parametrize("sector", ["authors", "centred"])
def test_sector_minima_match_the_oracle(sector):
    rng = np.random.default_rng(2)
    azimuths = np.arange(720) * 2 * math.pi / 720
    ranges = rng.uniform(0.2, 10, 720)
    ranges[rng.random(720) < 0.1] = np.inf
    np.testing.assert_array_equal(bvc3d.authors.sector_minima(ranges, azimuths, 8, sector),
                                  ao.sector_minima(ranges, azimuths, 8, sector))
    # One return at 10° guards direction 0 in both readings; at −10°, direction 7 (authors) or 0 (centred).
    one = bvc3d.authors.sector_minima([0.5], [math.radians(-10)], 8, sector)
    assert np.argmin(one) == (7 if sector == "authors" else 0)


def test_the_reliability_bookkeeping_matches_the_oracle_step_for_step():
    rng = np.random.default_rng(4)
    for trial in range(10):
        S = 1 + trial % 3
        mine, oracle = bvc3d.authors.AuthorsReliability(S), ao.Reliability(S)
        heading = 0.0
        phases = []
        for decision in range(120):
            # Big turns now and then (a loop), contacts now and then (penalties, forced exploration).
            heading += rng.choice([0.0, 0.4, 3.0, 95.0, -170.0])
            phase = mine.begin(heading)
            assert phase == oracle.begin(heading)
            phases.append(phase)
            if phase == "decide":
                steps = list(heading + np.cumsum(rng.choice([0.0, 0.0, 1.0, -2.0], 10)))
                mine.movement_headings(steps)
                oracle.movement_headings(steps)
                heading = steps[-1]
                w = rng.dirichlet(np.ones(S))
                contact = bool(rng.random() < (0.8 if trial % 2 else 0.2))
                mine.end(w, contact)
                oracle.end(w, contact)
            np.testing.assert_allclose(mine.rho, oracle.rho, rtol=1e-14)
            assert list(mine.cooldown) == list(oracle.cooldown)
            np.testing.assert_allclose(mine.contributions, oracle.contributions, rtol=1e-12, atol=1e-15)
            assert mine.accumulated == pytest.approx(oracle.accumulated, abs=1e-9)
            assert (mine.loops, mine.since_loop, mine.force_explore) == (oracle.loops, oracle.since_loop,
                                                                         oracle.force_explore)
        if trial % 2:
            assert "explore" in phases  # contacts drove every ρ under 0.15: forced exploration


def test_a_whole_decision_matches_the_oracle():
    rng = np.random.default_rng(8)
    sizes = [10, 7, 5]
    for trial in range(8):
        scales = []
        for n in sizes:
            w = float32_adjacency(rng, 8, n, scale=2.0)
            scales.append((w, rng.random(n) * (rng.random(n) < 0.7), rng.normal(0.5, 1, n)))
        flat = rng.random(len(scales) * 2 * 8 * 10)
        sector_min = rng.uniform(0.3, 4, 8)
        rho = rng.uniform(0.1, 1, 3)
        prev = None if trial == 0 else rng.random(3) * 2
        mine = bvc3d.authors.authors_decide(scales, flat, sector_min, rho, prev)
        oracle = ao.decide(scales, rho, ao.rollout_uniforms(flat, len(scales)), sector_min, prev)
        np.testing.assert_allclose(mine["H_smoothed"], oracle["H_smoothed"], rtol=1e-12, atol=1e-12)
        if oracle["choice"] is None:
            assert mine["choice"] is None
            continue
        assert mine["choice"]["rule"] == oracle["choice"]["rule"]
        assert mine["choice"]["heading"] == pytest.approx(oracle["choice"]["heading"], abs=1e-10)
        np.testing.assert_allclose(mine["choice"]["scale_weights"], oracle["choice"]["scale_weights"], rtol=1e-10)


ROOM = """name: room
objects:
  - box: {center: [0, 0, -0.05], size: [8, 8, 0.1]}
  - box: {center: [-4.1, 0, 1.25], size: [0.2, 8.4, 2.5]}
  - box: {center: [4.1, 0, 1.25], size: [0.2, 8.4, 2.5]}
  - box: {center: [0, -4.1, 1.25], size: [8.4, 0.2, 2.5]}
  - box: {center: [0, 4.1, 1.25], size: [8.4, 0.2, 2.5]}
  - box: {center: [1, -1, 1.25], size: [0.6, 0.6, 2.5]}
walkable: {rect: [-4, -4, 4, 4]}
start: {rect: [-3.5, -3.5, 3.5, 3.5]}
"""


def test_the_policy_reaches_a_goal_in_sight_the_same_for_a_seed_learning_on_or_off(tmp_path):
    world = tmp_path / "room.yaml"
    world.write_text(ROOM)
    kw = dict(max_learn_hours=0.5, starts=4, min_start_distance=4.0, goal_visits=3, coverage=0.9, reward_map_cell=0)
    a = bvc3d.navigate(world, [[2.5, 2.5]], seed=3, policy="authors", navigation=kw)
    b = bvc3d.navigate(str(world), [[2.5, 2.5]], seed=3, policy="authors", navigation=kw)
    for key in ("start_x", "path_m", "time_s", "success"):
        np.testing.assert_array_equal(a[key], b[key])
    assert a["success"].sum() >= 3
    for i, path in enumerate(a["paths"]):
        steps = np.hypot(*np.diff(path, axis=0).T)
        # Steps of 0.143 m; one that slides along a wall moves less from point to point than along its way.
        assert np.all(steps <= 0.143 + 1e-9) and steps.sum() - 1e-9 <= a["path_m"][i] <= 0.143 * len(steps) + 1e-9
        if a["success"][i]:
            assert np.hypot(path[-1, 0] - 2.5, path[-1, 1] - 2.5) <= 1.0 + 1e-9
    frozen = bvc3d.navigate(world, [[2.5, 2.5]], seed=3, policy="authors", authors=dict(learn=False), navigation=kw)
    assert frozen["success"].sum() >= 3
    assert not np.array_equal(frozen["path_m"], a["path_m"])  # learning while exploiting changes the paths
    with pytest.raises(ValueError, match="authors=: key 'lean': unknown key"):
        bvc3d.navigate(world, [[2.5, 2.5]], policy="authors", authors=dict(lean=False), navigation=kw)
    with pytest.raises(ValueError, match="another policy"):
        bvc3d.navigate(world, [[2.5, 2.5]], authors=dict(learn=False), navigation=kw)
    with pytest.raises(ValueError, match="moves a robot on the floor"):
        bvc3d.navigate("flight-room", [[1.5, 1.0, 1.6]], model="fly-5l", policy="authors", navigation=kw)
