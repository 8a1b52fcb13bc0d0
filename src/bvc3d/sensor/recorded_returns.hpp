#pragma once
// Returns from recorded scans (docs/model-reference.md#recorded-scans): the preprocessing that
// turns a real LiDAR's points into the returns a model reads, as sources behind the ReturnSource
// seam. Takes: points in the sensor's frame with the pose's rotation (a recording), or the returns
// of another source (a simulated sensor treated like a recorded one). Gives: gravity-aligned,
// allocentric returns (r, θ, φ) within the range limits, with the elevations the model keeps.
#include <memory>
#include <span>
#include <string>

#include "bvc3d/core/angles.hpp"
#include "bvc3d/core/params.hpp"
#include "bvc3d/recording/recording.hpp"
#include "bvc3d/sensor/return_source.hpp"

namespace bvc3d {

// Which elevations a model keeps of a recorded scan.
enum class ReturnSelection {
    upper_half,        // φ >= 0: models whose sensor keeps the upper half (the 3-D presets)
    all,               // every elevation: models whose sensor also reads below the horizon
    horizontal_slice,  // |φ| <= slice_half_width: models without elevation layers (2-D, eq. 1)
};
std::string selection_name(ReturnSelection s);

// The selection for a model reading `sensor`, with (planar = false) or without elevation layers.
ReturnSelection selection_for(const LidarSpec& sensor, bool planar);

struct RecordedReturnParams {
    double min_range = 0.3;                   // m: nearer points (the carrier, the operator) are dropped
    double max_range = 20.0;                  // m: the simulated sensors' range
    double slice_half_width = deg_to_rad(1);  // rad: the 2-D models' horizontal slice

    static const params::Table<RecordedReturnParams>& table();
    void validate() const;  // throws params::ParamError naming the bad field
};

// The returns of `xyz` (N × 3 row-major, sensor frame) seen through rotation `world_from_sensor`
// (v = R·p; the translation does not enter), kept by range and selection, into `out` (cleared).
void returns_from_points(std::span<const double> xyz, const Eigen::Matrix3d& world_from_sensor,
                         const RecordedReturnParams& params, ReturnSelection selection, Scan& out);

// The other way (exporting simulated scans as a recording): world-frame returns as points in the
// frame of a sensor with rotation `world_from_sensor` (p = Rᵀ·v).
recording::PointCloud points_from_returns(const Scan& scan, const Eigen::Matrix3d& world_from_sensor);
// Where a simulated sensor is: `height` above the agent's base along its up axis, turned with it.
Eigen::Isometry3d sensor_pose(const Pose& agent, double height);

// Drops the returns outside the range limits and the selection, in place (order kept).
void filter_returns(Scan& scan, const RecordedReturnParams& params, ReturnSelection selection);

// A recording's scans for the sources of one run: scan i is loaded when first asked for and kept
// until another is (several models read the same step). Not shared between threads.
class RecordedScans {
public:
    explicit RecordedScans(std::shared_ptr<const recording::Recording> recording);
    const recording::Recording& recording() const { return *recording_; }
    const recording::PointCloud& cloud(std::size_t i);

private:
    std::shared_ptr<const recording::Recording> recording_;
    std::size_t loaded_ = static_cast<std::size_t>(-1);
    recording::PointCloud cloud_;
};

// Model step i reads scan i of the recording, rotated by its own recorded pose (the agent's pose,
// rounded through heading/pitch/roll, is not used).
class RecordedSource : public ReturnSource {
public:
    RecordedSource(std::shared_ptr<RecordedScans> scans, RecordedReturnParams params, ReturnSelection selection);
    void returns(std::uint64_t step, const Pose& pose, const std::vector<char>& rows, Scan& out) override;

private:
    std::shared_ptr<RecordedScans> scans_;
    RecordedReturnParams params_;
    ReturnSelection selection_;
};

// Another source's returns with the same preprocessing (for a simulated sensor standing in for a
// recorded one). A beam table at a level pose casts only the rows the selection can keep.
class FilteredSource : public ReturnSource {
public:
    FilteredSource(std::shared_ptr<ReturnSource> inner, RecordedReturnParams params, ReturnSelection selection);
    const LidarSpec* beam_table() const override { return inner_->beam_table(); }
    void returns(std::uint64_t step, const Pose& pose, const std::vector<char>& rows, Scan& out) override;

private:
    std::shared_ptr<ReturnSource> inner_;
    RecordedReturnParams params_;
    ReturnSelection selection_;
    std::vector<char> allowed_, mask_;  // rows the selection can keep; this step's rows
};

}  // namespace bvc3d
