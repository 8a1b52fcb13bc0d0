// World YAML (config::world_from_yaml), as `--world FILE` reads it.
#include "bvc3d/config/world_yaml.hpp"
#include "fuzz_common.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    return bvc3d::fuzz::expect_input_errors([&] {
        const std::string text(reinterpret_cast<const char*>(data), size);
        bvc3d::config::world_from_yaml(bvc3d::config::YamlView::load_string(text, "fuzz.yaml"));
    });
}
