#pragma once
// YAML <-> models (sensor + BVC layer + place cells). Schema in docs/model.md; every key, default
// and check comes from the parameter structs' tables.
#include <string>

#include "bvc3d/config/model_spec.hpp"
#include "bvc3d/config/yaml_reader.hpp"

namespace bvc3d::config {

ModelSpec model_from_yaml(const YamlView& v);
// A preset name or a model YAML file.
ModelSpec resolve_model(const std::string& name_or_file);
// The YAML text that model_from_yaml reads back to the same model (stored in trial files).
std::string model_to_yaml(const ModelSpec& m);
// Every key of a model mapping at `indent`, with descriptions (the sensor by name when it is a built-in
// one exactly); model_from_yaml reads it back to `m` (equal model_to_yaml).
void write_model(params::CommentedYaml& out, const ModelSpec& m, const std::string& indent);
// What `bvc3d config --model` prints: a model file with every key.
std::string model_to_commented_yaml(const ModelSpec& m);
// The preset `m` is exactly (same model_to_yaml), or "".
std::string preset_name_of(const ModelSpec& m);

}  // namespace bvc3d::config
