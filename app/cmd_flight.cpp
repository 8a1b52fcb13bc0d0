// bvc3d flight: the flying agents' experiment (docs/flying.md), models × worlds × seeds.
#include <cstdio>
#include <memory>
#include <optional>
#include <string>
#include <utility>

#include "bvc3d/config/agent_kinds.hpp"
#include "bvc3d/config/model_yaml.hpp"
#include "bvc3d/config/protocols.hpp"
#include "bvc3d/core/error.hpp"
#include "cli_common.hpp"
#include "commands.hpp"
#include "run_options.hpp"

namespace bvc3d::cli {

namespace {

// The agent of the experiment: its kind says which protocol it runs.
const AgentKind& flying_kind() { return agent_kind("flight"); }

struct FlightOptions {
    std::string models = "fly-up,fly-5l,fly-9l", worlds = "flight-room,atrium,cross-60", protocol;
    int seeds = 1;
    std::optional<double> hours, explore_hours, sample_hours;
    RunOptions run{"results/flight"};
};

// Models × worlds × seeds, seeds slowest; the flying agent's protocol (docs/flying.md) unless shortened.
std::vector<TrialConfig> flight_trials(const FlightOptions& o) {
    for (const auto& [h, name] :
         {std::pair{o.hours, "--hours"}, {o.explore_hours, "--explore-hours"}, {o.sample_hours, "--sample-hours"}})
        if (h && !(*h > 0 || (*h == 0 && std::string(name) == "--explore-hours")))
            throw InputError(std::string(name) + " must be a positive number of hours");
    std::vector<ModelSpec> models;
    for (const auto& m : model_list(o.models, "--models")) models.push_back(config::resolve_model(m));
    const auto worlds = split_commas(o.worlds);
    if (worlds.empty()) throw InputError("--worlds lists no world");
    check_seed_count(o.seeds, {{models.size(), "models"}, {worlds.size(), "worlds"}});
    const auto agent = flying_kind().make_default();
    std::vector<TrialConfig> trials;
    for (int seed = 0; seed < o.seeds; ++seed)
        for (const auto& w : worlds)
            for (const auto& m : models) {
                TrialConfig t;
                t.world = WorldSpec{w, std::nullopt, "+x+y"};
                t.model = m;
                t.set_agent(agent);
                t.seed = static_cast<std::uint64_t>(seed);
                t.protocol = protocol_preset(flying_kind().protocol);
                if (!o.protocol.empty()) t.protocol.kind = parse_protocol(o.protocol);
                if (o.hours) t.protocol.explore_hours = t.protocol.sample_hours = *o.hours;
                if (o.explore_hours) t.protocol.explore_hours = *o.explore_hours;
                if (o.sample_hours) t.protocol.sample_hours = *o.sample_hours;
                trials.push_back(t);
            }
    for (const auto& w : worlds) agent->check_world(WorldSpec{w, std::nullopt, "+x+y"}.resolve());
    return trials;
}

}  // namespace

void add_flight_command(CLI::App& app) {
    auto* cmd = app.add_subcommand(
        "flight", "Run the flying agents' experiment: models x worlds x seeds, 3-D place fields, summary, figures");
    auto o = std::make_shared<FlightOptions>();
    o->run.add_experiment_options(*cmd);
    add_model_option(*cmd, o->models, ModelCount::list, "--models");
    cmd->add_option("--worlds", o->worlds, "Comma-separated worlds with a flight volume (presets or YAML files)")
        ->capture_default_str();
    cmd->add_option("--seeds", o->seeds, "Seeds per condition (0 .. N-1)")->capture_default_str();
    cmd->add_option("--hours", o->hours,
                    "Both phases this many simulated hours (default " +
                        protocol_hours_text(protocol_preset(flying_kind().protocol)) + ")");
    cmd->add_option("--explore-hours", o->explore_hours, "Simulated hours of exploration (learning on)");
    cmd->add_option("--sample-hours", o->sample_hours, "Simulated hours of sampling (recorded)");
    cmd->add_option("--protocol", o->protocol, "explore_then_sample (default) or online");
    cmd->footer(
        "The flying agent (a 0.2 m sphere on a 3-D random walk) in each world's flight volume; 3-D rate maps on\n"
        "0.5 m voxels, DBSCAN min_samples 10, field isotropy, horizontal and vertical decoding (docs/flying.md).\n"
        "Writes one HDF5 file per trial (format version 2), trials.csv, summary.csv, summary.md, and the figures\n"
        "and report.md. Completed trials are skipped on a rerun; Ctrl-C stops cleanly and can be resumed.");
    cmd->callback([o] {
        o->run.check();
        run_experiment_in_folder(flight_trials(*o), o->run);
        std::printf("summary: %s/summary.md%s\n", o->run.out.c_str(),
                    o->run.no_figures ? "" : (", report: " + o->run.out + "/report.md").c_str());
    });
}

}  // namespace bvc3d::cli
