#include "bvc3d/config/authors.hpp"

#include <algorithm>

#include "bvc3d/config/model_yaml.hpp"
#include "bvc3d/config/world_yaml.hpp"
#include "bvc3d/core/error.hpp"

namespace bvc3d {

namespace {

// The robot of a random-walk trial (InputError for a trial that follows a given path).
RobotParams robot_of(const TrialConfig& t, const std::string& choice) {
    const auto* walk = dynamic_cast<const RandomWalkSpec*>(t.agent.get());
    if (!walk)
        throw InputError("the authors' '" + choice + "' choice applies to the random walk, not to a given trajectory");
    return walk->robot();
}

// A model that is exactly the preset `from` becomes the preset `to`; any other model is left alone.
void replace_preset(ModelSpec& m, const std::string& from, const std::string& to) {
    if (config::preset_name_of(m) == from) m = model_preset(to);
}

}  // namespace

const std::vector<AuthorsChoice>& authors_choices() {
    static const std::vector<AuthorsChoice> choices{
        {"protocol", "one recorded 4-hour phase with learning on (protocol online)",
         [](TrialConfig& t) {
             t.protocol.kind = Protocol::Kind::online;
             t.protocol.sample_hours = 4.0;
         }},
        {"reading", "the 2-D model reads the single nearest beam per direction (2d becomes 2d-8beam)",
         [](TrialConfig& t) { replace_preset(t.model, "2d", "2d-8beam"); }},
        {"geometry", "the arena as built in Webots (world cross becomes cross-webots, same tilt and lean)",
         [](TrialConfig& t) {
             if (t.world.source == "cross") t.world.source = "cross-webots";
         }},
        {"robot",
         "radius 0.17 m, turns at 1.83 rad/s in 96 ms control steps, the Gaussian turn after a bump too, "
         "start heading east",
         [](TrialConfig& t) {
             RobotParams r = RobotParams::authors();
             r.log_lag = robot_of(t, "robot").log_lag;  // the lag is a choice of its own
             t.agent = std::make_shared<RandomWalkSpec>(r);
         }},
        {"labels", "the spherical image's angle labels and whole-column heading roll (3d-X becomes 3d-X-authors)",
         [](TrialConfig& t) {
             for (const char* m : {"3d-0.1", "3d-0.2", "3d-3l"})
                 replace_preset(t.model, m, std::string(m) + "-authors");
         }},
        {"lag", "each sample's position logged two 96 ms control steps after its scan (≈0.1 m)",
         [](TrialConfig& t) {
             RobotParams r = robot_of(t, "lag");
             r.log_lag = RobotParams::authors_log_lag;
             t.agent = std::make_shared<RandomWalkSpec>(r);
         }},
        {"analysis", "modality at the 20 % quantile, the first sample dropped, MSAI over a fixed 2662²",
         [](TrialConfig& t) {
             const analysis::AnalysisParams a = analysis::AnalysisParams::authors();
             t.analysis.mi_quantile = a.mi_quantile;
             t.analysis.skip_samples = a.skip_samples;
             t.analysis.msai_bins = a.msai_bins;
         }},
    };
    return choices;
}

std::vector<std::string> authors_choice_names() {
    std::vector<std::string> names;
    for (const auto& c : authors_choices()) names.push_back(c.name);
    return names;
}

void apply_authors_choices(TrialConfig& t, const std::vector<std::string>& names) {
    const bool all = std::find(names.begin(), names.end(), "all") != names.end();
    for (const auto& name : names) {
        if (name == "all") continue;
        const auto& list = authors_choices();
        if (std::none_of(list.begin(), list.end(), [&](const AuthorsChoice& c) { return c.name == name; })) {
            std::string known;
            for (const auto& n : authors_choice_names()) known += n + ", ";
            throw InputError("unknown authors' choice '" + name + "' (choices: " + known + "all)");
        }
    }
    // In the table's order, whatever the order given.
    for (const auto& c : authors_choices())
        if (all || std::find(names.begin(), names.end(), c.name) != names.end()) c.apply(t);
}

const std::vector<PaperPreset>& paper_presets() {
    static const std::vector<PaperPreset> presets{
        {"spec",
         "the paper as specified: cross arena, explore then sample, the paper's robot, sensor and analysis",
         {}},
        {"authors",
         "the authors' published code: every authors' choice (" +
             [] {
                 std::string s;
                 for (const auto& n : authors_choice_names()) s += (s.empty() ? "" : ", ") + n;
                 return s;
             }() +
             ")",
         {"all"}},
    };
    return presets;
}

const PaperPreset& paper_preset(const std::string& name) {
    for (const auto& p : paper_presets())
        if (p.name == name) return p;
    std::string list;
    for (const auto& p : paper_presets()) list += (list.empty() ? "" : ", ") + p.name;
    throw InputError("unknown paper preset '" + name + "' (presets: " + list + ")");
}

}  // namespace bvc3d
