#include "bvc3d/config/model_yaml.hpp"

#include <algorithm>
#include <filesystem>

#include "bvc3d/config/population_kinds.hpp"
#include "bvc3d/config/world_yaml.hpp"

namespace bvc3d::config {

ModelSpec model_from_yaml(const YamlView& v) {
    v.expect_map({"name", "base", "sensor", "bvc", "place", "populations", "place_grid"});
    ModelSpec m;
    try {
        m = model_preset(v.get("base", "3d-0.2"));
    } catch (const InputError& e) {
        v["base"].fail(e.what());
    }
    // Unnamed: a model file is named after the file; an inline model after its base, marked as
    // changed when it changes anything.
    const std::string base_name = m.name;
    const bool inline_model = !v.path().empty();
    const bool changed =
        v.has("sensor") || v.has("bvc") || v.has("place") || v.has("populations") || v.has("place_grid");
    m.name = v.get("name", inline_model ? base_name + (changed ? "-custom" : "")
                                        : std::filesystem::path(v.file()).stem().string());
    if (v.has("sensor")) m.sensor = sensor_from_yaml(v["sensor"]);
    if (v.has("bvc")) read_table(v["bvc"], m.bvc, BvcParams::table());
    if (v.has("place")) read_table(v["place"], m.place, PlaceParams::table());
    if (v.has("populations")) m.populations = populations_from_yaml(v["populations"]);
    if (v.has("place_grid")) m.place_grid = v["place_grid"].as_string();
    if (!m.place_grid.empty() && std::none_of(m.populations.begin(), m.populations.end(),
                                              [&](const PopulationSpec& p) { return p.name == m.place_grid; }))
        (v.has("place_grid") ? v["place_grid"] : v["populations"])
            .fail("'" + m.place_grid +
                  "' names no population of the model's populations: list (the place cells' grid)");
    // The sections one by one may still not fit together (too many weights): at the key named.
    try {
        m.validate();
    } catch (const params::ParamError& e) {
        for (const char* section : {"place", "bvc", "sensor"})
            if (v.has(section) && v[section].is_map() && v[section].has(e.key())) v[section][e.key()].fail(e.reason());
        v.fail(e.what());
    }
    return m;
}

ModelSpec resolve_model(const std::string& name) {
    const auto presets = model_preset_names();
    if (std::find(presets.begin(), presets.end(), name) != presets.end()) return model_preset(name);
    std::error_code ec;
    if (!std::filesystem::exists(name, ec)) return model_preset(name);  // throws the "unknown model" error
    return model_from_yaml(YamlView::load_file(name));
}

std::string model_to_yaml(const ModelSpec& m) {
    std::string text = "name: " + m.name + "\nsensor:\n" + params::yaml_lines(LidarSpec::table(), m.sensor, "  ") +
                       "bvc:\n" + params::yaml_lines(BvcParams::table(), m.bvc, "  ") + "place:\n" +
                       params::yaml_lines(PlaceParams::table(), m.place, "  ");
    if (!m.populations.empty()) {  // only then: the paper's models keep their text and fingerprints
        text += "populations:\n";
        for (const PopulationSpec& p : m.populations) {
            text += "  - name: " + p.name + "\n    kind: " + p.kind + "\n    inputs: [";
            for (std::size_t i = 0; i < p.inputs.size(); ++i) text += (i ? ", " : "") + p.inputs[i];
            text += "]\n    recorded: " + std::string(p.recorded ? "true" : "false") + "\n    key: " + p.key + "\n";
        }
    }
    if (!m.place_grid.empty()) text += "place_grid: " + m.place_grid + "\n";
    return text;
}

void write_model(params::CommentedYaml& out, const ModelSpec& m, const std::string& indent) {
    out.line(indent, "name", params::CommentedYaml::scalar(m.name), "a label: trial names and tables show it");
    if (const std::string builtin = builtin_sensor_name(m.sensor); !builtin.empty()) {
        out.line(indent, "sensor", builtin,
                 "horizontal, spherical, spherical-authors, or a sensor mapping (bvc3d config --sensor NAME)");
    } else {
        out.section(indent, "sensor", "the scanner the model reads (docs/worlds.md#sensors)");
        write_sensor(out, m.sensor, indent + "  ");
    }
    out.section(indent, "bvc", "the boundary vector cells");
    out.fields(BvcParams::table(), m.bvc, indent + "  ");
    out.section(indent, "place", "the place-cell network");
    out.fields(PlaceParams::table(), m.place, indent + "  ");
    if (!m.populations.empty()) {  // each with its parameters as its canonical key (which the reader takes)
        std::string items;
        for (const PopulationSpec& p : m.populations) {
            items += (items.empty() ? "" : ", ") + std::string("{name: ") + params::CommentedYaml::scalar(p.name) +
                     ", kind: " + p.kind + ", inputs: [";
            for (std::size_t i = 0; i < p.inputs.size(); ++i) items += (i ? ", " : "") + p.inputs[i];
            items += "], recorded: " + std::string(p.recorded ? "true" : "false") + ", key: \"" + p.key +
                     "\"}";  // quoted: in a flow mapping, its brackets and commas
        }
        out.line(indent, "populations", "[" + items + "]", "further populations (docs/model-reference.md)");
    }
    if (!m.place_grid.empty())
        out.line(indent, "place_grid", params::CommentedYaml::scalar(m.place_grid),
                 "the grid population the place cells also read");
}

std::string model_to_commented_yaml(const ModelSpec& m) {
    params::CommentedYaml out;
    out.comment("", "A model (docs/model.md#custom-models-yaml): every key. Read by --model FILE.");
    write_model(out, m, "");
    return out.str();
}

std::string preset_name_of(const ModelSpec& m) {
    const auto names = model_preset_names();
    if (std::find(names.begin(), names.end(), m.name) == names.end()) return "";
    return model_to_yaml(model_preset(m.name)) == model_to_yaml(m) ? m.name : "";
}

}  // namespace bvc3d::config
