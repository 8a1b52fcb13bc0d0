#pragma once
// Experiment stage: navigation's episodes (SPEC §17, docs/navigation.md), what a navigation trial does after its
// learning run. Takes: the world, the trial (TrialConfig::navigation set) and every population's state at the end of
// learning. Gives: the trial's NavigationRecord (recorder/trial_record.hpp) and the reward cells' state after replay.
//
// Per scale of place cells, the learned adjacency's frozen copies (navigation/scale_memory.hpp) and, per goal,
// replay from the reward cell the learning bound (navigation/replay.hpp). Then the model, its state as learned (the
// reward cells' weights set by replay), is stepped through its populations one model step at a time: at points of
// the floor for the first scale's reward map (at rest, learning off), and from `starts` random starts per goal (at
// least `min_start_distance` from it, in its part of the space) where the trial's policy (navigation/policy.hpp: the
// NavigationSpec's) runs each start — it steps the model and moves the agent (agent/navigation_space.hpp) until it is
// within `success_radius` of the goal, or its path reaches `max_path_ratio` × the shortest path, or `max_hours` pass.
#include <atomic>
#include <functional>
#include <vector>

#include "bvc3d/config/trial_config.hpp"
#include "bvc3d/population/population.hpp"
#include "bvc3d/recorder/trial_record.hpp"

namespace bvc3d {

struct EpisodeControl {
    const std::atomic<bool>* stop = nullptr;  // checked between starts: Interrupted
    std::function<void(std::size_t starts_done, std::size_t starts)> progress;
};

struct EpisodeOutcome {
    NavigationRecord record;
    // The states given, the reward cells' with their weights after replay (what the trial keeps of them).
    std::vector<std::vector<StateArray>> states;
};

// `learned`: every population's state, in the order of the trial's network (ModelNetwork of the trial alone).
EpisodeOutcome run_episodes(const World& world, const TrialConfig& trial, std::vector<std::vector<StateArray>> learned,
                            const EpisodeControl& control = {});

}  // namespace bvc3d
