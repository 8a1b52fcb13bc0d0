#pragma once
// BVC stage: the parameters of a layer of boundary vector cells, with their defaults, keys and checks (the table).
// Takes: nothing. Gives: BvcParams and its table, read by YAML, `bvc3d config`, Python and the layer.
#include <string>
#include <vector>

#include "bvc3d/core/params.hpp"

namespace bvc3d {

enum class BvcNormalization { per_step_max, none, fixed };

// How a direction reads the scan: the paper's Gaussian over all returns (eq. 1-2), or the single
// return nearest to theta_k with no angular or elevation factor (the authors' code; `2d-8beam`).
enum class BvcReading { gaussian, nearest_beam };

// Defaults: the paper's σs and spacing; the layers of its `3d-0.2` model (the default model).
struct BvcParams {
    std::vector<double> elevations{0.0, 0.2};  // psi_l in radians; empty: the 2-D model (no elevation factor)
    int n_dir = 8;
    int n_per_axis = 60;
    double max_dist = 12.0;    // m
    double sigma_r = 0.75;     // m
    double sigma_theta = 0.1;  // rad
    double sigma_phi = 0.01;   // rad
    BvcNormalization normalization = BvcNormalization::per_step_max;
    double norm_constant = 1.0;  // `fixed`: rate = raw / norm_constant
    BvcReading reading = BvcReading::gaussian;

    // At most this many cells (layers × n_dir × n_per_axis): beyond it a layer is a mistake, and its
    // weights and rates would not fit in memory.
    static constexpr double max_cells = 1e6;

    int n_layers() const { return elevations.empty() ? 1 : static_cast<int>(elevations.size()); }
    int n_cells() const { return n_layers() * n_dir * n_per_axis; }
    double spacing() const { return n_per_axis > 1 ? max_dist / (n_per_axis - 1) : 0.0; }
    static const params::Table<BvcParams>& table();
    void validate() const;  // throws params::ParamError naming the bad parameter
};

}  // namespace bvc3d
