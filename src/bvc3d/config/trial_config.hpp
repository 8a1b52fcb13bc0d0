#pragma once
// Config stage: what one trial is (docs/experiments.md) — a world, a model, an agent, a protocol, a
// seed, and how to analyze it — as plain data with its canonical text and fingerprint. A replay of a
// recording (docs/recordings.md) is a trial with no world, the recording's path as its agent and
// its scans as the returns.
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>

#include "bvc3d/agent/agent.hpp"
#include "bvc3d/agent/random_walk.hpp"
#include "bvc3d/analysis/trial_metrics.hpp"
#include "bvc3d/config/building.hpp"
#include "bvc3d/config/model_spec.hpp"
#include "bvc3d/config/returns_spec.hpp"
#include "bvc3d/core/params.hpp"

namespace bvc3d {

// A world by name: a preset (with tilt and lean for `cross`), a YAML file or a Gazebo world file (with
// what becomes of its missing models); or none (an empty source: a replay of recorded data).
struct WorldSpec {
    std::string source = "cross";
    std::optional<double> tilt_deg;
    std::string lean = "+x+y";
    config::MissingModels missing_models = config::MissingModels::error;

    // A world built in code (a Python World): its name labels it; it cannot be found again from the spec.
    bool in_memory = false;

    static WorldSpec none() { return WorldSpec{"", std::nullopt, "+x+y"}; }
    static WorldSpec built(const std::string& name) {
        return WorldSpec{name, std::nullopt, "+x+y", config::MissingModels::error, true};
    }
    bool is_none() const { return source.empty(); }
    WorldDescription resolve() const;  // InputError for none
    // "cross-45", "two-rooms", ...: used in file names and tables.
    std::string label() const;
    // Text that changes whenever the world does (for a YAML file: its contents).
    std::string fingerprint() const;
};

struct Protocol {
    // learn: learning on until explore_hours or the agent's end (navigation's learning walk), nothing recorded
    enum class Kind { explore_then_sample, online, learn } kind = Kind::explore_then_sample;
    double explore_hours = 4.0;  // learning on, nothing recorded
    double sample_hours = 4.0;   // learning off, every step recorded (online: the one recorded phase)
    bool record_bvc = false;     // also record the BVC rates

    static const params::Table<Protocol>& table();
    void validate() const;
    double seconds() const;  // agent time the protocol runs
    bool records() const { return kind != Kind::learn; }
};

// Place-cell weights to start from (a trained network, e.g. from a trial file) instead of the
// seed's Bernoulli draw.
struct InitialWeights {
    std::string source;         // where they came from (a file name), for trial files
    std::vector<float> values;  // n_place × n_bvc, row-major
    int n_place = 0, n_bvc = 0;
    // The model that trained them (name, canonical text) when known: a model whose BVCs differ is
    // refused (TrialConfig::validate), even when the shapes agree.
    std::string model, model_config;
    std::string key() const;  // the source and a hash of the values
};

// The trained weights of a trial file with the model that trained them (InputError naming the file).
std::shared_ptr<const InitialWeights> weights_from_trial_file(const std::filesystem::path& path);
// Why weights trained by a model of canonical text `trained` cannot be loaded into `model`: the first
// BVC key that differs (the BVCs are what the weights' columns mean), or "" when they agree. The
// sensor and the place cells' dynamics may differ (a trained network on a real sensor's scans).
std::string weights_model_mismatch(const std::string& trained, const ModelSpec& model);

struct NavigationSpec;  // config/navigation_spec.hpp

struct TrialConfig {
    WorldSpec world;
    ModelSpec model = model_preset("3d-0.2");
    Protocol protocol;
    std::shared_ptr<const AgentSpec> agent = std::make_shared<RandomWalkSpec>();  // where the agent goes
    std::shared_ptr<const ReturnsSpec> returns;     // null: each model's sensor ray-cast in the world
    std::shared_ptr<const InitialWeights> weights;  // null: drawn from the seed
    analysis::AnalysisParams analysis;              // defaults as the paper; its extent is set from arena_extent
    bool arena_extent = false;                      // bin over the walkable region's bounds, not the trajectory's
    std::uint64_t seed = 0;
    // A navigation trial (config/navigation_spec.hpp): after its learning run, episodes to goals. Null for others.
    std::shared_ptr<const NavigationSpec> navigation;

    // The experimental condition this trial belongs to (its seeds are its replicates) and the
    // values that define it, e.g. {model: 3d-0.2, world: cross-45}. Labels only: they do not
    // change the results. Empty condition: "<world>_<model>".
    std::string condition;
    std::vector<std::pair<std::string, std::string>> swept;
    // Where the trial was described ("trial.yaml", "sweep.yaml, condition 3"), for messages; a label.
    std::string origin;

    // Sets the agent; when that changes the positions' dimension, a min_samples left at the old
    // dimension's default takes the new one's (20 in 2-D, 10 in 3-D).
    void set_agent(std::shared_ptr<const AgentSpec> a);
    std::string condition_label() const;
    // The world's label, or for a trial without one the label of its returns (the recording).
    std::string world_label() const;
    // Throws InputError for impossible values (model, protocol, agent, analysis, durations).
    void validate() const;
    // validate(), and what needs the world: it resolves (files exist, geometry sound) and the agent
    // can run in it (room for the robot at the start points; a trajectory inside it).
    void check_runnable() const;
    std::string name() const;  // "<condition>_seed<N>", the trial file's stem
    // Everything that determines the agent's steps (world, seed, protocol, agent), as text: trials
    // with equal keys can share one agent.
    std::string walk_key() const;
    // Everything that determines the trial's results, as text: equal text, equal results.
    // The place cells never learn and start from the seed's random draw (a frozen replay without
    // weights, `explore_hours 0` without weights): their metrics would mean nothing (not written).
    bool place_cells_untrained() const;
    // "learned", "trained" or "untrained" (TrialIdentity::place_weights).
    std::string place_weights() const;
    std::string canonical() const;
    std::string fingerprint() const;  // a short hash of canonical()
    // The trial's analysis parameters, with the walkable region's bounds as the extent when
    // arena_extent asks for them, and for a 3-D agent the flight volume as the voxels' box.
    analysis::AnalysisParams analysis_params(const WorldDescription& world) const;
};

// check_runnable() for many trials, once per distinct world and agent.
void check_runnable(const std::vector<TrialConfig>& trials);

std::string protocol_name(Protocol::Kind k);
Protocol::Kind parse_protocol(const std::string& name);

}  // namespace bvc3d
