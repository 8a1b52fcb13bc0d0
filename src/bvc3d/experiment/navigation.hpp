#pragma once
// Experiment stage: navigation to goals (SPEC §17, docs/navigation.md) as trials of the engine. Takes: a world, a
// model, a NavigationSpec (config/navigation_spec.hpp) and seeds. Gives: the checks a command makes before anything
// runs, and one navigation trial run in memory (Python's bvc3d.navigate); `bvc3d navigate` and sweeps run navigation
// trials through the experiment engine (experiment.hpp) like any other, into trial files.
//
// A navigation trial is an ordinary trial whose model carries navigation's populations (an HD population, and per
// scale of place cells an adjacency and reward cells) and whose agent is the learning walk (agent/learning_walk.hpp):
// its learning run is stepped, checkpointed and memory-checked as every trial is; after it, its episodes
// (episodes.hpp) run and the recorder writes them into its trial file (/navigation).
#include <atomic>
#include <cstdint>

#include "bvc3d/config/navigation_spec.hpp"
#include "bvc3d/recorder/trial_record.hpp"
#include "bvc3d/world/world.hpp"

namespace bvc3d {

// InputError naming each goal outside the walkable floor (in 3-D: the flight volume), where the body does not fit,
// or that cannot be reached from where the learning walk roams; goals of mixed dimension; a world without room for
// them; no goals.
void check_goals(const World& world, const NavigationSpec& nav);

// One navigation trial of `model` in `world` with `seed`, in memory through the trial pipeline: its record.
// Interrupted if `stop` is set.
NavigationRecord navigate(const World& world, const ModelSpec& model, const NavigationSpec& nav, std::uint64_t seed,
                          const std::atomic<bool>* stop = nullptr);

}  // namespace bvc3d
