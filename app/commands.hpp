#pragma once
// The groups of subcommands, each defined in its own file and registered in main.cpp.
#include <CLI/CLI.hpp>

namespace bvc3d::cli {

void add_simulator_commands(CLI::App& app);         // cmd_simulator.cpp: scan, walk
void add_model_commands(CLI::App& app);             // cmd_model.cpp: bvc, config
void add_experiment_commands(CLI::App& app);        // cmd_experiment.cpp: run, paper, analyze, summarize
void add_sweep_command(CLI::App& app);              // cmd_sweep.cpp
void add_flight_command(CLI::App& app);             // cmd_flight.cpp
void add_recording_commands(CLI::App& app);         // cmd_recording.cpp: replay, localize, map, export-scans
void add_view_command(CLI::App& app);               // view/cmd_view.cpp
void add_adaptive_command(CLI::App& app);           // cmd_adaptive.cpp: choose-elevations
void add_place_recognition_command(CLI::App& app);  // cmd_place_recognition.cpp
void add_route_command(CLI::App& app);              // cmd_route.cpp: route, tour
void add_navigate_command(CLI::App& app);           // cmd_navigate.cpp

}  // namespace bvc3d::cli
