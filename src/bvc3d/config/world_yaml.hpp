#pragma once
// YAML <-> worlds and sensors. The schemas are documented in docs/worlds.md.
#include <optional>
#include <string>

#include "bvc3d/config/building.hpp"
#include "bvc3d/config/yaml_reader.hpp"
#include "bvc3d/sensor/lidar.hpp"
#include "bvc3d/world/world.hpp"

namespace bvc3d::config {

// The names `--world` accepts besides a YAML file.
std::vector<std::string> world_preset_names();
// True for the presets that take a tilt (`cross`, `cross-webots`); the others fix their own.
bool world_preset_takes_tilt(const std::string& name);

WorldDescription world_from_yaml(const YamlView& v);
WorldDescription load_world_file(const std::string& path);
// The geometry files (meshes, point clouds) a world file refers to (paths as opened), for fingerprints.
std::vector<std::string> world_file_meshes(const std::string& path);

// A preset name ("cross", "cross-30", "cross-webots", ...), a YAML file or a Gazebo world file (.world,
// .sdf). `tilt_deg` sets the tilt of the presets that take one and is an error for anything else;
// `missing` says what becomes of a Gazebo file's models that are not found (skip is an error for
// anything but a Gazebo file: a world YAML says it with its own `missing_models` key).
WorldDescription resolve_world(const std::string& name_or_file, std::optional<double> tilt_deg = std::nullopt,
                               const std::string& lean = "+x+y", MissingModels missing = MissingModels::error);

// Sensors: "horizontal", "spherical", or a YAML mapping / file describing a beam table (keys from
// LidarSpec's table, plus `preset` and `keep_rows`).
LidarSpec sensor_from_yaml(const YamlView& v);
LidarSpec resolve_sensor(const std::string& name_or_file);
// The names `--sensor` accepts besides a YAML file: the paper's scanners ("horizontal", "spherical",
// ...), then the real LiDAR models (sensor/lidar_models.hpp). One list, which help texts and errors read.
std::vector<std::string> sensor_preset_names();

// The name of the built-in sensor `s` is exactly ("horizontal", "spherical"), or "".
std::string builtin_sensor_name(const LidarSpec& s);
// Every key of a sensor mapping at `indent`, with descriptions; sensor_from_yaml reads it back to `s`.
void write_sensor(params::CommentedYaml& out, const LidarSpec& s, const std::string& indent);
// What `bvc3d config --sensor` prints: a sensor file with every key.
std::string sensor_to_commented_yaml(const LidarSpec& s);

}  // namespace bvc3d::config
