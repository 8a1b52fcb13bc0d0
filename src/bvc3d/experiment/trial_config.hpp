#pragma once
// What one trial is (SPEC §7): a world, a model, a protocol, a seed, and how to analyse it.
#include <cstdint>
#include <optional>
#include <string>

#include "bvc3d/analysis/trial_metrics.hpp"
#include "bvc3d/experiment/model_spec.hpp"
#include "bvc3d/robot/random_walk.hpp"

namespace bvc3d {

// A world by name: a preset (with tilt and lean for `cross`) or a YAML file.
struct WorldSpec {
    std::string source = "cross";
    std::optional<double> tilt_deg;
    std::string lean = "+x+y";

    WorldDescription resolve() const;
    // "cross-45", "two-rooms", ...: used in file names and tables.
    std::string label() const;
    // Text that changes whenever the world does (for a YAML file: its contents).
    std::string fingerprint() const;
};

struct Protocol {
    enum class Kind { explore_then_sample, online } kind = Kind::explore_then_sample;
    double explore_hours = 4.0;  // learning on, nothing recorded
    double sample_hours = 4.0;   // learning off, every step recorded (online: the one recorded phase)
    bool record_bvc = false;     // also record the BVC rates
    void validate() const;
};

struct TrialConfig {
    WorldSpec world;
    ModelSpec model;
    Protocol protocol;
    RobotParams robot;
    analysis::AnalysisParams analysis;  // SPEC §8 defaults; its extent is set from arena_extent
    bool arena_extent = false;          // bin over the walkable region's bounds, not the trajectory's
    std::uint64_t seed = 0;

    // The experimental condition this trial belongs to (its seeds are its replicates) and the
    // values that define it, e.g. {model: 3d-0.2, world: cross-45}. Labels only: they do not
    // change the results. Empty condition: "<world>_<model>".
    std::string condition;
    std::vector<std::pair<std::string, std::string>> swept;

    std::string condition_label() const;
    // Throws InputError for impossible values (model, protocol, robot, analysis, durations).
    void validate() const;
    std::string name() const;  // "<condition>_seed<N>", the trial file's stem
    // Everything that determines the walk (world, seed, protocol, robot), as text: trials with equal
    // keys can share one walk.
    std::string walk_key() const;
    // Everything that determines the trial's results, as text: equal text, equal results.
    std::string canonical() const;
    std::string fingerprint() const;  // a short hash of canonical()
};

std::string protocol_name(Protocol::Kind k);
Protocol::Kind parse_protocol(const std::string& name);

}  // namespace bvc3d
