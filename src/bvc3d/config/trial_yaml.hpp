#pragma once
// YAML <-> trial configurations. Schema in docs/experiments.md. A sweep edits keys of this tree
// (e.g. model.bvc.elevations) and parses it again, so every value meets the same checks.
#include <string>

#include "bvc3d/config/trial_config.hpp"
#include "bvc3d/config/yaml_reader.hpp"

namespace bvc3d::config {

// world: preset name / YAML path, or {source, tilt_deg, lean}; model: preset name / YAML path, or a
// model mapping; seed; protocol: {kind, explore_hours, sample_hours, record_bvc}; the agent — robot:
// {...} for the random walk (default), or trajectory: FILE; analysis: {gridsize, quantile, eps,
// min_samples, d_th, decoding_templates, extent: data | arena}.
TrialConfig trial_from_yaml(const YamlView& v);
TrialConfig load_trial_file(const std::string& path);

// What `bvc3d config` prints: the trial as YAML with every key and its description, which
// trial_from_yaml reads back to the same trial (equal canonical text; the condition label aside).
// The model is named when it is a preset exactly, else written out; files are absolute paths.
std::string trial_to_commented_yaml(const TrialConfig& t);

// The trial keys trial_from_yaml accepts at the top level.
std::vector<std::string> trial_keys();

}  // namespace bvc3d::config
