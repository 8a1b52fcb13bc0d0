#pragma once
// Population stage: reward cells (SPEC §17.1), one per goal, reading one scale of place cells. Takes: the place-cell
// rates v and the agent's pose at each step. Gives: each reward cell's rate, its read-out of the place cells
//       r_g(v) = w_g·v / max(|v|₁, 10⁻⁴)
// and, while learning, the place cell bound to each goal: the most active cell (rate > 0) at a step inside the goal's
// radius (distance in the plane for goals x, y; in 3-D for goals x, y, z). The weights w_g are 0 until navigation
// sets them by replay from the bound cell (navigation/replay.hpp); they are a learned array of the population's state.
#include <cstddef>
#include <span>
#include <vector>

#include "bvc3d/core/params.hpp"
#include "bvc3d/population/population.hpp"

namespace bvc3d {

struct RewardCellParams {
    std::vector<double> goals;  // x, y per goal (dims 2) or x, y, z (dims 3), one after another
    int dims = 2;
    double radius = 0.7;  // m: a step this close to a goal binds its cell
    std::size_t n_goals() const { return dims > 0 ? goals.size() / std::size_t(dims) : 0; }
    static const params::Table<RewardCellParams>& table();
    // The table's checks, and goals that are whole points of `dims` coordinates (InputError naming the key).
    void validate() const;
};

// r(v) = w·v / max(|v|₁, 10⁻⁴): a reward cell's rate (the read-out), written once.
double reward_readout(std::span<const double> w, std::span<const double> v);

class RewardCells : public Population {
public:
    RewardCells(std::size_t n_place, const RewardCellParams& params);
    std::size_t size() const override { return p_.n_goals(); }
    void step(const StepBlock& block, std::span<const std::span<const double>> inputs, std::span<double> out) override;
    std::vector<StateArray> state() const override;
    void restore(const std::vector<StateArray>& state) override;
    std::vector<StateArray> kept() const override { return state(); }

    const RewardCellParams& params() const { return p_; }
    // The place cell bound to goal g (-1: none yet), and the rate it was bound with.
    int bound(std::size_t g) const { return bound_[g]; }

private:
    std::size_t n_;
    RewardCellParams p_;
    std::vector<int> bound_;       // per goal: the bound place cell, -1 if none
    std::vector<double> best_;     // per goal: the bound cell's rate when bound
    std::vector<double> weights_;  // goals × place cells: w_g
    double distance(const Pose& pose, std::size_t g) const;
};

}  // namespace bvc3d
