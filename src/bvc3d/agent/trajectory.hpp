#pragma once
// A given path as the agent: model steps at given times and poses, e.g. a real robot's or animal's
// track, in place of the random walk (docs/experiments.md#user-trajectories).
// Takes: rows (t, x, y, [z], heading, [pitch, roll]), from arrays or a text file. Gives: model steps:
// the rows resampled to the model step (0.288 s, the robot's), or one per row (`step_per_row`).
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "bvc3d/agent/agent.hpp"

namespace bvc3d {

// How a user's rows become model steps. The place cells' time constant and Oja's rate are per model
// step, so rows every 0.01 s would run the dynamics 29 times as fast per second as the paper's step:
// by default the rows are resampled to steps `model_dt` apart (resample_steps()), unless they are at
// that step already (rows_at_model_step(): then they are the steps, bit for bit).
struct TrajectoryParams {
    bool step_per_row = false;  // one model step per row, whatever their interval (as before issue 32)
    double model_dt = 0.288;    // s between model steps when the rows are resampled (the robot's step)

    static const params::Table<TrajectoryParams>& table();
    void validate() const { table().check(*this); }
    bool operator==(const TrajectoryParams&) const = default;
};

// Whether rows are model steps already: their median interval is `model_dt` within 1e-6 (relative),
// as `bvc3d walk` and `bvc3d route` write them (turns in place add time between rows, a bump
// shortens a step; such intervals are kept as they are). Fewer than 2 rows: yes.
bool rows_at_model_step(const std::vector<ModelStep>& rows, double model_dt);
// The median interval between rows (0 for fewer than 2).
double median_row_interval(const std::vector<ModelStep>& rows);
// Steps at t = 0, dt, 2·dt, ... up to the last row's time, each pose interpolated between the rows
// around it: x, y, z and pitch linearly, heading and roll along the shorter arc. `source` names the
// rows when the span is refused (more than max_agent_hours).
std::vector<ModelStep> resample_steps(const std::vector<ModelStep>& rows, double dt, const std::string& source);

// The rows' times are shifted so that the first row is at t = 0; they must increase strictly.
// Positions are in the world frame (z: the agent's base above the floor, 0 if not given); headings
// in radians. No collision is checked: the path is the data.
class Trajectory : public Agent {
public:
    explicit Trajectory(std::shared_ptr<const std::vector<ModelStep>> steps);

    std::optional<ModelStep> next(double t_end) override;
    double time() const override { return next_ == 0 ? 0.0 : (*steps_)[next_ - 1].t; }
    bool finished() const override { return next_ >= steps_->size(); }
    std::string save_state() const override;
    void restore_state(const std::string& state) override;

private:
    std::shared_ptr<const std::vector<ModelStep>> steps_;
    std::size_t next_ = 0;
};

// Rows checked and shifted to start at t = 0. `source` names the data in errors (a file, "arrays").
// Pitch and roll (radians; empty: 0) tilt the agent, e.g. a hand-held sensor's attitude.
std::vector<ModelStep> trajectory_steps(const std::vector<double>& t, const std::vector<double>& x,
                                        const std::vector<double>& y, const std::vector<double>& z,
                                        const std::vector<double>& heading, const std::string& source,
                                        const std::vector<double>& pitch = {}, const std::vector<double>& roll = {});

// A text file, comma- or whitespace-separated, `#` comments: columns t, x, y, heading or
// t, x, y, z, heading; an optional header line names them (then in any order, `heading_deg` may
// replace `heading`, and `pitch`/`roll` or `pitch_deg`/`roll_deg` may be added; `bumped`, a column of
// `bvc3d walk`'s output, is read and left out). Errors name the file, the line and the reason.
std::vector<ModelStep> read_trajectory_file(const std::filesystem::path& path);

// Writes steps as read_trajectory_file() reads them back, bit for bit: a header `t,x,y,z,heading`
// (`,pitch,roll` when a step is tilted), one row per step, shortest round-trip decimals. Atomic: the
// file appears whole or not at all (InputError naming it).
void write_trajectory_file(const std::filesystem::path& path, const std::vector<ModelStep>& steps);

// A trajectory as a trial's agent: from a file (its name and contents fix the key) or from arrays.
class TrajectorySpec : public AgentSpec {
public:
    // A user's path: its rows made model steps as `params` says (resampled by default).
    static TrajectorySpec from_file(const std::filesystem::path& path, const TrajectoryParams& params = {});
    TrajectorySpec(std::vector<ModelStep> rows, std::string source, const TrajectoryParams& params);
    // Steps as they are, one per row (a recording's scans, a walk the program made).
    // dims 3: positions are analyzed in 3-D (voxels), as a flying agent's; 2 (the default): in the plane.
    TrajectorySpec(std::vector<ModelStep> steps, std::string source, int dims = 2);

    const std::string& source() const { return source_; }
    const std::vector<ModelStep>& steps() const { return *steps_; }
    const std::vector<ModelStep>& rows() const { return *rows_; }  // as given (the steps unless resampled)
    bool resampled() const { return steps_ != rows_; }
    const TrajectoryParams& params() const { return params_; }
    // "N rows every X s (median), resampled to M model steps of 0.288 s", or how they are stepped per row.
    std::string note() const override;
    std::string kind() const override { return "trajectory"; }
    Locomotion locomotion() const override { return Locomotion::given_path; }
    int dims() const override { return dims_; }
    void validate() const override {}
    // Every pose lies within the world's geometry (a path in another frame is a mistake).
    void check_world(const WorldDescription& world) const override;
    // Checks the world when there is one; without a world (a replay of recorded data) there is
    // nothing to check.
    std::unique_ptr<Agent> make(const World* world, std::uint64_t seed) const override;
    std::string key() const override;
    double steps_per_second() const override;
    void write_yaml(params::CommentedYaml& out) const override;

private:
    std::shared_ptr<const std::vector<ModelStep>> rows_, steps_;
    std::string source_;
    TrajectoryParams params_;
    bool user_ = false;           // a user's path (its steps follow params_), not steps as they are
    std::uint64_t hash_ = 0;      // of the rows, for the key
    std::filesystem::path file_;  // the file it was read from (absolute), empty for arrays
    int dims_ = 2;
};

}  // namespace bvc3d
