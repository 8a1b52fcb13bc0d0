// bvc3d: the command-line program. Each subcommand lives in a cmd_*.cpp file.
// Exit status: 0 done, 2 bad input or a usage error (one line saying what and where), 3 an
// internal error, 130 interrupted (docs/experiments.md#exit-status).
#include <CLI/CLI.hpp>

#include <csignal>
#include <cstring>
#include <iostream>

#include "bvc3d/core/error.hpp"
#include "cli_common.hpp"
#include "commands.hpp"

namespace {

// CLI11's parse errors as one line and status 2, naming the command and, for an unknown command,
// the ones there are.
int usage_error(const CLI::App& app, const CLI::ParseError& e, int argc, char** argv) {
    const CLI::App* command = nullptr;
    for (int i = 1; i < argc && !command; ++i)
        for (const auto* sub : app.get_subcommands([](const CLI::App*) { return true; }))
            if (sub->get_name() == argv[i]) command = sub;
    std::string message = e.what();
    if (!command && argc > 1) {
        std::string list;
        for (const auto* sub : app.get_subcommands([](const CLI::App*) { return true; }))
            list += (list.empty() ? "" : ", ") + sub->get_name();
        message = argv[1][0] != '-'
                      ? std::string("unknown command '") + argv[1] + "' (commands: " + list + ")"
                      : std::string("unknown option '") + argv[1] + "': give a command first (" + list + ")";
    }
    const std::string help = command ? "bvc3d " + command->get_name() + " --help" : std::string("bvc3d --help");
    std::cerr << "bvc3d: usage error: " << bvc3d::cli::printable(message) << "\n(see '" << help << "')\n";
    return 2;
}

}  // namespace

int main(int argc, char** argv) {
    // Past the file-size limit (ulimit -f) a write then fails with EFBIG and is reported like a full
    // disk, instead of the signal ending the program.
    std::signal(SIGXFSZ, SIG_IGN);
    CLI::App app{
        "bvc3d: boundary vector cells and place cells in simulated 3-D worlds.\n"
        "Reproduces Gerstenslager, Dukenbaev & Minai (IJCNN 2025) and goes beyond it; see README.md and docs/."};
    app.require_subcommand(1);
    app.set_version_flag("--version", "bvc3d " BVC3D_VERSION);
    bvc3d::cli::add_simulator_commands(app);
    bvc3d::cli::add_model_commands(app);
    bvc3d::cli::add_experiment_commands(app);
    bvc3d::cli::add_sweep_command(app);
    bvc3d::cli::add_flight_command(app);
    bvc3d::cli::add_recording_commands(app);
    bvc3d::cli::add_view_command(app);
    bvc3d::cli::add_adaptive_command(app);
    bvc3d::cli::add_place_recognition_command(app);
    bvc3d::cli::add_route_command(app);
    bvc3d::cli::add_navigate_command(app);
    try {
        app.parse(argc, argv);
    } catch (const CLI::Success& e) {
        return app.exit(e);  // --help, --version
    } catch (const CLI::ParseError& e) {
        return usage_error(app, e, argc, argv);
    } catch (const bvc3d::InputError& e) {
        std::cerr << "bvc3d: error: " << bvc3d::cli::printable(e.what()) << "\n";
        return 2;
    } catch (const std::bad_alloc&) {
        std::cerr << "bvc3d: error: out of memory (the run needs more memory than the machine could give; "
                     "see docs/experiments.md#limits)\n";
        return 2;
    } catch (const std::exception& e) {
        std::cerr << "bvc3d: internal error: " << bvc3d::cli::printable(e.what()) << "\n";
        return 3;
    }
    return 0;
}
