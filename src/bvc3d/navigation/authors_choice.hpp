#pragma once
// Navigation stage: the authors' choice of a heading (SPEC §17.2 with the corrections of docs/navigation.md#the-
// authors-controller), in pieces a test can hold against test/python/authors_oracle.py. Takes: per scale a frozen
// adjacency (adjacency_product.hpp) with its column sums, a reward cell's weights and the current place-cell rates;
// the random draws as inputs; the LiDAR's least range per direction; each scale's reliability and the smoothed
// entropies of the decision before. Gives: each direction's mean return R, mean unit-step sum V and variance of the
// return, the scale mix P(s, d), the heading taken (or none: an exploration block), and the reliability and loop
// bookkeeping from decision to decision.
//
// Rollouts, per scale s and start direction d₀ (n directions, K samples, T steps, from the rates a₀):
//     for k = 0 … T−1:   k > 0: o ∈ (−1, 0, +1) drawn from softmax_o(Σ_i (W[d+o]·a)_i / temperature), d ← d + o
//                        a ← tanh([W[d]·a − a]+),   G += γ^k·r(a),   u += (cos θ_d, sin θ_d)
//     R = mean G, V = mean u, Var = Σ (G − R)² / (K − 1);   r(a) = clamp(w·a / max(|a|₁, 10⁻⁴), 0, 10⁶)
// The draw of a turn is the first option whose cumulative probability exceeds its uniform u (the last if rounding
// leaves u above them all); the uniforms come in the order scale → step k = 1 … T−1 → d₀ → sample. Rollouts that
// took the same directions share their states (the same products): a decision computes each distinct path once.
// Mix:   P(d|s) = e^{β(R − max R)} / max(Σ, 10⁻⁹),  M_s = Σ_d P·R,
//        H_s = −Σ_d P ln max(P, 10⁻⁹) + w·ln(1 + Σ_d P·Var),  H̃ = f·H + (1 − f)·H̃_prev (H at a start's first),
//        ι = (1/(H̃ + 10⁻⁹)) / max(Σ, 10⁻⁹),  q = M·ι^a·ρ^b / max(Σ, 10⁻⁹),  P(s) = softmax(β_s·q),
//        P(s,d) = P(s)·P(d|s)
// Heading: P′ = P over the safe pairs (s, d), / max(Σ, 10⁻⁹); c = Σ P′·V; if the two safe pairs of largest R have V's
//        at cos < −0.75: c = V of the best; if |c| < 10⁻⁶: c = V of the best; heading = atan2(c).
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "bvc3d/core/geometry.hpp"
#include "bvc3d/navigation/adjacency_product.hpp"
#include "bvc3d/navigation/authors_params.hpp"

namespace bvc3d {

// One scale's turning rollouts, per start direction.
struct TurningRollouts {
    std::vector<double> R, Var;  // n_dir each
    std::vector<Vec2> V;         // n_dir
    std::size_t products = 0;    // distinct states computed (what the decision cost)
};

// `column_sums`: n_dir × n (SparseAdjacency::column_sums); `uniforms`: (T−1) × n_dir × K, in that order.
TurningRollouts turning_rollouts(const AdjacencyProduct& adj, std::span<const double> column_sums,
                                 std::span<const double> w_reward, std::span<const double> a0,
                                 std::span<const double> uniforms, const AuthorsParams& p);
// How many uniforms a decision draws for `scales` scales of `n_dir` directions.
std::size_t rollout_uniforms(std::size_t scales, int n_dir, const AuthorsParams& p);

// The reward read-out of the authors' rollouts: clamp(w·a / max(|a|₁, 10⁻⁴), 0, 10⁶), NaN → 0.
double clamped_readout(std::span<const double> w, std::span<const double> a);

struct ScaleMix {
    std::size_t scales = 0, dirs = 0;
    std::vector<double> P_ds, P;                         // scales × dirs
    std::vector<double> M, H, H_smoothed, iota, q, P_s;  // per scale
};
// R, Var: scales × dirs; `reliability`: ρ per scale; `H_prev`: H̃ of the decision before (empty: a start's first).
ScaleMix mix_scales(std::span<const double> R, std::span<const double> Var, std::size_t dirs,
                    std::span<const double> reliability, std::span<const double> H_prev, const AuthorsParams& p);

enum class HeadingRule { mix, opposed, fallback };
std::string to_string(HeadingRule r);

struct HeadingChoice {
    double heading = 0;  // rad in [0, 2π)
    Vec2 c = Vec2::Zero();
    HeadingRule rule = HeadingRule::mix;
    std::vector<double> P_prime;        // scales × dirs, 0 at the unsafe pairs
    std::vector<double> scale_weights;  // Σ_d P′(s, d): what the reliability update credits
};
// None when no direction is safe (an exploration block). P, R: scales × dirs; V: scales × dirs; safe: dirs.
std::optional<HeadingChoice> heading_rule(std::span<const double> P, std::span<const double> R, std::span<const Vec2> V,
                                          std::span<const char> safe);

// The least range per direction's sector (+∞ for a sector without a return); azimuths allocentric, rad.
std::vector<double> sector_minima(std::span<const double> ranges, std::span<const double> azimuths, int n_dir,
                                  SafetySector sector);

// The per-start bookkeeping of reliability, loops and forced exploration, in the order the authors' code runs it:
// per decision begin(heading) first; if it says decide, the caller rolls out, mixes and takes the heading, moves
// (movement_headings: the heading after each step of the block) and calls end(scale_weights, contact).
class AuthorsReliability {
public:
    AuthorsReliability(std::size_t scales, const AuthorsParams& p);
    enum class Phase { explore, decide };
    Phase begin(double heading_deg);
    void movement_headings(std::span<const double> headings_deg);
    void end(std::span<const double> scale_weights, bool contact);

    const std::vector<double>& rho() const { return rho_; }
    const std::vector<int>& cooldown() const { return cooldown_; }
    const std::vector<double>& contributions() const { return contributions_; }
    double accumulated() const { return accumulated_; }
    int loops() const { return loops_; }
    int since_loop() const { return since_loop_; }
    int force_explore() const { return force_explore_; }
    int full_turns() const { return full_turns_; }  // times the accumulated heading change passed 360° (loops seen)
    int penalties() const { return penalties_; }    // loops that cost the scales reliability

private:
    double clamp(double x) const;
    AuthorsParams p_;
    std::vector<double> rho_, contributions_, last_weights_;
    std::vector<int> cooldown_;
    std::optional<double> last_heading_;
    double accumulated_ = 0;
    int loops_ = 0, since_loop_ = 0, force_explore_ = 0, full_turns_ = 0, penalties_ = 0;
    bool triggered_ = false;
};

// One scale's inputs to a decision.
struct DecisionScale {
    const AdjacencyProduct* adjacency = nullptr;
    std::span<const double> column_sums, w_reward, rates;
};

struct AuthorsDecision {
    std::vector<TurningRollouts> rollouts;  // per scale
    ScaleMix mix;
    std::optional<HeadingChoice> choice;  // none: no safe direction
};
// The whole choice: rollouts per scale (the uniforms split in the order above), the mix, the heading rule over the
// directions whose sector's least range is at least p.safe_distance.
AuthorsDecision authors_decide(std::span<const DecisionScale> scales, std::span<const double> uniforms,
                               std::span<const double> sector_min, std::span<const double> reliability,
                               std::span<const double> H_prev, const AuthorsParams& p);

}  // namespace bvc3d
