#pragma once
// Where a model step's returns come from: the seam between agents and models. Two kinds of source:
// a scanner ray-cast in a world (a beam table, whose rows a model may not all need), and returns
// given as data (arrays here; recorded LiDAR scans in the recording stage).
// Takes: the step's index and the agent's pose. Gives: the step's returns.
#include <cstdint>
#include <vector>

#include "bvc3d/sensor/lidar.hpp"

namespace bvc3d {

class ReturnSource {
public:
    virtual ~ReturnSource() = default;
    // The beam table the returns are cast from, if any: a model may then cast only the rows it needs
    // (see BoundaryVectorLayer::plan). nullptr for returns given as data.
    virtual const LidarSpec* beam_table() const { return nullptr; }
    // The returns of model step `step` at `pose`, into `out`. `rows` (one flag per row of the beam
    // table, empty for all) applies to beam tables at level poses only; other sources ignore it.
    virtual void returns(std::uint64_t step, const Pose& pose, const std::vector<char>& rows, Scan& out) = 0;
};

// A simulated scanner in a world. Noise and dropout are keyed by (noise_seed, step, beam), so a
// step's noise does not depend on which rows were cast.
class RayCastSource : public ReturnSource {
public:
    RayCastSource(const World& world, LidarSpec spec, std::uint64_t noise_seed)
        : world_(world), lidar_(std::move(spec)), noise_seed_(noise_seed) {}
    const LidarSpec* beam_table() const override { return &lidar_.spec(); }
    void returns(std::uint64_t step, const Pose& pose, const std::vector<char>& rows, Scan& out) override {
        lidar_.scan(world_, pose, out, NoiseKey{noise_seed_, step}, rows);
    }

private:
    const World& world_;
    Lidar lidar_;
    std::uint64_t noise_seed_;
};

// Returns given per step as data (e.g. from numpy): step i reads scans[i].
class ArrayReturnSource : public ReturnSource {
public:
    explicit ArrayReturnSource(std::vector<Scan> scans) : scans_(std::move(scans)) {}
    std::size_t size() const { return scans_.size(); }
    void returns(std::uint64_t step, const Pose&, const std::vector<char>&, Scan& out) override;

private:
    std::vector<Scan> scans_;
};

}  // namespace bvc3d
