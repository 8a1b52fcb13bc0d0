#include "bvc3d/config/model_spec.hpp"

#include <numbers>

#include "bvc3d/config/population_kinds.hpp"
#include "bvc3d/core/error.hpp"
#include "bvc3d/core/format.hpp"

namespace bvc3d {

void ModelSpec::validate() const {
    sensor.validate();
    bvc.validate();
    place.validate();
    const double weights = static_cast<double>(place.n_place) * bvc.n_cells();
    if (weights > max_weights)
        PlaceParams::table().fail("n_place", "makes " + std::to_string(place.n_place) + " place cells × " +
                                                 std::to_string(bvc.n_cells()) + " BVCs = " + format_number(weights) +
                                                 " weights; the limit is " + format_number(max_weights));
    if (place.grid_influence > 0 && place_grid.empty())
        PlaceParams::table().fail("grid_influence", "is " + std::to_string(place.grid_influence) +
                                                        " but the place cells read no grid cells (place_grid)");
}

std::vector<std::string> ModelSpec::place_scales() const {
    std::vector<std::string> names{"place"};
    for (const PopulationSpec& spec : populations)
        if (spec.kind == "place") names.push_back(spec.name);
    return names;
}

namespace {

// A model reading the horizontal scanner (no elevation layers), 120 distances per direction.
ModelSpec planar(const std::string& name) {
    ModelSpec m{name, LidarSpec::horizontal(), {}, {}, {}, {}};
    m.bvc.elevations.clear();
    m.bvc.n_per_axis = 120;
    return m;
}

// A model reading the spherical scanner's upper half with the given layers.
ModelSpec layered(const std::string& name, std::vector<double> elevations, int n_per_axis) {
    ModelSpec m{name, LidarSpec::spherical(), {}, {}, {}, {}};
    m.bvc.elevations = std::move(elevations);
    m.bvc.n_per_axis = n_per_axis;
    return m;
}

// A flying agent's model: the full spherical scanner (both halves) at the body's center.
ModelSpec flying(const std::string& name, std::vector<double> elevations, int n_per_axis) {
    ModelSpec m{name, LidarSpec::spherical_full(), {}, {}, {}, {}};
    m.bvc.elevations = std::move(elevations);
    m.bvc.n_per_axis = n_per_axis;
    return m;
}

// The same model reading the spherical image with the authors' angle labels.
ModelSpec as_authors(ModelSpec m) {
    m.sensor = LidarSpec::spherical_as_authors();
    return m;
}

// The authors' multiscale model (SPEC §16): three scales, each a BVC layer, a grid module and place cells fed by
// both; the first scale is the model's own "bvc" and "place", the others populations, with head-direction cells.
// `elevations`: none for the horizontal scanner, else the paper's layers on the spherical one.
ModelSpec multiscale(const std::string& name, const std::vector<double>& elevations) {
    struct Scale {
        const char* tag;
        double sigma_r, sigma_theta_deg;
        int n_per_axis;
        double grid_spacing;
        int n_grid, n_place;
        double g, mask_p, gamma_pp, gamma_pb;
    };
    static constexpr Scale scales[] = {{"s", 0.5, 1, 100, 4.0, 800, 2000, 0.30, 0.3, 1.0, 0.35},
                                       {"m", 1.0, 3, 50, 5.5, 400, 1000, 0.35, 0.3, 0.7, 0.35},
                                       {"l", 1.5, 5, 75, 7.0, 400, 500, 0.35, 0.2, 0.7, 0.25}};
    ModelSpec m{name, elevations.empty() ? LidarSpec::horizontal() : LidarSpec::spherical(), {}, {}, {}, {}};
    m.populations.push_back(config::head_direction_spec("hd", HeadDirectionParams{}));
    for (const Scale& sc : scales) {
        const std::string tag = sc.tag;
        BvcParams bvc;
        bvc.elevations = elevations;
        bvc.max_dist = 25.0;
        bvc.n_per_axis = sc.n_per_axis;
        bvc.sigma_r = sc.sigma_r;
        bvc.sigma_theta = sc.sigma_theta_deg * std::numbers::pi / 180.0;
        PlaceParams place;
        place.n_place = sc.n_place;
        place.grid_influence = sc.g;
        place.grid_p_connect = sc.mask_p;
        place.gamma_pp = sc.gamma_pp;
        place.gamma_pb = place.gamma_pg = sc.gamma_pb;
        GridParams grid;
        grid.spacing = sc.grid_spacing;
        grid.n = sc.n_grid;
        PopulationSpec grid_cells = config::grid_spec("grid-" + tag, grid);
        grid_cells.recorded = false;  // 1 600 rates a step: kept only when asked (recorded: true in YAML)
        m.populations.push_back(std::move(grid_cells));
        if (tag == "s") {
            m.bvc = bvc;
            m.place = place;
            m.place_grid = "grid-s";
            continue;
        }
        m.populations.push_back(config::bvc_layer_spec("bvc-" + tag, bvc));
        m.populations.push_back(config::grid_place_spec("place-" + tag, place, {"bvc-" + tag, "grid-" + tag}));
    }
    return m;
}

}  // namespace

const std::vector<ModelPreset>& model_presets() {
    static const std::vector<ModelPreset> presets{
        {"2d", "the paper's 2-D model: horizontal scanner, 8 directions × 120 distances", [] { return planar("2d"); }},
        {"3d-0.1", "spherical scanner, layers 0 and 0.1 rad × 8 directions × 60 distances",
         [] {
             return layered("3d-0.1", {0.0, 0.1}, 60);
         }},
        {"3d-0.2", "spherical scanner, layers 0 and 0.2 rad × 8 directions × 60 distances",
         [] {
             return layered("3d-0.2", {0.0, 0.2}, 60);
         }},
        {"3d-3l", "spherical scanner, layers 0, 0.1 and 0.2 rad × 8 directions × 40 distances",
         [] {
             return layered("3d-3l", {0.0, 0.1, 0.2}, 40);
         }},
        {"2d-8beam",
         "the 2-D model as the authors' code computed it: the single nearest beam per direction, d_m = 0.1·m",
         [] {
             ModelSpec m = planar("2d-8beam");
             m.bvc.reading = BvcReading::nearest_beam;
             m.bvc.max_dist = 11.9;
             return m;
         }},
        // The 3-D models reading the spherical image as the authors' code labels it.
        {"3d-0.1-authors", "3d-0.1 with the authors' image labels and whole-column heading roll",
         [] {
             return as_authors(layered("3d-0.1-authors", {0.0, 0.1}, 60));
         }},
        {"3d-0.2-authors", "3d-0.2 with the authors' image labels and whole-column heading roll",
         [] {
             return as_authors(layered("3d-0.2-authors", {0.0, 0.2}, 60));
         }},
        {"3d-3l-authors", "3d-3l with the authors' image labels and whole-column heading roll",
         [] {
             return as_authors(layered("3d-3l-authors", {0.0, 0.1, 0.2}, 40));
         }},
        // The authors' multiscale model (docs/model-reference.md#multiscale-models).
        {"ms-2d",
         "multiscale, horizontal scanner: 3 scales of BVCs (σ_r 0.5/1/1.5 m), grid modules (4/5.5/7 m) and place "
         "cells (2000/1000/500, fed by both), HD cells",
         [] { return multiscale("ms-2d", {}); }},
        {"ms-3d", "ms-2d on the spherical scanner, each scale's BVCs in layers 0, 0.1 and 0.2 rad",
         [] {
             return multiscale("ms-3d", {0.0, 0.1, 0.2});
         }},
        {"fly-up", "flying: full spherical scanner at the body's center, layers 0, 0.1, 0.2 rad (upward only) × 8 × 40",
         [] {
             return flying("fly-up", {0.0, 0.1, 0.2}, 40);
         },
         true},
        {"fly-5l", "flying: full spherical scanner, layers -0.4, -0.2, 0, 0.2, 0.4 rad × 8 directions × 24 distances",
         [] {
             return flying("fly-5l", {-0.4, -0.2, 0.0, 0.2, 0.4}, 24);
         },
         true},
        {"fly-9l", "flying: full spherical scanner, layers -0.8 to 0.8 rad in steps of 0.2 × 8 × 13 (936 cells)",
         [] {
             return flying("fly-9l", {-0.8, -0.6, -0.4, -0.2, 0.0, 0.2, 0.4, 0.6, 0.8}, 13);
         },
         true},
    };
    return presets;
}

std::vector<std::string> model_preset_names() {
    std::vector<std::string> names;
    for (const auto& p : model_presets()) names.push_back(p.name);
    return names;
}

const ModelPreset* find_model_preset(const std::string& name) {
    for (const auto& p : model_presets())
        if (p.name == name) return &p;
    return nullptr;
}

ModelSpec model_preset(const std::string& name) {
    if (const auto* p = find_model_preset(name)) return p->make();
    std::string list;
    for (const auto& n : model_preset_names()) list += (list.empty() ? "" : ", ") + n;
    throw InputError("unknown model '" + name + "' (presets: " + list + "; or a model YAML file)");
}

}  // namespace bvc3d
