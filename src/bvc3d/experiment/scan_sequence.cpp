#include "bvc3d/experiment/scan_sequence.hpp"

#include "bvc3d/agent/trajectory.hpp"
#include "bvc3d/core/error.hpp"
#include "bvc3d/core/random.hpp"
#include "bvc3d/sensor/recorded_returns.hpp"

namespace bvc3d {

RecordingSequence::RecordingSequence(std::shared_ptr<const recording::Recording> recording)
    : recording_(std::move(recording)) {
    if (!recording_ || recording_->size() == 0) throw InputError("a recording without scans");
}

SimulatedSequence::SimulatedSequence(std::shared_ptr<const World> world, std::vector<ModelStep> route,
                                     std::string route_name, LidarSpec sensor, std::uint64_t seed)
    : world_(std::move(world)),
      route_(std::move(route)),
      name_(std::move(route_name)),
      sensor_(std::move(sensor)),
      noise_seed_(hash_u64(seed, static_cast<std::uint64_t>(Stream::sensor_noise), 0)) {
    if (route_.empty()) throw InputError("route '" + name_ + "' has no rows");
    sensor_.validate();
    TrajectorySpec(route_, name_).check_world(world_->description());
    for (const ModelStep& s : route_) poses_.push_back(sensor_pose(s.pose, sensor_.height));
}

recording::PointCloud SimulatedSequence::points(std::size_t i) const {
    const Lidar lidar(sensor_);  // its scratch space is not shared between threads
    Scan scan;
    lidar.scan(*world_, route_.at(i).pose, scan, NoiseKey{noise_seed_, i});
    return points_from_returns(scan, poses_[i].linear());
}

}  // namespace bvc3d
