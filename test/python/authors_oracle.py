"""The authors' exploitation controller (SPEC §17.2), written out in numpy from the spec and a reading of their code
(bduke13/AlabiHippocampalModel: multiscale_grid_driver.py `exploit_v12`, `_execute_movement`, `explore` @26c3ab19;
multiscale_pcn_with_gcn.py `hierarchical_multiscale_preplay_sampling` @c34c9e9d). It shares no code with bvc3d or
with theirs; it is the oracle the C++ `policy: authors` is tested against.

Every random number is an input, so that an implementation drawing from its own seeded stream can be checked to
make the same choices from the same draws:
- rollout turns: one uniform u in [0, 1) per (scale, step k = 1 … T−1, start direction d0, sample j), consumed in
  that order (the authors draw one categorical per step for all n_hd·K trajectories of a scale, trajectory index
  d0·K + j). `rollout_uniforms(flat, ...)` splits a flat stream that way. A turn takes the first option m of
  (−1, 0, +1) whose cumulative probability exceeds u (the last option when rounding leaves u above them all).
- exploration blocks: for a contact, u → a turn of −π + 2πu; the closing turn takes a standard normal z → 30°·z.
- a failed turn: u → a turn of −π/4 + (π/2)u.
Angles are radians unless a name says _deg; direction k points along 2πk/n_hd in the frame where k increases.
"""
import math

import numpy as np

TURNS = (-1, 0, 1)  # the rollout's turn options, in HD steps of 2π/n_hd, in the authors' order


def rollout_step(w, a):
    """One look-ahead step through one direction's matrix: tanh([W·a − a]+)."""
    return np.tanh(np.maximum(w @ a - a, 0.0))


def readout(w_reward, a):
    """The reward cell's rate: clamp(w·a / max(|a|₁, 10⁻⁴), 0, 10⁶)."""
    return float(np.clip(w_reward @ a / max(np.abs(a).sum(), 1e-4), 0.0, 1e6))


def turn_probabilities(w_rec, a, d, temperature=1.0):
    """softmax over o ∈ (−1, 0, +1) of Σ_i (W_rec[(d + o) mod n_hd]·a)_i / temperature."""
    n_hd = w_rec.shape[0]
    logits = np.array([(w_rec[(d + o) % n_hd] @ a).sum() / temperature for o in TURNS])
    e = np.exp(logits - logits.max())
    return e / e.sum()


def pick(p, u):
    """Inverse CDF: the first index whose cumulative probability exceeds u (the last one if rounding leaves none)."""
    c = np.cumsum(p)
    for m in range(len(p)):
        if u < c[m]:
            return m
    return len(p) - 1


def rollout_uniforms(flat, n_scales, n_hd=8, samples=10, steps=3):
    """Split a flat stream of uniforms in the documented order into one (steps−1, n_hd, samples) array per scale."""
    per_scale = (steps - 1) * n_hd * samples
    flat = np.asarray(flat, dtype=float)
    if flat.size != n_scales * per_scale:
        raise ValueError(f"expected {n_scales * per_scale} uniforms, got {flat.size}")
    return [flat[s * per_scale:(s + 1) * per_scale].reshape(steps - 1, n_hd, samples) for s in range(n_scales)]


def sample_rollouts(w_rec, a0, w_reward, uniforms, samples=10, steps=3, discount=0.7, temperature=1.0):
    """One scale's turning rollouts (SPEC §17.2 "Rollouts"). w_rec: (n_hd, n, n); a0: the current rates; uniforms:
    (steps−1, n_hd, samples). Per start direction d0 and sample j: d = d0; for k = 0 … steps−1: at k > 0 turn by the
    option picked from turn_probabilities(w_rec, a, d) with uniforms[k−1, d0, j]; then a ← rollout_step(W_rec[d], a),
    G += discount^k·readout(a), u += (cos, sin)(2πd/n_hd). Returns R (n_hd,) the mean G, V (n_hd, 2) the mean u, Var
    (n_hd,) the variance of G with divisor samples − 1, and G and the visited directions per sample."""
    n_hd = w_rec.shape[0]
    uniforms = np.asarray(uniforms, dtype=float).reshape(steps - 1, n_hd, samples)
    G = np.zeros((n_hd, samples))
    U = np.zeros((n_hd, samples, 2))
    dirs = np.zeros((n_hd, samples, steps), dtype=int)
    for d0 in range(n_hd):
        for j in range(samples):
            a, d = np.array(a0, dtype=float), d0
            for k in range(steps):
                if k > 0:
                    d = (d + TURNS[pick(turn_probabilities(w_rec, a, d, temperature), uniforms[k - 1, d0, j])]) % n_hd
                a = rollout_step(w_rec[d], a)
                G[d0, j] += discount**k * readout(w_reward, a)
                U[d0, j] += (math.cos(2 * math.pi * d / n_hd), math.sin(2 * math.pi * d / n_hd))
                dirs[d0, j, k] = d
    return {"R": G.mean(axis=1), "V": U.mean(axis=1), "Var": G.var(axis=1, ddof=1), "G": G, "dirs": dirs}


def mix_scales(R, Var, reliability, H_prev=None, beta=500.0, scale_beta=2.0, smoothing=0.25, variance_weight=1.0,
               entropy_exp=2.0, reliability_exp=2.0):
    """SPEC §17.2 "Mixing scales" with the code's guards. R, Var: (S, D); reliability: (S,); H_prev: the smoothed
    entropies of the previous decision (None: H̃ = H). Returns P(d|s), M, H, H̃, ι, q, P(s) and P(s, d)."""
    R, Var = np.atleast_2d(np.asarray(R, float)), np.atleast_2d(np.asarray(Var, float))
    e = np.exp(beta * (R - R.max(axis=1, keepdims=True)))
    P_ds = e / np.maximum(e.sum(axis=1, keepdims=True), 1e-9)
    M = (P_ds * R).sum(axis=1)
    H = -(P_ds * np.log(np.maximum(P_ds, 1e-9))).sum(axis=1) + variance_weight * np.log1p((P_ds * Var).sum(axis=1))
    H_s = H if H_prev is None else smoothing * H + (1 - smoothing) * np.asarray(H_prev, float)
    inv = 1.0 / (H_s + 1e-9)
    iota = inv / max(inv.sum(), 1e-9)
    q_raw = M * iota**entropy_exp * np.asarray(reliability, float)**reliability_exp
    q = q_raw / max(q_raw.sum(), 1e-9)
    w = np.exp(scale_beta * (q - q.max()))
    P_s = w / max(w.sum(), 1e-9)
    return {"P_ds": P_ds, "M": M, "H": H, "H_smoothed": H_s, "iota": iota, "q": q, "P_s": P_s,
            "P": P_s[:, None] * P_ds}


def sector_minima(ranges, azimuths, n_hd=8, align="centred"):
    """The minimum range per direction's 45° sector (2π/n_hd). align="centred": azimuths within [θ_d − π/n_hd,
    θ_d + π/n_hd); "authors": [θ_d, θ_d + 2π/n_hd), the one-sided sector their index arithmetic gives (see the
    notes). A sector without a return has +inf."""
    width = 2 * math.pi / n_hd
    shift = width / 2 if align == "centred" else 0.0 if align == "authors" else None
    if shift is None:
        raise ValueError(f"align: centred or authors, not {align!r}")
    sector = np.floor(np.mod(np.asarray(azimuths, float) + shift, 2 * math.pi) / width).astype(int) % n_hd
    out = np.full(n_hd, np.inf)
    np.minimum.at(out, sector, np.asarray(ranges, float))
    return out


def heading_rule(P, R, V, safe):
    """SPEC §17.2 "Heading taken". P, R: (S, D); V: (S, D, 2); safe: (D,) bools (a direction is safe in every scale
    or none). Pairs are ranked in the order s·D + d (ties: the first). Returns None when no pair is safe (an
    exploration block), else the heading in [0, 2π), the vector c, the rule that set it ("mix", "opposed",
    "fallback"), P′ and each scale's share Σ_d P′(s, d) (what the reliability update credits)."""
    S, D = np.shape(P)
    mask = np.tile(np.asarray(safe, bool), S)
    if not mask.any():
        return None
    p, r, v = np.ravel(P)[mask], np.ravel(R)[mask], np.reshape(V, (S * D, 2))[mask]
    p = p / max(p.sum(), 1e-9)
    c, rule = (p[:, None] * v).sum(axis=0), "mix"
    if len(r) >= 2:
        i1 = int(np.argmax(r))
        rest = r.copy()
        rest[i1] = -np.inf
        i2 = int(np.argmax(rest))
        n1, n2 = np.linalg.norm(v[i1]), np.linalg.norm(v[i2])
        if n1 > 1e-9 and n2 > 1e-9 and v[i1] @ v[i2] / (n1 * n2) < -0.75:
            c, rule = v[i1], "opposed"
    if np.linalg.norm(c) < 1e-6:
        c, rule = v[int(np.argmax(r))], "fallback"
    P_prime = np.zeros(S * D)
    P_prime[mask] = p
    P_prime = P_prime.reshape(S, D)
    return {"heading": math.atan2(c[1], c[0]) % (2 * math.pi), "c": np.array(c), "rule": rule, "P_prime": P_prime,
            "scale_weights": P_prime.sum(axis=1)}


class Reliability:
    """The per-start state of SPEC §17.2 "Reliability" and loop detection, in the order the authors' exploit_v12
    runs it. Per decision: begin(heading_deg) first ("explore" or "decide"); if "decide", the caller rolls out,
    mixes and applies the heading rule, then moves (movement_headings(...) with the heading after each step of the
    block) and calls end(scale_weights, contact)."""

    def __init__(self, n_scales, bad=0.6, good=1.03, floor=0.1, cooldown=4, trigger=0.15, explore_blocks=10,
                 loop_penalty=0.4, max_steps_between_loops=10, loop_reset=10):
        self.rho = np.ones(n_scales)
        self.cooldown = np.zeros(n_scales, dtype=int)
        self.contributions = np.zeros(n_scales)
        self.last_weights = None
        self.last_heading = None
        self.accumulated = 0.0
        self.loops = 0
        self.since_loop = 0
        self.force_explore = 0
        self.triggered = False
        self.bad, self.good, self.floor, self.cooldown_steps = bad, good, floor, cooldown
        self.trigger, self.explore_blocks, self.loop_penalty = trigger, explore_blocks, loop_penalty
        self.max_steps_between_loops, self.loop_reset = max_steps_between_loops, loop_reset

    def clamp(self, x):
        return np.clip(x, self.floor, 1.0)

    @staticmethod
    def wrap_deg(x):
        return (x + 180.0) % 360.0 - 180.0

    def begin(self, heading_deg):
        self.cooldown = np.maximum(self.cooldown - 1, 0)
        low = bool(np.all(self.rho < self.trigger))
        if low and not self.triggered:
            self.force_explore, self.triggered = self.explore_blocks, True
        elif not low:
            self.triggered = False
        if self.force_explore > 0:
            self.force_explore -= 1
            self.rho = self.clamp(self.rho * self.good)
            return "explore"
        if self.last_heading is None:
            self.last_heading = heading_deg
        diff = abs(self.wrap_deg(heading_deg - self.last_heading))
        self.accumulated += diff
        self.last_heading = heading_deg
        if self.last_weights is not None:
            self.contributions += self.last_weights * diff / 360.0
        if self.accumulated >= 360.0:
            self.loops += 1
            self.accumulated -= 360.0
            if self.since_loop > self.max_steps_between_loops:
                self.loops = 1
            self.since_loop = 0
            if self.loops >= 1 and self.contributions.sum() > 0:
                c = self.contributions
                self.rho = self.clamp(self.rho * (1.0 - c * self.loop_penalty))
                self.cooldown[c > 0] = self.cooldown_steps
                self.contributions = np.zeros_like(c)
            if self.loops >= self.loop_reset:
                self.loops, self.accumulated, self.since_loop = 0, 0.0, 0
        else:
            self.since_loop += 1
            if self.since_loop > self.max_steps_between_loops:
                self.loops = 0
        return "decide"

    def movement_headings(self, headings_deg):
        """The block's steps add their heading changes to the loop accumulator (not to the scales' contributions)."""
        for h in headings_deg:
            if self.last_heading is not None:
                self.accumulated += abs(self.wrap_deg(h - self.last_heading))
            self.last_heading = h

    def end(self, scale_weights, contact):
        self.last_weights = np.asarray(scale_weights, float).copy()
        k = int(np.argmax(self.last_weights))
        if contact:
            if self.force_explore == 0:
                self.rho[k] = self.clamp(self.rho[k] * self.bad)
                self.cooldown[k] = self.cooldown_steps
        elif self.cooldown[k] <= 0:
            self.rho[k] = min(self.rho[k] * self.good, 1.0)


def exploration_turns(contact_u=None, z=0.0):
    """An exploration block's turns in order: on a contact (u given) −π + 2πu, then always 30°·z."""
    turns = [] if contact_u is None else [-math.pi + 2 * math.pi * contact_u]
    return turns + [math.radians(30.0) * z]


def failed_turn(u):
    """The turn after a turn that could not be completed: −π/4 + (π/2)u (then 3 steps)."""
    return -math.pi / 4 + math.pi / 2 * u


def decide(scales, reliability, uniforms, sector_min, H_prev=None, min_clearance=1.0, **rollout):
    """One decision's choice (after Reliability.begin returned "decide"): per scale (w_rec, a, w_reward) the
    rollouts with its uniforms, the mix, the safety filter and the heading rule. Returns the heading rule's dict
    (None: an exploration block) with the mix and the rollouts, and the smoothed entropies to pass on."""
    outs = [sample_rollouts(w, a, wr, u, **rollout) for (w, a, wr), u in zip(scales, uniforms)]
    R = np.array([o["R"] for o in outs])
    V = np.array([o["V"] for o in outs])
    Var = np.array([o["Var"] for o in outs])
    mix = mix_scales(R, Var, reliability, H_prev)
    choice = heading_rule(mix["P"], R, V, np.asarray(sector_min) >= min_clearance)
    return {"choice": choice, "mix": mix, "R": R, "V": V, "Var": Var, "H_smoothed": mix["H_smoothed"]}
