#pragma once
// Navigation stage: the parameters of the authors' controller (SPEC §17.2, policy `authors`), one table (YAML's
// `authors:` section beside `policy: authors`, Python's authors=dict(...)). Takes: nothing. Gives: AuthorsParams and
// its table. The defaults are the values of the authors' code (docs/navigation.md#the-authors-controller says where
// each comes from and where bvc3d departs from SPEC's text).
#include "bvc3d/core/params.hpp"

namespace bvc3d {

// What a step does at contact: slide along the wall (the motion's component along it goes on, as a robot pushed by
// its wheels against a wall at an angle does in a physics simulator) or stop (SPEC §4's body).
enum class ContactRule { slide, stop };

// Which LiDAR returns guard a direction d (θ_d = 2πd/n): [θ_d, θ_d + 2π/n) as the authors' index arithmetic gives,
// or [θ_d − π/n, θ_d + π/n), centred on it.
enum class SafetySector { authors, centred };

struct AuthorsParams {
    // Rollouts (per scale, per start direction)
    int samples = 10;          // K rollouts per direction
    int steps = 3;             // T steps each
    double discount = 0.7;     // γ of G = Σ γ^k r
    double temperature = 1.0;  // of the turns' softmax over Σ_i (W_rec[d + o]·a)_i
    // The scale mix
    double beta = 500.0;            // P(d|s) = softmax_d(β·R)
    double scale_beta = 2.0;        // P(s) = softmax(β_s·q)
    double smoothing = 0.25;        // H̃ = f·H + (1 − f)·H̃_prev
    double variance_weight = 1.0;   // H = −Σ P ln P + w·ln(1 + Σ P·Var)
    double entropy_exponent = 2.0;  // q ∝ M·ι^a·ρ^b
    double reliability_exponent = 2.0;
    // Reliability and loops
    double bad_factor = 0.6;               // ρ of the dominant scale × this after a block ending in contact
    double good_factor = 1.03;             // … × this after one without, unless cooling down
    double reliability_floor = 0.1;        // ρ ∈ [floor, 1]
    int cooldown = 4;                      // decisions without reward after a penalty
    double explore_trigger = 0.15;         // every ρ below this: exploration blocks
    int explore_blocks = 10;               // how many
    double loop_penalty = 0.4;             // ρ_s × (1 − penalty·c_s) on a loop
    int max_decisions_between_loops = 10;  // the loop count restarts after more
    int loop_reset = 10;                   // loops counted before the count starts over
    // Movement
    int block_steps = 10;                   // model steps a decision moves
    double step = 0.143;                    // m a model step
    int settle_steps = 10;                  // model updates at a start before the first decision
    double min_turn = 0.08726646259971647;  // rad (5°): a turn no larger is skipped
    double safe_distance = 1.0;             // m: a direction is safe when its sector's least range is at least this
    SafetySector sector = SafetySector::authors;
    ContactRule contact = ContactRule::slide;
    int scan_beams = 720;                         // the planar scan's beams, all round
    int explore_steps = 10;                       // an exploration block's steps
    double explore_turn_sd = 0.5235987755982988;  // rad (30°): the block's closing turn ~ N(0, sd)
    int failed_turn_steps = 3;                    // steps after a turn that could not be completed
    double failed_turn_max = 0.7853981633974483;  // rad (45°): its turn ~ U(−max, max)
    // Learning while exploiting
    bool learn = true;    // Oja and the adjacency learn during a start (from the learned state, reloaded each start)
    bool refresh = true;  // while learning, the rollouts' copies are made again from the live adjacency each decision
    static const params::Table<AuthorsParams>& table();
    void validate() const { table().check(*this); }
};

}  // namespace bvc3d
