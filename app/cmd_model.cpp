// bvc3d bvc: what a model's boundary vector cells respond to at one pose; bvc3d config: trials, models
// and sensors as YAML with every key.
#include <cstdio>
#include <iostream>
#include <memory>

#include "bvc3d/config/model_yaml.hpp"
#include "bvc3d/config/trial_yaml.hpp"
#include "bvc3d/config/world_yaml.hpp"
#include "bvc3d/core/angles.hpp"
#include "bvc3d/core/atomic_file.hpp"
#include "bvc3d/core/csv.hpp"
#include "cli_common.hpp"
#include "commands.hpp"
#include "option_groups.hpp"

namespace bvc3d::cli {

namespace {

// The rates along one (layer, direction) axis as a row of block characters, `width` wide.
std::string sparkline(const double* v, int n, int width) {
    static const char* blocks[] = {" ", "▁", "▂", "▃", "▄", "▅", "▆", "▇", "█"};
    std::string s;
    for (int c = 0; c < width; ++c) {
        double mx = 0;
        for (int m = c * n / width; m < std::max((c + 1) * n / width, c * n / width + 1); ++m) mx = std::max(mx, v[m]);
        s += blocks[std::clamp(static_cast<int>(std::ceil(mx / 0.5 * 8)), 0, 8)];
    }
    return s;
}

void add_bvc(CLI::App& app) {
    auto* cmd = app.add_subcommand("bvc", "Show the boundary vector cell rates of a model at one pose");
    struct Options {
        std::string model = "3d-0.2", pose, csv;
        WorldOptions world;
        Outputs outputs;
    };
    auto o = std::make_shared<Options>();
    add_model_option(*cmd, o->model, ModelCount::one);
    o->world.add_to(*cmd);
    cmd->add_option("--pose", o->pose, "Robot pose X,Y,HEADING (m, m, rad; or e.g. 90deg)")->required();
    o->outputs.add(*cmd, "--csv", o->csv, OutputKind::file,
                   "Also write every cell to this CSV file: index, elevation, azimuth, distance, rate");
    cmd->footer(
        "One line per (layer, direction): the largest rate, the preferred distance where it peaks, and the\n"
        "rates over preferred distance 0..max_dist as a bar (a full block is the step's maximum, 0.5).");
    cmd->callback([o] {
        o->outputs.check();
        const ModelSpec model = config::resolve_model(o->model);
        const World world(o->world.resolve());
        const Pose pose = parse_pose(o->pose);
        warn_if_blocked(world, pose);
        const Scan scan = Lidar(model.sensor).scan(world, pose);
        const BoundaryVectorLayer layer(model.bvc);
        std::vector<double> rates(layer.n_cells());
        layer.rates(scan, rates);
        const auto& p = model.bvc;
        std::printf("model %s (%s scanner, %zu returns) in %s at x=%.3f y=%.3f heading=%.3f rad: %zu BVCs\n",
                    model.name.c_str(), model.sensor.name.c_str(), scan.size(), world.name().c_str(), pose.x, pose.y,
                    pose.heading, layer.n_cells());
        std::printf("%-9s %-6s %-6s %-7s rate over distance 0 .. %g m\n", "elev rad", "dir", "peak", "at m",
                    p.max_dist);
        for (int l = 0; l < p.n_layers(); ++l)
            for (int k = 0; k < p.n_dir; ++k) {
                const double* v = rates.data() + (static_cast<std::size_t>(l) * p.n_dir + k) * p.n_per_axis;
                const int best = static_cast<int>(std::max_element(v, v + p.n_per_axis) - v);
                std::printf("%-9s %4.0f°  %6.4f %6.2f  %s\n",
                            p.elevations.empty() ? "2-D" : std::to_string(p.elevations[l]).substr(0, 5).c_str(),
                            rad_to_deg(k * two_pi / p.n_dir), v[best], best * p.spacing(),
                            sparkline(v, p.n_per_axis, 40).c_str());
            }
        if (!o->csv.empty()) {
            AtomicFile f(o->csv);
            CsvWriter csv(f.stream());
            csv.row("index", "elevation", "azimuth", "distance", "rate");
            for (std::size_t i = 0; i < rates.size(); ++i) {
                const int m = static_cast<int>(i % p.n_per_axis), k = static_cast<int>(i / p.n_per_axis % p.n_dir);
                const int l = static_cast<int>(i / (p.n_per_axis * p.n_dir));
                csv.row(i, p.elevations.empty() ? 0.0 : p.elevations[l], k * two_pi / p.n_dir, m * p.spacing(),
                        rates[i]);
            }
            f.commit();
        }
    });
}

void add_config(CLI::App& app) {
    auto* cmd =
        app.add_subcommand("config", "Print a trial, model or sensor as YAML: every key, its value and meaning");
    struct Options {
        std::string trial, model, sensor;
    };
    auto o = std::make_shared<Options>();
    auto* trial =
        cmd->add_option("--trial", o->trial, "A trial YAML file, every key filled in (default: the default trial)");
    auto* model = add_model_option(*cmd, o->model, ModelCount::one);
    auto* sensor = add_sensor_option(*cmd, o->sensor);
    trial->excludes(model)->excludes(sensor);
    model->excludes(sensor);
    cmd->footer(
        "Without options: the default trial (the paper's protocol, cross arena, 3d-0.2, seed 0). Values are exact\n"
        "(shortest round-trip numbers): saved to a file and read back (bvc3d run --config FILE, --model FILE,\n"
        "--sensor FILE), the text gives the same trial, model or sensor, with the same results.");
    cmd->callback([o] {
        std::string text;
        if (!o->model.empty()) {
            text = config::model_to_commented_yaml(config::resolve_model(o->model));
        } else if (!o->sensor.empty()) {
            text = config::sensor_to_commented_yaml(config::resolve_sensor(o->sensor));
        } else {
            TrialConfig t;
            if (!o->trial.empty()) t = config::load_trial_file(o->trial);
            text = config::trial_to_commented_yaml(t);
        }
        std::fwrite(text.data(), 1, text.size(), stdout);
    });
}

}  // namespace

void add_model_commands(CLI::App& app) {
    add_bvc(app);
    add_config(app);
}

}  // namespace bvc3d::cli
