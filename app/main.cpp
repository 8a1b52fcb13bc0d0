// bvc3d: the command-line program. Each subcommand lives in a cmd_*.cpp file.
#include <CLI/CLI.hpp>

#include <iostream>

#include "bvc3d/core/error.hpp"
#include "cli_common.hpp"

int main(int argc, char** argv) {
    CLI::App app{
        "bvc3d: boundary vector cells and place cells in simulated 3-D worlds.\n"
        "Reproduces Gerstenslager, Dukenbaev & Minai (IJCNN 2025) and goes beyond it; see README.md and docs/."};
    app.require_subcommand(1);
    app.set_version_flag("--version", "bvc3d " BVC3D_VERSION);
    bvc3d::cli::add_simulator_commands(app);
    bvc3d::cli::add_model_commands(app);
    bvc3d::cli::add_experiment_commands(app);
    bvc3d::cli::add_sweep_command(app);
    bvc3d::cli::add_recording_commands(app);
    bvc3d::cli::add_view_command(app);
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        return app.exit(e);
    } catch (const bvc3d::InputError& e) {
        std::cerr << "bvc3d: error: " << e.what() << "\n";
        return 2;
    } catch (const std::exception& e) {
        std::cerr << "bvc3d: internal error: " << e.what() << "\n";
        return 3;
    }
    return 0;
}
