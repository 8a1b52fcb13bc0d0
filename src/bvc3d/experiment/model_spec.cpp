#include "bvc3d/experiment/model_spec.hpp"

#include "bvc3d/core/error.hpp"

namespace bvc3d {

void ModelSpec::validate() const {
    sensor.validate();
    bvc.validate();
    place.validate();
}

std::vector<std::string> model_preset_names() { return {"2d", "3d-0.1", "3d-0.2", "3d-3l", "2d-8beam"}; }

ModelSpec model_preset(const std::string& name) {
    ModelSpec m;
    m.name = name;
    if (name == "2d" || name == "2d-8beam") {
        m.sensor = LidarSpec::horizontal();
        m.bvc.n_per_axis = 120;
        if (name == "2d-8beam") {
            // As the authors' code computed it: one beam per direction, d_m = 0.1·m (SPEC §5).
            m.bvc.reading = BvcReading::nearest_beam;
            m.bvc.max_dist = 11.9;
        }
    } else if (name == "3d-0.1" || name == "3d-0.2" || name == "3d-3l") {
        m.sensor = LidarSpec::spherical();
        if (name == "3d-0.1") m.bvc.elevations = {0.0, 0.1};
        if (name == "3d-0.2") m.bvc.elevations = {0.0, 0.2};
        if (name == "3d-3l") m.bvc.elevations = {0.0, 0.1, 0.2};
        m.bvc.n_per_axis = name == "3d-3l" ? 40 : 60;
    } else {
        std::string list;
        for (const auto& n : model_preset_names()) list += (list.empty() ? "" : ", ") + n;
        throw InputError("unknown model '" + name + "' (presets: " + list + "; or a model YAML file)");
    }
    return m;
}

}  // namespace bvc3d
