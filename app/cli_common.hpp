#pragma once
// Helpers shared by the bvc3d subcommands.
#include <CLI/CLI.hpp>

#include <string>

#include "bvc3d/sensor/lidar.hpp"

namespace bvc3d::cli {

// "X,Y,HEADING": metres and radians; the heading may end in "deg" for degrees.
Pose parse_pose(const std::string& text);

// Full-precision decimal text for numbers written to CSV.
std::string num(double v);

void add_simulator_commands(CLI::App& app);
void add_model_commands(CLI::App& app);
void add_experiment_commands(CLI::App& app);

}  // namespace bvc3d::cli
