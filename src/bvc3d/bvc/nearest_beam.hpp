#pragma once
// BVC stage: the authors'-code reading of the 2-D model (`2d-8beam`, docs/model-reference.md#presets): each
// direction k reads only the single return whose azimuth is nearest to θ_k, with no angular or elevation factor:
//   raw_(k, m) = D(r_k − d_m),   r_k the range of the first return with the smallest |wrap(θ_j − θ_k)|.
// Takes: returns. Gives: the raw sums (a workspace: private to the layer).
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "bvc3d/bvc/tuning.hpp"
#include "bvc3d/sensor/lidar.hpp"

namespace bvc3d {

class NearestBeamReading {
public:
    explicit NearestBeamReading(const LayerTuning& tuning);
    // raw into `out` (zeroed by the caller). Pruned: only each direction's distance window is evaluated; returns
    // false if what that drops is not below the pruning tolerance (the caller then reads again unpruned).
    bool raw(std::span<const LidarReturn> returns, std::span<double> out, bool prune);

private:
    LayerTuning t_;
    double window_r_;
    std::vector<double> dir_angle_;          // θ_k, NaN-padded to a multiple of 8
    std::vector<std::int64_t> best_return_;  // per direction
    std::vector<double> best_gap_;
    std::vector<double> near_azimuth_;  // the valid returns' azimuths and indices
    std::vector<std::size_t> near_index_;
    std::vector<std::size_t> cells_;  // the cells to evaluate and their exponents
    std::vector<double> exponents_;
};

}  // namespace bvc3d
