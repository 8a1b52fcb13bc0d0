#pragma once
// Population stage: a growing place-cell network (docs/model-reference.md#growing-place-cells; SPEC §16, bvc3d's own
// answer to buildings). Takes: the rates of one BVC population, one vector per model step. Gives: place-cell rates
// (budget of them, the cells not yet recruited silent at 0), learning with Oja's rule on the steps that learn, and
// recruiting cells where none fires.
//
// Its n recruited cells are the paper's network of n cells (place/place_cell_network.hpp), bit for bit:
//   s ← s + (Δt/τ_p)·(−s + W·v_b − Γ_pb·Σ v_b − Γ_pp·Σ v_prev),   v = tanh(g·[s]+)
//   learning:  W_i ← W_i + η·v_i·(v_b − v_i·W_i/α_pb)                                              (Oja, §6)
// Recruitment, on every sample_every-th learning step (c = 1, 2, … counts the learning steps; the step is sampled
// when c mod sample_every = 0), after that step's update:
//   if n < budget and max_i v_i < threshold and Σ v_b > 0:
//       W_n = (p_connect·n_bvc) · v_b / Σ v_b,   s_n = 0,   n ← n + 1
// The new row has the total weight a paper row starts with on average (Bernoulli(p_connect) over n_bvc inputs),
// all of it on the BVCs active here: where a fraction f of the BVCs is active its drive W_n·v_b exceeds the
// feedforward inhibition Γ_pb·Σ v_b about p_connect/(Γ_pb·f) times over, so it fires here from the next step on.
// Then it learns as every cell does. n_initial cells start as the paper's (Bernoulli(p_connect) from the trial's
// weights stream: the same rows as PlaceCellNetwork's first n_initial); nothing else is random.
//
// A cell not recruited has zero weights: with Γ_pb, Γ_pp >= 0 its membrane never rises above 0, so it is silent and
// adds nothing to the inhibition. The network holds rows for `capacity` cells (doubling as it grows, up to budget):
// a step costs as many rows as it holds, not the budget.
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "bvc3d/core/params.hpp"
#include "bvc3d/place/place_cell_network.hpp"
#include "bvc3d/population/population.hpp"

namespace bvc3d {

struct GrowingParams {
    int budget = 2000;       // most cells: ~1 per 0.3 m² of a 600 m² floor (the hall: 632 m² of templates)
    int n_initial = 0;       // cells at the start, the paper's random ones
    double threshold = 0.5;  // recruit where no cell fires at half its largest rate (tanh: 1)
    int sample_every = 3;    // learning steps between sampled places: 0.43 m of the paper's walk (0.144 m a step)
    static const params::Table<GrowingParams>& table();
    void validate() const;  // the table's checks, and n_initial <= budget
};

class GrowingPlaceCells : public Population {
public:
    // `place`: the dynamics of §6 (its n_place is not used: the cells are budget and n_initial); Γ_pb and Γ_pp must
    // be >= 0 (InputError naming the key otherwise). Initial rows drawn from the weights stream of `seed`.
    GrowingPlaceCells(int n_bvc, const PlaceParams& place, const GrowingParams& growing, std::uint64_t seed);
    // The parameters' checks (ParamError naming the key): both tables', n_initial <= budget, Γ_pb, Γ_pp >= 0.
    static void check(const PlaceParams& place, const GrowingParams& growing);

    int n_bvc() const { return n_bvc_; }
    int n_cells() const { return n_; }  // recruited so far (with the initial ones)
    const GrowingParams& params() const { return g_; }
    const PlaceParams& place_params() const { return net_->params(); }
    std::int64_t learning_steps() const { return learning_steps_; }

    // One model step: the budget's rates (cells >= n_cells() are 0). Recruits after the update if the step is
    // sampled (see above).
    std::span<const float> step(std::span<const double> bvc_rates, bool learn);
    // Rates of the last step (budget values).
    std::span<const float> rates() const { return rates_; }
    // The recruited cells' weights, row-major n_cells() × n_bvc.
    std::vector<float> weights() const;
    // The learning step (c above) at which each recruited cell was recruited; 0 for the initial ones.
    const std::vector<std::int64_t>& recruited_at() const { return recruited_at_; }
    // Membrane and rates back to zero; weights and cells kept.
    void reset();
    void reset_activity() override { reset(); }

    std::size_t size() const override { return static_cast<std::size_t>(g_.budget); }
    void step(const StepBlock& block, std::span<const std::span<const double>> inputs, std::span<double> out) override;
    std::vector<StateArray> state() const override;
    void restore(const std::vector<StateArray>& state) override;
    // weights (budget × n_bvc, rows >= n_cells 0) and recruited_at (budget; −1 for a cell never recruited).
    std::vector<StateArray> kept() const override;
    std::vector<std::pair<std::string, std::int64_t>> counters() const override;

private:
    int n_bvc_;
    GrowingParams g_;
    std::uint64_t seed_;
    std::unique_ptr<PlaceCellNetwork> net_;  // capacity rows
    int n_ = 0;
    std::int64_t learning_steps_ = 0;
    std::vector<std::int64_t> recruited_at_;
    std::vector<float> rates_;  // budget
    bool sampled(bool learn) const;
    void recruit_if_silent(std::span<const double> bvc_rates);
    void set_capacity(int capacity);  // rows held, >= n_
};

}  // namespace bvc3d
