#include "bvc3d/experiment/navigation.hpp"

#include <memory>

#include "bvc3d/agent/navigation_space.hpp"
#include "bvc3d/experiment/pipeline.hpp"

namespace bvc3d {

void check_goals(const World& world, const NavigationSpec& nav) {
    nav.validate();
    const auto space = make_navigation_space(world.description(), nav.space);
    for (std::size_t i = 0; i < nav.space.goals.size(); ++i) space->check_goal(i, nav.space.goals[i]);
}

NavigationRecord navigate(const World& world, const ModelSpec& model, const NavigationSpec& nav, std::uint64_t seed,
                          const std::atomic<bool>* stop) {
    check_goals(world, nav);
    TrialConfig trial =
        navigation_trial(WorldSpec::built(world.name()), model, std::make_shared<NavigationSpec>(nav), seed);
    RunControl control;
    control.stop = stop;
    GroupOutcome out = run_and_analyze(&world, {trial}, control);
    return std::move(out.result.models.front().navigation.front());
}

}  // namespace bvc3d
