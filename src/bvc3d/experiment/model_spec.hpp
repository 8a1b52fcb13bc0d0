#pragma once
// A whole model: which scanner it reads, its BVC layer and its place-cell network.
// The paper's four (Table I) and the authors'-code 2-D baseline are named presets (SPEC §5).
#include <string>
#include <vector>

#include "bvc3d/bvc/boundary_vector_layer.hpp"
#include "bvc3d/place/place_cell_network.hpp"
#include "bvc3d/sensor/lidar.hpp"

namespace bvc3d {

struct ModelSpec {
    std::string name;
    LidarSpec sensor;
    BvcParams bvc;
    PlaceParams place;
    void validate() const;
};

std::vector<std::string> model_preset_names();  // 2d, 3d-0.1, 3d-0.2, 3d-3l, 2d-8beam
ModelSpec model_preset(const std::string& name);  // throws InputError for unknown names

}  // namespace bvc3d
