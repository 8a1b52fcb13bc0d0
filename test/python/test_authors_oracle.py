"""The numpy transcription of the authors' controller (authors_oracle.py, SPEC §17.2) against values worked out by
hand: a hand-made adjacency whose rollouts can be followed step by step, the scale mix on known returns, the heading
rule's special cases, the reliability and loop bookkeeping, the safety sectors. numpy only (no bvc3d)."""
import math

import numpy as np
import pytest

import authors_oracle as ao

T2 = math.tanh(2.0)


def chain(n_hd=8):
    """Three cells: along direction 0 cell 0 leads to cell 1 (weight 2); along direction 1 cell 1 leads to cell 2
    (weight 1); every other weight 0."""
    w = np.zeros((n_hd, 3, 3))
    w[0, 1, 0] = 2.0
    w[1, 2, 1] = 1.0
    return w


def unit(deg):
    return np.array([math.cos(math.radians(deg)), math.sin(math.radians(deg))])


def test_the_uniforms_split_scale_step_direction_sample():
    flat = np.arange(2 * 2 * 8 * 10)
    parts = ao.rollout_uniforms(flat, n_scales=2)
    assert len(parts) == 2 and parts[0].shape == (2, 8, 10)
    for s, k, d0, j in [(0, 1, 0, 0), (1, 1, 3, 7), (1, 2, 7, 9), (0, 2, 5, 2)]:
        assert parts[s][k - 1, d0, j] == ((s * 2 + (k - 1)) * 8 + d0) * 10 + j
    with pytest.raises(ValueError):
        ao.rollout_uniforms(flat[:-1], n_scales=2)


def test_pick_takes_the_first_option_whose_cumulative_probability_exceeds_u():
    p = [0.2, 0.3, 0.5]
    assert [ao.pick(p, u) for u in (0.0, 0.19, 0.2, 0.49, 0.5, 0.999)] == [0, 0, 1, 1, 2, 2]
    assert ao.pick([0.1, 0.1, 0.7999999], 0.9999999999) == 2  # rounding leaves u above the sum: the last option


def test_rollouts_follow_the_hand_made_chain_with_the_given_turns():
    w = chain()
    a0 = np.array([1.0, 0.0, 0.0])
    w_reward = np.array([0.0, 1.0, 0.5])
    # Along direction 0, step 0 reaches cell 1 (rate tanh 2, reward 1). At step 1 the turn's logits are
    # (Σ W_7·a, Σ W_0·a, Σ W_1·a) = (0, 0, tanh 2): a left or straight turn ends the rollout's rates (reward 0),
    # a right turn (+1, direction 1) reaches cell 2, rate tanh(tanh 2), reward 0.5: G = 1 + 0.7·0.5.
    # Step 2 sees no weights at all (uniform turns), reward 0.
    e = math.exp(T2)
    cum = [1 / (2 + e), 2 / (2 + e)]
    u1 = [0.1, 0.2, 0.3, 0.4, 0.42, 0.44, 0.6, 0.8, 0.95, 0.99]
    turn1 = [-1 if u < cum[0] else 0 if u < cum[1] else 1 for u in u1]
    assert turn1 == [-1, -1, 0, 0, 0, 1, 1, 1, 1, 1]
    uniforms = np.full((2, 8, 10), 0.5)  # straight on at step 2 (cumulative 1/3, 2/3), and for d0 ≠ 0
    uniforms[0, 0, :] = u1
    out = ao.sample_rollouts(w, a0, w_reward, uniforms)
    G = [1 + 0.7 * 0.5 if t == 1 else 1.0 for t in turn1]
    mean = sum(G) / 10
    assert out["G"][0] == pytest.approx(G, abs=1e-12)
    assert out["R"][0] == pytest.approx(mean, abs=1e-12)
    assert out["Var"][0] == pytest.approx(sum((g - mean)**2 for g in G) / 9, abs=1e-12)
    assert out["dirs"][0, :, 1].tolist() == [(0 + t) % 8 for t in turn1]
    assert out["dirs"][0, :, 2].tolist() == out["dirs"][0, :, 1].tolist()
    # u = Σ over the three steps of (cos, sin) of the direction: (1, 0) + 2·unit(45°·d1).
    V = sum(unit(0) + 2 * unit(45 * t) for t in turn1) / 10
    assert out["V"][0] == pytest.approx(V, abs=1e-12)
    # Every other start direction leaves cell 0 with nothing to follow: rates 0 at once, return 0.
    assert np.all(out["R"][1:] == 0) and np.all(out["Var"][1:] == 0)
    # With every step-1 uniform at 0.5 the sample turns right (0.5 ≥ 2/(2 + e^tanh 2) ≈ 0.433).
    assert ao.sample_rollouts(w, a0, w_reward, np.full((2, 8, 10), 0.5))["R"][0] == pytest.approx(1.35)


def test_turn_probabilities_are_a_softmax_of_the_summed_products():
    w = chain()
    a = np.array([0.0, 0.5, 0.0])
    e = math.exp(0.5)
    assert ao.turn_probabilities(w, a, 0) == pytest.approx([1 / (2 + e), 1 / (2 + e), e / (2 + e)])
    # From direction 2 the options are 1, 2, 3: only W_1 has weights from cell 1.
    assert ao.turn_probabilities(w, a, 2) == pytest.approx([e / (2 + e), 1 / (2 + e), 1 / (2 + e)])
    assert ao.turn_probabilities(w, a, 0, temperature=2.0)[2] == pytest.approx(math.exp(0.25) / (2 + math.exp(0.25)))


def test_readout_is_normalised_by_the_l1_norm_and_clamped():
    w = np.array([1.0, -2.0, 3.0])
    assert ao.readout(w, np.array([0.5, 0.0, 0.5])) == pytest.approx(2.0)
    assert ao.readout(w, np.array([0.0, 1.0, 0.0])) == 0.0  # negative: clamped to 0
    assert ao.readout(w, np.zeros(3)) == 0.0
    assert ao.readout(w, np.array([0.0, 0.0, 1e-6])) == pytest.approx(3e-6 / 1e-4)  # |a|₁ floored at 10⁻⁴


def test_the_scale_mix_matches_the_formulas_on_known_returns():
    R = np.array([[0.1] * 8, [0.002] + [0.0] * 7])
    Var = np.array([[0.2] * 8, [0.5] + [0.0] * 7])
    rho = np.array([1.0, 0.5])
    e = math.e  # 500 · 0.002 = 1
    p1 = [e / (e + 7)] + [1 / (e + 7)] * 7
    H0 = math.log(8) + math.log(1.2)
    H1 = -sum(p * math.log(p) for p in p1) + math.log(1 + 0.5 * p1[0])
    M = [0.1, 0.002 * p1[0]]

    def expected(Hs):
        inv = [1 / h for h in Hs]
        iota = [x / sum(inv) for x in inv]
        q_raw = [M[s] * iota[s]**2 * rho[s]**2 for s in range(2)]
        q = [x / sum(q_raw) for x in q_raw]
        w = [math.exp(2 * x) for x in q]
        return iota, q, [x / sum(w) for x in w]

    mix = ao.mix_scales(R, Var, rho)
    assert mix["P_ds"][0] == pytest.approx([1 / 8] * 8)
    assert mix["P_ds"][1] == pytest.approx(p1)
    assert mix["M"] == pytest.approx(M)
    assert mix["H"] == pytest.approx([H0, H1])
    assert mix["H_smoothed"] == pytest.approx([H0, H1])  # a start's first decision: H̃ = H
    iota, q, P_s = expected([H0, H1])
    assert mix["iota"] == pytest.approx(iota) and mix["q"] == pytest.approx(q) and mix["P_s"] == pytest.approx(P_s)
    assert mix["P"] == pytest.approx(np.outer(P_s, [1.0] * 8) * mix["P_ds"])
    assert mix["P"].sum() == pytest.approx(1.0)

    later = ao.mix_scales(R, Var, rho, H_prev=[1.0, 2.0])
    Hs = [0.25 * H0 + 0.75 * 1.0, 0.25 * H1 + 0.75 * 2.0]
    assert later["H_smoothed"] == pytest.approx(Hs)
    assert later["P_s"] == pytest.approx(expected(Hs)[2])


def test_a_scale_sure_of_one_direction_has_entropy_near_zero_and_silent_returns_give_equal_scales():
    mix = ao.mix_scales(np.array([[1.0] + [0.0] * 7]), np.zeros((1, 8)), [1.0])
    assert mix["P_ds"][0, 0] == 1.0 and 0 <= mix["H"][0] < 1e-200 and mix["P_s"][0] == 1.0
    silent = ao.mix_scales(np.zeros((3, 8)), np.zeros((3, 8)), [1.0, 1.0, 1.0])
    assert silent["q"] == pytest.approx([0, 0, 0]) and silent["P_s"] == pytest.approx([1 / 3] * 3)


def test_the_heading_is_the_angle_of_the_mean_direction_over_the_safe_pairs():
    V = np.array([[unit(45 * d) for d in range(8)]])
    P = np.zeros((1, 8))
    P[0, 0] = P[0, 2] = 0.5
    R = np.zeros((1, 8))
    R[0, 0], R[0, 2] = 1.0, 0.9
    out = ao.heading_rule(P, R, V, [True] * 8)
    assert out["rule"] == "mix" and out["heading"] == pytest.approx(math.radians(45))
    assert out["scale_weights"] == pytest.approx([1.0])
    # Direction 0 unsafe: P′ keeps direction 2 alone (renormalised), the heading is 90°.
    out = ao.heading_rule(P, R, V, [False] + [True] * 7)
    assert out["heading"] == pytest.approx(math.radians(90)) and out["P_prime"][0, 2] == pytest.approx(1.0)
    assert ao.heading_rule(P, R, V, [False] * 8) is None  # no safe direction: an exploration block


def test_opposed_best_pairs_take_the_best_pairs_vector():
    V = np.array([[unit(45 * d) for d in range(8)]])
    P = np.zeros((1, 8))
    P[0, 0], P[0, 4] = 0.6, 0.4
    R = np.zeros((1, 8))
    R[0, 0], R[0, 4] = 0.5, 0.6
    out = ao.heading_rule(P, R, V, [True] * 8)
    # The mix would point along +x (0.6 − 0.4); the two best returns point opposite ways (cos −1 < −0.75), so the
    # best return's own vector wins: 180°.
    assert out["rule"] == "opposed" and out["heading"] == pytest.approx(math.pi)
    # cos(135°) ≈ −0.707 is not below −0.75: the mix stands.
    R2 = np.zeros((1, 8))
    R2[0, 0], R2[0, 3] = 0.5, 0.6
    P2 = np.zeros((1, 8))
    P2[0, 0], P2[0, 3] = 0.6, 0.4
    out = ao.heading_rule(P2, R2, V, [True] * 8)
    c = 0.6 * unit(0) + 0.4 * unit(135)
    assert out["rule"] == "mix" and out["heading"] == pytest.approx(math.atan2(c[1], c[0]))


def test_a_vanishing_mean_falls_back_to_the_best_returns_vector():
    V = np.zeros((1, 8, 2))
    V[0, 0], V[0, 1], V[0, 2] = unit(0), unit(120), unit(240)
    P = np.zeros((1, 8))
    P[0, :3] = 1 / 3
    R = np.zeros((1, 8))
    R[0, :3] = [0.2, 0.3, 0.1]
    out = ao.heading_rule(P, R, V, [True] * 8)
    # Σ P′V = 0; the best two (directions 1 and 0) are 120° apart, cos −0.5: not opposed; |c| < 10⁻⁶ → V of the best.
    assert out["rule"] == "fallback" and out["heading"] == pytest.approx(math.radians(120))


def test_ties_in_the_returns_go_to_the_first_pair_in_scale_major_order():
    V = np.zeros((2, 8, 2))
    V[0, 1], V[1, 5] = unit(10), unit(190)
    P = np.zeros((2, 8))
    P[0, 1], P[1, 5] = 0.5, 0.5
    R = np.zeros((2, 8))
    R[0, 1] = R[1, 5] = 0.7
    out = ao.heading_rule(P, R, V, [True] * 8)
    assert out["rule"] == "opposed" and out["heading"] == pytest.approx(math.radians(10))
    assert out["scale_weights"] == pytest.approx([0.5, 0.5])


def test_contact_penalises_the_dominant_scale_and_its_cooldown_blocks_three_rewards():
    r = ao.Reliability(3)
    assert r.begin(0.0) == "decide"
    r.end([0.2, 0.5, 0.3], contact=True)
    assert r.rho == pytest.approx([1.0, 0.6, 1.0]) and r.cooldown.tolist() == [0, 4, 0]
    for expected in (0.6, 0.6, 0.6, 0.6 * 1.03, 0.6 * 1.03**2):
        assert r.begin(0.0) == "decide"
        r.end([0.2, 0.5, 0.3], contact=False)
        assert r.rho[1] == pytest.approx(expected)
    r.end([0.9, 0.05, 0.05], contact=False)  # a reward never lifts ρ above 1
    assert r.rho[0] == 1.0
    r.rho[:] = 0.15
    r.end([0.0, 0.0, 1.0], contact=True)
    assert r.rho[2] == pytest.approx(0.1)  # 0.09 clamped to the floor


def test_all_scales_unreliable_gives_ten_exploration_blocks_and_no_retrigger_while_still_low():
    r = ao.Reliability(3)
    r.rho[:] = 0.1
    for i in range(10):
        assert r.begin(0.0) == "explore"
        assert r.rho == pytest.approx([0.1 * 1.03**(i + 1)] * 3)
    assert np.all(r.rho < 0.15)  # 0.1·1.03¹⁰ ≈ 0.134: still low, but the trigger waits for one to recover
    assert r.begin(0.0) == "decide"
    r.rho[:] = [0.2, 0.1, 0.1]  # one recovers: the trigger is re-armed ...
    assert r.begin(0.0) == "decide"
    r.rho[:] = 0.1  # ... and fires again
    assert r.begin(0.0) == "explore"


def test_a_full_turn_of_decisions_is_a_loop_penalising_each_scale_by_its_share_of_the_turning():
    r = ao.Reliability(2)
    r.begin(0.0)
    r.end([0.75, 0.25], contact=False)
    for h in (90.0, 180.0, 270.0):
        assert r.begin(h) == "decide"
        r.end([0.75, 0.25], contact=False)
    assert r.accumulated == pytest.approx(270.0) and r.contributions == pytest.approx([0.75 * 0.75, 0.25 * 0.75])
    r.begin(0.0)  # 360° turned: one loop
    assert r.loops == 1 and r.accumulated == pytest.approx(0.0)
    assert r.rho == pytest.approx([1 - 0.4 * 0.75, 1 - 0.4 * 0.25]) and r.cooldown.tolist() == [4, 4]
    assert r.contributions == pytest.approx([0.0, 0.0])


def test_a_blocks_steps_turn_the_accumulator_but_not_the_scales_contributions():
    r = ao.Reliability(2)
    r.begin(0.0)
    r.end([1.0, 0.0], contact=False)
    r.movement_headings([90.0, 90.0, 90.0])  # the turn shows at the block's first step
    assert r.accumulated == pytest.approx(90.0)
    r.begin(90.0)  # nothing turned since the block's last step
    assert r.accumulated == pytest.approx(90.0) and r.contributions == pytest.approx([0.0, 0.0])
    r.begin(-170.0)  # wrapped: 100°
    assert r.accumulated == pytest.approx(190.0) and r.contributions == pytest.approx([100 / 360, 0.0])


def test_safety_sectors_centred_and_as_the_authors_index_them():
    az = np.radians([10.0, -10.0, 30.0, 100.0, 200.0])
    rng = np.array([0.5, 0.7, 0.9, 3.0, 2.0])
    centred = ao.sector_minima(rng, az)
    assert centred[0] == 0.5 and centred[1] == 0.9 and centred[2] == 3.0 and centred[4] == 2.0
    assert np.isinf(centred[[3, 5, 6, 7]]).all()
    authors = ao.sector_minima(rng, az, align="authors")
    assert authors[0] == 0.5 and authors[7] == 0.7 and authors[2] == 3.0 and authors[4] == 2.0
    assert (authors >= 1.0).tolist() == [False, True, True, True, True, True, True, False]


def test_exploration_and_failed_turns_map_their_draws():
    assert ao.exploration_turns(None, 1.0) == pytest.approx([math.radians(30)])
    assert ao.exploration_turns(0.75, -2.0) == pytest.approx([math.pi / 2, -math.radians(60)])
    assert ao.failed_turn(0.0) == pytest.approx(-math.pi / 4) and ao.failed_turn(1.0) == pytest.approx(math.pi / 4)


def test_a_decision_on_the_chain_heads_along_the_rewarded_rollouts():
    w = chain()
    a0 = np.array([1.0, 0.0, 0.0])
    uniforms = np.full((2, 8, 10), 0.5)
    scales = [(w, a0, np.array([0.0, 1.0, 0.5]))]
    out = ao.decide(scales, [1.0], [uniforms], sector_min=np.full(8, 5.0))
    # Only direction 0 returns anything: P(d|s) ≈ one-hot and the heading is that of its mean vector, (0, 0, 1):
    # (1, 0) + 2·unit(45°).
    v = unit(0) + 2 * unit(45)
    assert out["choice"]["rule"] == "mix" and out["choice"]["heading"] == pytest.approx(math.atan2(v[1], v[0]))
    # Direction 0's sector blocked: the seven others hold P(d|s) = e^(−500·1.35) ≈ 10⁻²⁹³ each, and P′ divides by
    # max(Σ, 10⁻⁹), not by Σ: P′ stays ≈ 10⁻²⁸⁴, |c| < 10⁻⁶, and the fallback takes the best safe return's vector —
    # all seven return 0, so the first, direction 1 (straight on: 3·unit(45°)).
    blocked = ao.decide(scales, [1.0], [uniforms], sector_min=np.array([0.5] + [5.0] * 7))
    assert blocked["choice"]["rule"] == "fallback" and blocked["choice"]["heading"] == pytest.approx(math.radians(45))
    assert blocked["choice"]["P_prime"].sum() < 1e-200
    assert ao.decide(scales, [1.0], [uniforms], sector_min=np.full(8, 0.9))["choice"] is None


def test_safe_pairs_renormalise_when_they_hold_enough_probability():
    # Returns 0.01 apart (500·0.01 = 5): the safe directions keep e^−5 of the best's weight, far above 10⁻⁹.
    R = np.array([[0.01] + [0.0] * 7])
    mix = ao.mix_scales(R, np.zeros((1, 8)), [1.0])
    V = np.array([[3 * unit(45 * d) for d in range(8)]])
    out = ao.heading_rule(mix["P"], R, V, [False] + [True] * 7)
    assert out["P_prime"][0, 1:] == pytest.approx([1 / 7] * 7) and out["P_prime"][0, 0] == 0
    assert out["rule"] == "mix" and out["heading"] == pytest.approx(math.pi)  # Σ of 7 of the 8 unit vectors: −unit(0)
