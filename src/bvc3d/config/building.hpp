#pragma once
// Config stage: a Gazebo building as an ordinary world (docs/buildings.md).
// Takes: an SDF world file and how to read it (model path, visual or collision geometry, the floor).
// Gives: a WorldDescription whose chosen floor is at z = 0 (the rest of bvc3d needs nothing else):
// its triangles and spheres, the edges where that floor ends, the walkable region (the floor's
// extent: walls and drop edges keep the body in the part it reaches from its start), the start
// region and, if asked, a flight volume inside the storey.
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "bvc3d/config/yaml_reader.hpp"
#include "bvc3d/world/floors.hpp"
#include "bvc3d/world/gazebo_world.hpp"
#include "bvc3d/world/world.hpp"

namespace bvc3d::config {

// A flight volume chosen from the storey: the floor's extent × [floor + clearance, ceiling −
// clearance], the ceiling being the median height of the first geometry above the floor's cells.
struct StoreyFlight {
    double clearance = 0.2;  // m
};

// What becomes of a Gazebo world's included models that are not found on the model path: the world is
// refused (error, the default) or built without them (skip; WorldDescription::left_out names them).
// The values of a world YAML's `missing_models:` and of the program's --missing-models.
enum class MissingModels { error, skip };
const std::vector<std::string>& missing_models_names();  // "error", "skip": in the enum's order
// InputError "must be 'error' or 'skip', got '...'" for other text.
MissingModels parse_missing_models(const std::string& text);

struct BuildingSpec {
    std::string file;  // a .world or .sdf file
    std::string name;  // default: the world's name in the file
    GazeboOptions gazebo;
    // m in the file's frame: the floor nearest this height; none: the lowest floor with at least a
    // quarter of the largest one's horizontal area (not a pit, a platform or a step)
    std::optional<double> floor_z;
    std::optional<StoreyFlight> flight;
    double step_height = 0.02;  // m: the ground robot passes over lower things (a carpet, a door sill)
};

// Reads the file and builds the world (InputError naming the file and element, or the floor).
WorldDescription building_world(const BuildingSpec& spec);

// The floors of a building file (their heights in the file's frame, lowest first), as
// building_world() chooses among them: horizontal geometry with at least 0.5 m of room above it;
// Gazebo's ground plane is a floor only when there is no other.
std::vector<FloorLevel> building_floors(const GazeboScene& scene);

// A world YAML with an `sdf` key (docs/buildings.md#world-yaml): sdf, model_path, resource_path, geometry,
// missing_models, collada_up_axis, floor_z, step_height, name, start, flight_volume.
WorldDescription building_from_yaml(const YamlView& v);
// The files such a YAML's world depends on (for fingerprints): see gazebo_world_files().
std::vector<std::string> building_yaml_files(const YamlView& v);

}  // namespace bvc3d::config
