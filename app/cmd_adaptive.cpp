// bvc3d choose-elevations: the agent chooses its BVC layers' elevations from a short exploratory walk
// (docs/adaptive.md).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <optional>

#include "bvc3d/config/agent_kinds.hpp"
#include "bvc3d/config/model_yaml.hpp"
#include "bvc3d/config/world_yaml.hpp"
#include "bvc3d/core/atomic_file.hpp"
#include "bvc3d/core/error.hpp"
#include "bvc3d/core/format.hpp"
#include "bvc3d/experiment/elevation_chooser.hpp"
#include "cli_common.hpp"
#include "commands.hpp"
#include "option_groups.hpp"
#include "recording_options.hpp"
#include "table_options.hpp"

namespace bvc3d::cli {

namespace {

struct ChooseOptions {
    WorldOptions world;
    std::string sensor, agent, layers = "1-4", sets, out, scans, poses;
    TableOptions<ChooserParams> chooser{ChooserParams::table()};
    std::uint64_t seed = ChooserParams{}.seed;
    int jobs = 0;
    RecordingOptions recording;
    PreprocessOptions preprocess;
    Outputs outputs;
};

std::shared_ptr<const AgentSpec> named_agent(const std::string& name) {
    try {
        return agent_by_name(name);
    } catch (const InputError& e) {
        throw InputError(std::string("--agent: ") + e.what());
    }
}

// "2", "1-4": the fewest and most layers.
std::pair<int, int> parse_layers(const std::string& text) {
    const auto dash = text.find('-');
    const auto whole = [&](const std::string& s) {
        const double v = parse_number(s, "--layers");
        if (v != static_cast<int>(v) || v < 1)
            throw InputError("--layers: '" + text + "' is not N or MIN-MAX with whole numbers >= 1");
        return static_cast<int>(v);
    };
    if (dash == std::string::npos) return {whole(text), whole(text)};
    return {whole(text.substr(0, dash)), whole(text.substr(dash + 1))};
}

// "0,0.2;0,0.1,0.2": elevation sets, each sorted.
std::vector<std::vector<double>> parse_sets(const std::string& text) {
    std::vector<std::vector<double>> sets(1);
    std::string item;
    const auto flush = [&] {
        if (!item.empty()) sets.back().push_back(parse_number(item, "--sets"));
        item.clear();
    };
    for (char ch : text) {
        if (ch == ',' || ch == ';') flush();
        if (ch == ';') sets.emplace_back();
        if (ch != ',' && ch != ';') item += ch;
    }
    flush();
    for (auto& s : sets) {
        if (s.empty()) throw InputError("--sets: '" + text + "' has an empty set (give sets as 0,0.2;0,0.1,0.2)");
        std::sort(s.begin(), s.end());
    }
    return sets;
}

// Where the chooser's walk and scans come from: an agent exploring a world, or a recording.
struct Exploration {
    std::shared_ptr<const AgentSpec> agent;
    std::optional<ReplaySource> recorded;
    std::string text;  // for the model file's comment
};

Exploration exploration_of(const ChooseOptions& o) {
    if (o.scans.empty() && o.poses.empty() && !o.recording.has_bag()) {
        const auto agent = named_agent(o.agent.empty() ? "ground" : o.agent);
        const WorldSpec world = o.world.spec();
        return {agent, std::nullopt,
                "world " + world.source +
                    (world.tilt_deg ? " tilt " + format_number(*world.tilt_deg) + " lean " + world.lean : "") +
                    ", agent " + (o.agent.empty() ? "ground" : o.agent)};
    }
    if (o.scans.empty() && !o.recording.has_bag()) throw InputError("--poses needs --scans");
    if (o.world.given() || !o.agent.empty())
        throw InputError(
            "a recording is its own walk: give --scans and --poses (or --bag), or --world (and --agent), not both");
    const ReplaySource source = recorded_source(o.recording.open_any(o.scans, o.poses), o.preprocess.get());
    return {std::make_shared<RandomWalkSpec>(), source,
            "recording " + (o.scans.empty() ? o.recording.bag : o.scans) + " (" +
                std::to_string(source.path->steps().size()) + " scans)"};
}

void choose(const ChooseOptions& o) {
    const Exploration exploration = exploration_of(o);
    const auto& agent = exploration.agent;
    const ChooserDefaults defaults = chooser_defaults(*agent);
    check_jobs(o.jobs);
    ChooserParams p;
    o.chooser.apply(p);
    p.seed = o.seed;
    p.jobs = o.jobs;
    std::tie(p.min_layers, p.max_layers) = parse_layers(o.layers);
    if (!o.chooser.given("elevation_min") && defaults.symmetric_range) p.elevation_min = -p.elevation_max;
    ModelSpec base = model_preset(defaults.model);
    const std::string sensor = o.sensor.empty() ? defaults.sensor : o.sensor;
    base.sensor = config::resolve_sensor(sensor);
    p.validate(base.bvc.n_dir);
    if (o.out.empty()) throw InputError("--out: give the model YAML file to write");
    o.outputs.check();
    // Fail before minutes of work, not after.
    const auto folder = std::filesystem::path(o.out).parent_path();
    const EmptyFolderCleanup cleanup{folder, folder.empty() ? folder : ensure_writable_directory(folder)};
    const auto analysis = analysis::AnalysisParams::defaults(agent->dims());
    const auto sets = o.sets.empty() ? std::vector<std::vector<double>>{} : parse_sets(o.sets);
    InterruptGuard guard;
    p.stop = &stop_flag();
    ElevationChoice c;
    try {
        if (exploration.recorded) {
            std::printf("replaying %s twice per candidate (seed %llu); candidate elevations %s rad\n",
                        exploration.text.c_str(), static_cast<unsigned long long>(p.seed),
                        elevations_text(p.candidate_elevations()).c_str());
            c = choose_elevations_on(*exploration.recorded, base, p, analysis, sets);
        } else {
            const World world(o.world.resolve());
            agent->check_world(world.description());
            std::printf("exploring %s for %s simulated minutes (seed %llu); candidate elevations %s rad\n",
                        o.world.spec().source.c_str(), format_number(p.explore_minutes).c_str(),
                        static_cast<unsigned long long>(p.seed), elevations_text(p.candidate_elevations()).c_str());
            c = sets.empty() ? choose_elevations(world, base, *agent, p, analysis)
                             : choose_from_sets(world, base, *agent, sets, p, analysis);
        }
    } catch (const Interrupted&) {
        std::fprintf(stderr, "\nbvc3d: interrupted; nothing was written.\n");
        std::exit(130);
    }
    std::printf("%zu walk steps; criterion = MSAI of the network on the walk (lower is better)\n", c.walk_steps);
    std::printf("%5s  %-28s %10s %8s %10s %9s\n", "round", "elevations (rad)", "n_per_axis", "MSAI", "MI>1 frac",
                "BVC MSAI");
    for (const auto& s : c.candidates)
        std::printf("%5d  %-28s %10d %8.4f %10.3f %9.4f\n", s.round, elevations_text(s.elevations).c_str(),
                    s.n_per_axis, s.msai, s.frac_multimodal, s.bvc_msai);
    std::printf("chosen: %s rad, %d per axis (MSAI %.4f)\n", elevations_text(c.chosen.elevations).c_str(),
                c.chosen.n_per_axis, c.chosen.msai);
    AtomicFile file(o.out);
    file.stream() << "# chosen by bvc3d choose-elevations: " << exploration.text << ", sensor " << sensor << ", "
                  << (exploration.recorded ? std::string("recorded walk")
                                           : format_number(p.explore_minutes) + " min walk")
                  << ", seed " << p.seed << ", budget " << p.budget
                  << "\n# criterion (MSAI of the network on the walk): " << format_number(c.chosen.msai) << "\n"
                  << config::model_to_yaml(c.model);
    file.commit();
    std::printf("wrote %s\n", o.out.c_str());
}

}  // namespace

void add_adaptive_command(CLI::App& app) {
    auto o = std::make_shared<ChooseOptions>();
    auto* cmd = app.add_subcommand(
        "choose-elevations", "Choose the BVC layers' elevations from a short exploratory walk; write the model YAML");
    o->world.add_to(*cmd);
    auto* sensor = add_sensor_option(*cmd, o->sensor);
    sensor->description(sensor->get_description() + " [spherical on the ground, spherical-full when flying]");
    const std::string who = "; default ground (a flying agent's world needs a flight volume)";
    cmd->add_option("--agent", o->agent, "Who explores: " + agent_names_text() + who);
    cmd->add_option("--scans", o->scans,
                    "Instead of a world: a recording's scans (folder, list or file); its poses are the walk, its scans "
                    "the returns");
    cmd->add_option("--poses", o->poses, "With --scans: the recording's pose file (KITTI, TUM or 4x4 rows)");
    o->recording.add_to(*cmd);
    o->preprocess.add_to(*cmd);
    static const ChooserParams defaults;
    o->chooser.add_to(*cmd, {"budget"}, &defaults);
    cmd->add_option("--layers", o->layers, "Number of layers: N or MIN-MAX")->capture_default_str();
    auto* lowest = o->chooser.add_to(*cmd, {"elevation_min"}, nullptr, {{"elevation_min", "--min-elevation"}}).front();
    lowest->description(lowest->get_description() + " [0 on the ground, -(--max-elevation) when flying]");
    o->chooser.add_to(*cmd, {"elevation_max", "elevation_step", "explore_minutes"}, &defaults,
                      {{"elevation_max", "--max-elevation"}});
    cmd->add_option("--seed", o->seed, "Seed of the exploratory walk")->check(seed_check)->capture_default_str();
    cmd->add_option("--sets", o->sets, "Score these elevation sets instead of searching, e.g. '0,0.2;0,0.1,0.2' (rad)");
    add_jobs_option(*cmd, o->jobs, "Candidates");
    o->outputs.add(*cmd, "--out", o->out, OutputKind::file, "Model YAML file to write")->required();
    cmd->callback([o] { choose(*o); });
}

}  // namespace bvc3d::cli
