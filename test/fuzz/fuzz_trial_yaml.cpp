// Trial YAML (config::trial_from_yaml), as `run --config FILE` reads it, then the checks a run makes
// before it starts.
#include "bvc3d/config/trial_yaml.hpp"
#include "fuzz_common.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    return bvc3d::fuzz::expect_input_errors([&] {
        const std::string text(reinterpret_cast<const char*>(data), size);
        const auto trial = bvc3d::config::trial_from_yaml(bvc3d::config::YamlView::load_string(text, "fuzz.yaml"));
        trial.validate();
        trial.canonical();
    });
}
