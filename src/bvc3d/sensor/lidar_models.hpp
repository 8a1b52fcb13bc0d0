#pragma once
// Sensor stage: real LiDAR models as beam tables (docs/worlds.md#sensors). One table of data from
// the makers' datasheets: vertical angles, columns per turn, range limits, range noise.
// Takes: a model's name. Gives: its LidarSpec (`vlp16`, `hdl32`, `hdl64`, `os1-64`, `os1-128`).
#include <string>
#include <vector>

#include "bvc3d/sensor/lidar.hpp"

namespace bvc3d {

// The beams are evenly spaced in elevation from `top_deg` (row 0) down to `bottom_deg`, the columns
// evenly in azimuth.
struct LidarModel {
    std::string name;
    std::string description;  // maker, model and where the numbers come from
    double top_deg = 0.0, bottom_deg = 0.0;
    int beams = 1;
    int columns = 1;
    double min_range = 0.0, max_range = 0.0;  // m
    double range_noise_sd = 0.0;              // m
};

// Mounted at the paper's 3-D scanner height, so that swapping scanners changes only the beam pattern.
inline constexpr double lidar_model_height = 0.18;  // m

const std::vector<LidarModel>& lidar_models();
const LidarModel* find_lidar_model(const std::string& name);  // nullptr for other names
LidarSpec lidar_model_spec(const LidarModel& model);

}  // namespace bvc3d
