#pragma once
// Config stage: the authors' configuration (docs/reproduction.md#the-authors-configuration) — every
// way the authors' published code differs from the paper's text, as named choices that each change
// a trial's parameters through the ordinary tables and presets, and the experiment presets of
// `bvc3d paper --preset`: `spec` (none of them) and `authors` (all of them).
// Takes: a trial configuration. Gives: the same trial with some of the authors' choices switched on.
#include <functional>
#include <string>
#include <vector>

#include "bvc3d/config/trial_config.hpp"

namespace bvc3d {

struct AuthorsChoice {
    std::string name;         // protocol, reading, geometry, robot, labels, lag, analysis
    std::string description;  // what it changes, for help texts
    std::function<void(TrialConfig&)> apply;
};

// In the order an ablation switches them on. Each leaves everything else as it is, so any subset
// in any order gives the same trial.
const std::vector<AuthorsChoice>& authors_choices();
std::vector<std::string> authors_choice_names();
// Applies the named choices ("all": every one). InputError for an unknown name, or for a choice
// that cannot apply (the robot's choices to a trial that follows a given trajectory).
void apply_authors_choices(TrialConfig& t, const std::vector<std::string>& names);

// `bvc3d paper --preset NAME`: the paper's four models in the four tilts, with these choices.
struct PaperPreset {
    std::string name, description;
    std::vector<std::string> choices;
};
const std::vector<PaperPreset>& paper_presets();
const PaperPreset& paper_preset(const std::string& name);  // InputError for an unknown name

}  // namespace bvc3d
