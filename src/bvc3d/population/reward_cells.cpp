#include "bvc3d/population/reward_cells.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "bvc3d/core/error.hpp"

namespace bvc3d {

const params::Table<RewardCellParams>& RewardCellParams::table() {
    using namespace params;
    using P = RewardCellParams;
    static const Table<P> t(
        "reward cells", {reals("goals", &P::goals, finite(), "the goals' coordinates, x, y (or x, y, z) per goal"),
                         integer("dims", &P::dims, closed(2, 3), "coordinates per goal: 2 on the floor, 3 flying"),
                         real("radius", &P::radius, closed(0.01, 100), "m, a step this close binds a goal's cell")});
    return t;
}

void RewardCellParams::validate() const {
    table().check(*this);
    if (goals.empty() || goals.size() % std::size_t(dims) != 0)
        table().fail("goals",
                     std::to_string(goals.size()) + " coordinates are not whole goals of " + std::to_string(dims));
}

double reward_readout(std::span<const double> w, std::span<const double> v) {
    double dot = 0.0, l1 = 0.0;
    for (std::size_t i = 0; i < v.size(); ++i) dot += w[i] * v[i], l1 += std::abs(v[i]);
    return dot / std::max(l1, 1e-4);
}

RewardCells::RewardCells(std::size_t n_place, const RewardCellParams& params) : n_(n_place), p_(params) {
    p_.validate();
    const std::size_t g = p_.n_goals();
    bound_.assign(g, -1);
    best_.assign(g, 0.0);
    weights_.assign(g * n_, 0.0);
}

double RewardCells::distance(const Pose& pose, std::size_t g) const {
    // As navigation measures it (agent/navigation_space.hpp): in the plane on the floor, in 3-D in flight.
    const double* at = &p_.goals[g * std::size_t(p_.dims)];
    if (p_.dims == 2) return (Vec2(pose.x, pose.y) - Vec2(at[0], at[1])).norm();
    return (pose.position() - Vec3(at[0], at[1], at[2])).norm();
}

void RewardCells::step(const StepBlock& block, std::span<const std::span<const double>> inputs, std::span<double> out) {
    const std::size_t G = size();
    for (std::size_t s = 0; s < block.size(); ++s) {
        const auto v = inputs[0].subspan(s * n_, n_);
        if (block.learn[s])
            for (std::size_t g = 0; g < G; ++g) {
                if (!(distance(block.steps[s].pose, g) <= p_.radius)) continue;
                for (std::size_t i = 0; i < n_; ++i)
                    if (v[i] > best_[g]) best_[g] = v[i], bound_[g] = static_cast<int>(i);
            }
        for (std::size_t g = 0; g < G; ++g)
            out[s * G + g] = reward_readout(std::span<const double>(&weights_[g * n_], n_), v);
    }
}

std::vector<StateArray> RewardCells::state() const {
    const std::size_t G = size();
    std::vector<double> cells(bound_.begin(), bound_.end());
    return {{"reward_cells", {G}, std::move(cells)},
            {"reward_cell_rates", {G}, best_},
            {"reward_weights", {G, n_}, weights_}};
}

void RewardCells::restore(const std::vector<StateArray>& state) {
    const std::size_t G = size();
    const auto& cells = state_doubles(state, "reward_cells", G);
    for (std::size_t g = 0; g < G; ++g) {
        if (!(cells[g] >= -1 && cells[g] < double(n_) && cells[g] == std::floor(cells[g])))
            throw InputError("reward cells: goal " + std::to_string(g + 1) + "'s cell " + std::to_string(cells[g]) +
                             " is not one of " + std::to_string(n_));
        bound_[g] = static_cast<int>(cells[g]);
    }
    best_ = state_doubles(state, "reward_cell_rates", G);
    weights_ = state_doubles(state, "reward_weights", G * n_);
}

}  // namespace bvc3d
