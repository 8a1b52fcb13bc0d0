#pragma once
// A sequence of scans with poses, as place recognition reads it (docs/place-recognition.md): a
// recording, or a simulated sensor driven along a route through a world (the same scans a recording
// of that drive would hold: points in the sensor's frame, its world-from-sensor pose, a time).
// Takes: a recording; or a world, a route (trajectory rows) and a sensor. Gives: scan i's points,
// pose and time, from any thread.
#include <Eigen/Geometry>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "bvc3d/agent/agent.hpp"
#include "bvc3d/recording/recording.hpp"
#include "bvc3d/sensor/lidar.hpp"
#include "bvc3d/world/world.hpp"

namespace bvc3d {

class ScanSequence {
public:
    virtual ~ScanSequence() = default;
    virtual std::string name() const = 0;
    virtual std::size_t size() const = 0;
    virtual const Eigen::Isometry3d& pose(std::size_t i) const = 0;  // world from sensor
    virtual std::optional<double> time(std::size_t i) const = 0;     // s
    // Scan i's points in the sensor's frame (x forward, z up). Safe to call from several threads.
    virtual recording::PointCloud points(std::size_t i) const = 0;
};

class RecordingSequence : public ScanSequence {
public:
    explicit RecordingSequence(std::shared_ptr<const recording::Recording> recording);
    std::string name() const override { return recording_->name; }
    std::size_t size() const override { return recording_->size(); }
    const Eigen::Isometry3d& pose(std::size_t i) const override { return recording_->poses[i].world_from_sensor; }
    std::optional<double> time(std::size_t i) const override { return recording_->time(i); }
    recording::PointCloud points(std::size_t i) const override { return recording_->load(i); }

private:
    std::shared_ptr<const recording::Recording> recording_;
};

// The sensor sits `height` above each route pose (LidarSpec::height), turned with it; range noise and
// dropout are seeded by (seed, scan), as `bvc3d export-scans` seeds them. The route must lie inside
// the world's geometry (InputError naming the route's row otherwise).
class SimulatedSequence : public ScanSequence {
public:
    SimulatedSequence(std::shared_ptr<const World> world, std::vector<ModelStep> route, std::string route_name,
                      LidarSpec sensor, std::uint64_t seed);
    std::string name() const override { return name_; }
    std::size_t size() const override { return route_.size(); }
    const Eigen::Isometry3d& pose(std::size_t i) const override { return poses_[i]; }
    std::optional<double> time(std::size_t i) const override { return route_[i].t; }
    recording::PointCloud points(std::size_t i) const override;

private:
    std::shared_ptr<const World> world_;
    std::vector<ModelStep> route_;
    std::string name_;
    LidarSpec sensor_;
    std::uint64_t noise_seed_;
    std::vector<Eigen::Isometry3d> poses_;
};

}  // namespace bvc3d
