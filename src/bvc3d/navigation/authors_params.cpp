#include "bvc3d/navigation/authors_params.hpp"

namespace bvc3d {

const params::Table<AuthorsParams>& AuthorsParams::table() {
    using namespace params;
    using P = AuthorsParams;
    static const Table<P> t(
        "authors",
        {integer("samples", &P::samples, closed(2, 1000), "K: turning rollouts per direction and scale"),
         integer("steps", &P::steps, closed(1, 100), "T: steps of each rollout"),
         real("discount", &P::discount, closed(0, 1), "γ of a rollout's return G = Σ γ^k r"),
         real("temperature", &P::temperature, above(0),
              "of the rollouts' turns: softmax of Σ_i (W_rec[d+o]·a)_i / this"),
         real("beta", &P::beta, closed(0, 1e6), "P(d|s) = softmax(β·R) within a scale"),
         real("scale_beta", &P::scale_beta, closed(0, 1e6), "P(s) = softmax(β_s·q) between scales"),
         real("smoothing", &P::smoothing, closed(0, 1),
              "a scale's smoothed entropy: f·H + (1 − f)·(that of the decision before)"),
         real("variance_weight", &P::variance_weight, closed(0, 1e6), "H = −Σ P ln P + w·ln(1 + Σ P·Var)"),
         real("entropy_exponent", &P::entropy_exponent, closed(0, 100), "a in q ∝ M·ι^a·ρ^b"),
         real("reliability_exponent", &P::reliability_exponent, closed(0, 100), "b in q ∝ M·ι^a·ρ^b"),
         real("bad_factor", &P::bad_factor, closed(0, 1),
              "the dominant scale's ρ × this after a block ending in contact"),
         real("good_factor", &P::good_factor, closed(1, 10), "… × this after a block without, unless cooling down"),
         real("reliability_floor", &P::reliability_floor, closed(0, 1), "ρ stays in [this, 1]"),
         integer("cooldown", &P::cooldown, closed(0, 1000), "decisions without the reward after a penalty"),
         real("explore_trigger", &P::explore_trigger, closed(0, 1), "every ρ below this: exploration blocks"),
         integer("explore_blocks", &P::explore_blocks, closed(0, 1000), "exploration blocks the trigger starts"),
         real("loop_penalty", &P::loop_penalty, closed(0, 10), "on a loop ρ_s × (1 − this·c_s)"),
         integer("max_decisions_between_loops", &P::max_decisions_between_loops, closed(0, 1000000),
                 "the loop count restarts when more decisions passed since the last loop"),
         integer("loop_reset", &P::loop_reset, closed(1, 1000000), "loops counted before the count starts over"),
         integer("block_steps", &P::block_steps, closed(1, 1000), "model steps a decision moves"),
         real("step", &P::step, closed(0.001, 10), "m a model step moves"),
         integer("settle_steps", &P::settle_steps, closed(0, 1000), "model updates at a start before deciding"),
         real("min_turn", &P::min_turn, closed(0, 3.2), "a turn to the new heading no larger than this is skipped")
             .in_radians(),
         real("safe_distance", &P::safe_distance, closed(0, 100),
              "m: a direction is safe when the least range in its sector is at least this"),
         choice("sector", &P::sector, {{SafetySector::authors, "authors"}, {SafetySector::centred, "centred"}},
                "the returns that guard direction d: [θ_d, θ_d + 45°) (the authors') or centred on θ_d"),
         choice("contact", &P::contact, {{ContactRule::slide, "slide"}, {ContactRule::stop, "stop"}},
                "a step at contact slides along the wall (its motion's component along it) or stops there"),
         integer("scan_beams", &P::scan_beams, closed(8, 100000), "beams of the planar scan the sectors read"),
         integer("explore_steps", &P::explore_steps, closed(1, 1000), "steps of an exploration block"),
         real("explore_turn_sd", &P::explore_turn_sd, closed(0, 10), "an exploration block ends turning by N(0, sd)")
             .in_radians(),
         integer("failed_turn_steps", &P::failed_turn_steps, closed(0, 1000),
                 "steps after a turn that could not be completed"),
         real("failed_turn_max", &P::failed_turn_max, closed(0, 3.2), "… which turns by U(−max, max)").in_radians(),
         flag("learn", &P::learn,
              "Oja and the adjacency learn while exploiting (each start from the learned state, as their code)"),
         flag("refresh", &P::refresh,
              "while learning, the rollouts read copies made again from the live adjacency at each decision")});
    return t;
}

}  // namespace bvc3d
