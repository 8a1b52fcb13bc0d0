#pragma once
// BVC stage: which rows of a scanner a layer needs. Takes: a layer's parameters and a beam table (LidarSpec). Gives:
// the rows to cast (a row whose elevation factor is negligible for every layer is skipped) and, bounded in advance
// from the beam table, what the skipped rows could have added (truncation_bound.hpp).
#include <algorithm>
#include <cstddef>
#include <vector>

#include "bvc3d/bvc/bvc_params.hpp"
#include "bvc3d/sensor/lidar.hpp"

namespace bvc3d {

struct ScanPlan {
    std::vector<char> rows;             // one flag per row of the sensor
    std::vector<double> skipped_rows;   // elevations of the rows not needed
    std::vector<double> skipped_bound;  // per layer: bound on their contribution to any cell
    std::size_t beams = 0;              // beams in the full table
    // Σ_columns A(x) over one row's columns, for any heading and direction, is at most angular_sum (a unimodal
    // function summed over a lattice); rows_per_label rows at most carry the same elevation label.
    double angular_sum = 0;
    int rows_per_label = 1;
    std::size_t columns = 0;  // the sensor's columns per row
    bool skips(double elevation) const {
        return std::find(skipped_rows.begin(), skipped_rows.end(), elevation) != skipped_rows.end();
    }
};

ScanPlan plan_scan(const BvcParams& params, const LidarSpec& sensor);

}  // namespace bvc3d
