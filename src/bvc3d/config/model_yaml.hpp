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

}  // namespace bvc3d::config
