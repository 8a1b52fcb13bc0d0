#pragma once
// Config stage: where a trial's returns come from when not from each model's own sensor ray-cast
// in the world (docs/recordings.md). Takes: a recording, or a simulated sensor, and the
// preprocessing of recorded scans. Gives: the sources a run's models read (a SourceFactory), with
// a label and the text that fixes them (for trial files and fingerprints).
#include <cstdint>
#include <functional>
#include <memory>
#include <string>

#include "bvc3d/agent/agent.hpp"
#include "bvc3d/config/model_spec.hpp"
#include "bvc3d/recording/recording.hpp"
#include "bvc3d/sensor/recorded_returns.hpp"
#include "bvc3d/sensor/return_source.hpp"
#include "bvc3d/world/world.hpp"

namespace bvc3d {

// A model's source of returns in a run; `world` is null when the trial has none. Models given the
// same source share it.
using SourceFactory = std::function<std::shared_ptr<ReturnSource>(const ModelSpec& model, const World* world)>;

class ReturnsSpec {
public:
    virtual ~ReturnsSpec() = default;
    virtual std::string label() const = 0;         // "hall-lidar": names the data in file names and tables
    virtual std::string sensor_label() const = 0;  // what the trial file records as its sensor
    virtual std::string key() const = 0;           // YAML text that fixes the returns (trial files, fingerprints)
    virtual bool needs_world() const = 0;
    // Text attributes a trial file records about the data (names, files).
    virtual std::vector<std::pair<std::string, std::string>> attributes() const { return {}; }
    // Sources for one run (shared by its models, not between threads); `seed` keys sensor noise.
    virtual SourceFactory factory(std::uint64_t seed) const = 0;
};

// A recording replayed: model step i reads scan i, preprocessed for each model's selection.
class RecordedReturnsSpec : public ReturnsSpec {
public:
    RecordedReturnsSpec(std::shared_ptr<const recording::Recording> recording, RecordedReturnParams params);
    const recording::Recording& recording() const { return *recording_; }
    const RecordedReturnParams& params() const { return params_; }
    std::string label() const override { return recording_->name; }
    std::string sensor_label() const override { return "recorded"; }
    std::string key() const override;
    bool needs_world() const override { return false; }
    // recording, recording_scans, recording_poses, and recording_t0 (the first scan's time, s)
    std::vector<std::pair<std::string, std::string>> attributes() const override;
    SourceFactory factory(std::uint64_t seed) const override;

private:
    std::shared_ptr<const recording::Recording> recording_;
    RecordedReturnParams params_;
    std::string fingerprint_;
};

// One simulated sensor for every model, its returns preprocessed as a recording's would be: a
// simulated stand-in for a real scanner (its beam pattern), e.g. template scans in a point map.
class SimulatedReturnsSpec : public ReturnsSpec {
public:
    SimulatedReturnsSpec(LidarSpec sensor, RecordedReturnParams params);
    const LidarSpec& sensor() const { return sensor_; }
    std::string label() const override { return sensor_.name; }
    std::string sensor_label() const override { return sensor_.name; }
    std::string key() const override;
    bool needs_world() const override { return true; }
    std::vector<std::pair<std::string, std::string>> attributes() const override {
        return {{"simulated_sensor", sensor_.name}};
    }
    SourceFactory factory(std::uint64_t seed) const override;

private:
    LidarSpec sensor_;
    RecordedReturnParams params_;
};

// The Trajectory rows of a recording: each scan's time (shifted to start at 0; a recording without
// times gets one scan per second), position and heading (the yaw of the sensor's forward axis on
// the floor), with pitch and roll. Times must increase (InputError naming the scan).
std::vector<ModelStep> recording_steps(const recording::Recording& recording);

}  // namespace bvc3d
