#pragma once
// Navigation stage: the authors' controller as their code runs it (SPEC §17.2, policy `authors`; where bvc3d reads
// their code rather than SPEC's text, docs/navigation.md#the-authors-controller). Takes: the model to step, the
// world (the robot's body and a planar scan), each scale's memories, a seeded stream. Gives: one start run.
//
// A start: the learned state reloaded (learning on) or every population at rest (off); `settle_steps` model updates;
// then decisions until the goal is within the success radius or a cap is reached. A decision is one model update at
// the current pose, the reliability bookkeeping (authors_choice.hpp), and either an exploration block or: the least
// range of a planar scan per direction's sector, the turning rollouts of every scale, the mix and the heading rule;
// then a block: turn in place to the heading (skipped within `min_turn`), and `block_steps` × (a model update, a step
// of `step` m forward that stops at contact). The goal and the caps are checked after every step. An exploration
// block: up to `explore_steps` × (a model update; at contact a turn by U(−π, π) that ends the block; a step), then a
// turn by N(0, explore_turn_sd). A turn that cannot be completed: a turn by U(−max, max) and `failed_turn_steps`
// steps. Random draws, in the order they happen, from the start's stream: a decision's rollout uniforms (scale →
// step → direction → sample), an exploration's contact uniform and closing normal, a failed turn's uniform.
#include <memory>
#include <vector>

#include "bvc3d/navigation/authors_choice.hpp"
#include "bvc3d/navigation/policy.hpp"

namespace bvc3d {

// Where the authors' controller moves: on the floor by default (floor_body); a test may refuse turns.
class AuthorsBody {
public:
    virtual ~AuthorsBody() = default;
    // Turns in place to `heading` (rad); false when the turn cannot be completed (the pose holds where it stopped).
    virtual bool turn(Pose& pose, double heading) = 0;
    // Moves up to `step` m along the pose's heading, stopping at contact: the distance moved.
    virtual double forward(Pose& pose, double step) = 0;
    // A planar scan from the pose: the ranges along the allocentric azimuths 2πj/beams (+∞: no return).
    virtual std::vector<double> scan(const Pose& pose, int beams) const = 0;
};

// The robot's body (a disc of the robot's radius: it turns in place always; a step at contact slides along the wall
// or stops, as `contact` says) and the model's sensor cast level at its height in `world`, up to its range.
std::unique_ptr<AuthorsBody> floor_body(const World& world, const RobotParams& robot, const LidarSpec& sensor,
                                        ContactRule contact);

// What a start did, beyond its path.
struct AuthorsStats {
    int decisions = 0;         // decisions that took a heading
    int forced = 0;            // exploration blocks the low reliability forced
    int unsafe = 0;            // exploration blocks for want of a safe direction
    int failed_turns = 0;      // turns that could not be completed
    int full_turns = 0;        // loops seen: the accumulated heading change passed 360°
    int loop_penalties = 0;    // loops that cost the scales reliability
    std::size_t products = 0;  // distinct rollout states computed
};

class AuthorsController : public EpisodeController {
public:
    AuthorsController(const PolicyContext& context, const AuthorsParams& params, std::unique_ptr<AuthorsBody> body);
    StartRun run(const Pose& start, const StartTask& task, Rng& rng) override;
    const AuthorsStats& stats() const { return stats_; }  // of the last start

private:
    struct Start;  // one start's state
    void decide(Start& s);
    void explore(Start& s);
    void block(Start& s, double heading);
    void failed_turn(Start& s);
    void turn(Start& s, double heading, bool& completed);
    bool step(Start& s);  // a model update and a step forward; true when the start is over
    bool move(Start& s);  // the step forward alone, recorded; true when the start is over
    bool over(Start& s);  // the goal reached or a cap: sets the run's end

    PolicyContext c_;
    AuthorsParams p_;
    std::unique_ptr<AuthorsBody> body_;
    std::vector<ScaleMemory> live_;  // the scales' memories; their copies made again while learning (refresh)
    AuthorsStats stats_;
};

// The policy `authors` with its parameters (the `authors:` section).
class AuthorsPolicySpec : public PolicySpec {
public:
    static constexpr const char* kind = "authors";
    explicit AuthorsPolicySpec(AuthorsParams params = {}) : p_(params) {}
    const AuthorsParams& params() const { return p_; }
    std::string name() const override { return kind; }
    void validate() const override { p_.validate(); }
    std::string canonical(const std::string& indent) const override;
    void check_dims(int dims) const override;
    bool learns() const override { return p_.learn; }
    std::unique_ptr<EpisodeController> make(const PolicyContext& context) const override;

private:
    AuthorsParams p_;
};

}  // namespace bvc3d
