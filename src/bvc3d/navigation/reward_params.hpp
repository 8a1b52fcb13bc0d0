#pragma once
// Navigation stage: the parameters of replay, the rollouts and the choice between directions and scales (SPEC §17),
// one table (YAML `reward:`, Python keywords). Takes: nothing. Gives: RewardParams and its table.
#include <cstddef>
#include <vector>

#include "bvc3d/core/params.hpp"

namespace bvc3d {

struct RewardParams {
    double lambda = 20.0;    // λ: replay length ⌈8λ⌉ + 1 and its decay e^{−t/λ}
    double amplitude = 0.0;  // A; 0 means 5/λ
    int rollout_steps = 3;   // T
    double discount = 0.7;   // γ
    double beta = 500.0;     // directions are preferred by softmax(β·R)
    // Further scales of a multiscale model (the model's first scale takes `lambda`)
    std::vector<double> scale_lambdas{30.0, 60.0};  // λ of the second, third, ... scale (A = 5/λ unless `amplitude`)
    double scale_beta = 2.0;                        // scales are weighted by softmax(β_scale·score)
    double scale_smoothing = 0.25;                  // f: a scale's score smoothed over a start's decisions
    double amplitude_or_default() const { return amplitude > 0 ? amplitude : 5.0 / lambda; }
    // These parameters for scale s (0: the model's own place cells): its λ. InputError naming the key if
    // scale_lambdas has no value for it.
    RewardParams for_scale(std::size_t s) const;
    static const params::Table<RewardParams>& table();
    void validate() const { table().check(*this); }
};

}  // namespace bvc3d
