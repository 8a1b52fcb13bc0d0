#include "bvc3d/recording/bag_writer.hpp"

#include <unistd.h>

#include <cmath>
#include <cstring>

#include "bvc3d/core/atomic_file.hpp"
#include "bvc3d/core/error.hpp"
#include "bvc3d/recording/bag.hpp"
#include "bvc3d/recording/cdr.hpp"
#include "bvc3d/recording/mcap.hpp"
#include "bvc3d/recording/ros_messages.hpp"

namespace bvc3d::recording {

namespace fs = std::filesystem;

namespace {

CloudMessage cloud_message(const PointCloud& cloud, double stamp, const std::string& frame) {
    CloudMessage c;
    c.stamp = stamp;
    c.frame_id = frame;
    c.height = 1;
    c.width = static_cast<std::uint32_t>(cloud.size());
    const auto f64 = static_cast<std::uint8_t>(PointFieldType::float64);
    c.fields = {{"x", 0, f64, 1}, {"y", 8, f64, 1}, {"z", 16, f64, 1}};
    c.point_step = 24;
    c.row_step = 24 * c.width;
    c.data.resize(cloud.xyz.size() * sizeof(double));
    std::memcpy(c.data.data(), cloud.xyz.data(), c.data.size());  // x86: little-endian, as declared
    return c;
}

StampedTransform transform(const PoseRecord& p, double stamp, const BagWriteOptions& o) {
    StampedTransform t;
    t.stamp = stamp;
    t.parent = o.fixed_frame;
    t.child = o.sensor_frame;
    t.translation = p.world_from_sensor.translation();
    t.rotation = Eigen::Quaterniond(p.world_from_sensor.linear()).normalized();
    return t;
}

void write_ros1(const fs::path& file, const std::vector<PointCloud>& clouds, const std::vector<PoseRecord>& poses,
                const BagWriteOptions& o) {
    std::vector<CloudMessage> messages;
    std::vector<StampedTransform> transforms;
    for (std::size_t i = 0; i < clouds.size(); ++i) {
        const double stamp = o.start + *poses[i].time;
        messages.push_back(cloud_message(clouds[i], stamp, o.sensor_frame));
        transforms.push_back(transform(poses[i], stamp, o));
    }
    ros1::write_bag(file, messages, transforms, o.cloud_topic, o.odom_topic);
}

void write_mcap(const fs::path& file, const std::vector<PointCloud>& clouds, const std::vector<PoseRecord>& poses,
                const BagWriteOptions& o) {
    McapWriter w(file, McapCompression::zstd);
    const auto tf = w.add_channel("/tf", "tf2_msgs/msg/TFMessage", ros2_definition("tf2_msgs/msg/TFMessage"));
    const auto odom = w.add_channel(o.odom_topic, "nav_msgs/msg/Odometry", ros2_definition("nav_msgs/msg/Odometry"));
    const auto points =
        w.add_channel(o.cloud_topic, "sensor_msgs/msg/PointCloud2", ros2_definition("sensor_msgs/msg/PointCloud2"));
    for (std::size_t i = 0; i < clouds.size(); ++i) {
        const double stamp = o.start + *poses[i].time;
        const auto ns = static_cast<std::uint64_t>(std::llround(stamp * 1e9));
        const StampedTransform t = transform(poses[i], stamp, o);
        w.write(tf, ns, cdr::encode_tf({t}));
        w.write(odom, ns, cdr::encode_odometry(t));
        w.write(points, ns, cdr::encode_cloud(cloud_message(clouds[i], stamp, o.sensor_frame)));
    }
    w.commit();
}

}  // namespace

void write_bag(const fs::path& target, const std::vector<PointCloud>& clouds, const std::vector<PoseRecord>& poses,
               const BagWriteOptions& o) {
    const fs::path file = without_trailing_slash(target);
    if (clouds.size() != poses.size()) throw std::logic_error("write_bag: one pose per scan");
    if (clouds.empty()) throw InputError(quoted_path(file) + ": a bag needs at least one scan");
    for (std::size_t i = 0; i < poses.size(); ++i)
        if (!poses[i].time || (i > 0 && !(*poses[i].time > *poses[i - 1].time)))
            throw InputError(quoted_path(file) + ": scan " + std::to_string(i) + " has no time after the previous");
    if (!(o.start + *poses.front().time > 0)) throw InputError("a bag's stamps must be positive: raise the start time");
    require_not_directory(file, "bag");
    if (o.format == BagFormat::mcap) return write_mcap(file, clouds, poses, o);
    const fs::path parent = file.has_parent_path() ? file.parent_path() : fs::path(".");
    const fs::path created = ensure_writable_directory(parent);
    // rosbag writes its own file: into a temporary beside the target, renamed when complete.
    const fs::path temp = file.string() + ".tmp" + std::to_string(::getpid());
    try {
        write_ros1(temp, clouds, poses, o);
        std::error_code ec;
        fs::rename(temp, file, ec);
        if (ec) throw InputError("cannot write " + quoted_path(file) + ": " + ec.message());
    } catch (...) {
        std::error_code ec;
        fs::remove(temp, ec);
        remove_empty_folders(parent, created);
        throw;
    }
}

}  // namespace bvc3d::recording
