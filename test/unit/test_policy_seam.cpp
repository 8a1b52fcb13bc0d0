// The navigation policy seam (navigation/policy.hpp, config/policy_kinds.hpp): a policy written in this file alone —
// it walks straight at the goal, stepping the model as it goes — runs through the episodes of a navigation trial with
// no change to them; the policy's name enters the trial's canonical text (and so its fingerprint) except for the
// default policy at its defaults; YAML's policy: and sections are read and refused as the list says.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "../support/temp_dir.hpp"

#include "bvc3d/config/policy_kinds.hpp"
#include "bvc3d/config/world_yaml.hpp"
#include "bvc3d/core/error.hpp"
#include "bvc3d/experiment/navigation.hpp"

using namespace bvc3d;

namespace {

// Straight at the goal, `step` m a model step (no body: the test room has nothing in the way), after one settling step.
class StraightController : public EpisodeController {
public:
    StraightController(const PolicyContext& c, double step) : c_(c), step_(step) {}
    StartRun run(const Pose& start, const StartTask& task, Rng&) override {
        c_.senses.reset();
        c_.senses.step(start, false, 0.0);
        StartRun out;
        out.path.push_back(start.position());
        Pose pose = start;
        while (c_.space.distance(pose.position(), task.at) > task.success_radius) {
            if (out.path_m >= task.max_path_m) {
                out.end = StartEnd::path_cap;
                return out;
            }
            const Vec3 to = task.at - pose.position();
            const double move = std::min(step_, to.head<2>().norm());
            const double heading = std::atan2(to.y(), to.x());
            pose = Pose::on_floor(pose.x + move * std::cos(heading), pose.y + move * std::sin(heading), heading);
            out.path_m += move, out.time_s += 1.0;
            ++steps;
            rates_seen += c_.senses.step(pose, false, out.time_s).front().size();
            out.path.push_back(pose.position());
            out.bumped.push_back(0);
        }
        out.end = StartEnd::reached;
        return out;
    }
    inline static int steps = 0;
    inline static std::size_t rates_seen = 0;

private:
    PolicyContext c_;
    double step_;
};

class StraightSpec : public PolicySpec {
public:
    explicit StraightSpec(double step = 0.3) : step_(step) {}
    std::string name() const override { return "straight"; }
    std::string canonical(const std::string& indent) const override {
        return step_ == 0.3 ? "" : indent + "step: " + std::to_string(step_) + "\n";
    }
    void check_dims(int dims) const override {
        if (dims != 2) throw InputError("policy 'straight' walks on the floor only");
    }
    std::unique_ptr<EpisodeController> make(const PolicyContext& c) const override {
        return std::make_unique<StraightController>(c, step_);
    }

private:
    double step_;
};

World room(const std::filesystem::path& dir) {
    const auto file = dir / "room.yaml";
    std::ofstream(file) << "name: room\nobjects:\n"
                           "  - box: {center: [0, 0, -0.05], size: [8, 8, 0.1]}\n"
                           "  - box: {center: [-4.1, 0, 1.25], size: [0.2, 8.4, 2.5]}\n"
                           "  - box: {center: [4.1, 0, 1.25], size: [0.2, 8.4, 2.5]}\n"
                           "  - box: {center: [0, -4.1, 1.25], size: [8.4, 0.2, 2.5]}\n"
                           "  - box: {center: [0, 4.1, 1.25], size: [8.4, 0.2, 2.5]}\n"
                           "walkable: {rect: [-4, -4, 4, 4]}\nstart: {rect: [-3.5, -3.5, 3.5, 3.5]}\n";
    return World(config::load_world_file(file.string()));
}

NavigationSpec room_spec() {
    NavigationSpec s;
    s.space.goals = {{2.5, 2.5}};
    s.space.nav.max_learn_hours = 0.1;
    s.space.nav.goal_visits = 1;
    s.space.nav.coverage = 0.5;
    s.space.nav.starts = 3;
    s.space.nav.min_start_distance = 4.0;
    s.space.nav.reward_map_cell = 0;
    return s;
}

}  // namespace

TEST(PolicySeam, APolicyOfOneFileRunsTheEpisodesUnchanged) {
    test::TempDir dir;
    const World world = room(dir.path());
    NavigationSpec spec = room_spec();
    spec.policy = std::make_shared<StraightSpec>();
    StraightController::steps = 0;
    const NavigationRecord r = navigate(world, model_preset("2d"), spec, 1);
    ASSERT_EQ(r.n_starts(), 3u);
    std::size_t moves = 0;
    for (std::size_t i = 0; i < r.n_starts(); ++i) {
        EXPECT_EQ(r.success[i], 1);
        const Vec2 start(r.start[2 * i], r.start[2 * i + 1]);
        // Straight: the path is the distance to the goal less the success radius, within one step's rounding.
        EXPECT_NEAR(r.path_m[i], (start - Vec2(2.5, 2.5)).norm() - 1.0, 0.3 + 1e-9);
        moves += r.path_start[i + 1] - r.path_start[i] - 1;
        EXPECT_EQ(r.path[2 * r.path_start[i]], start.x());  // each path opens at its start
    }
    EXPECT_EQ(std::size_t(StraightController::steps), moves);
    EXPECT_EQ(StraightController::rates_seen, moves * 250);  // it stepped the model (the 2-D model's 250 cells)

    // A space the policy cannot move in is refused before anything runs.
    spec.space.goals = {{1.0, 1.0, 1.0}};
    EXPECT_THROW(spec.validate(), InputError);
}

TEST(PolicySeam, ThePolicyEntersTheCanonicalTextUnlessItIsTheDefaultAtItsDefaults) {
    NavigationSpec spec = room_spec();
    const std::string today = spec.canonical();
    EXPECT_EQ(today.find("policy"), std::string::npos);
    spec.policy = default_policy();
    EXPECT_EQ(spec.canonical(), today);
    spec.policy = std::make_shared<StraightSpec>();
    EXPECT_NE(spec.canonical().find("  policy: straight\n"), std::string::npos) << spec.canonical();
    EXPECT_NE(spec.canonical(), today);
    EXPECT_EQ(default_policy_kind().name, "rollout8");
}

TEST(PolicySeam, YamlNamesAPolicyOfTheListAndItsSectionOnly) {
    const auto read = [](const std::string& text) {
        return config::policy_from_yaml(config::YamlView::load_string(text, "test.yaml"));
    };
    EXPECT_EQ(read("goals: []\n")->name(), "rollout8");
    EXPECT_EQ(read("policy: rollout8\n")->name(), "rollout8");
    try {
        read("policy: nonesuch\n");
        FAIL();
    } catch (const InputError& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("nonesuch"), std::string::npos) << what;
        EXPECT_NE(what.find("rollout8"), std::string::npos) << what;  // the list
    }
    const auto section = config::YamlView::load_string("{step: 1}", "test.yaml");
    EXPECT_THROW(config::policy_named("rollout8", &section), InputError);  // it takes no parameters
}
