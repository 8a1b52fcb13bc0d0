#include "bvc3d/recording/bag_writer.hpp"

#include <unistd.h>
#include <yaml-cpp/yaml.h>

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

// What rosbag2 records for a topic whose publisher has ROS 2's default QoS (reliable, volatile): the
// YAML list that `ros2 bag` keeps in metadata.yaml and, in an MCAP bag, in each channel's metadata.
const std::string default_qos =
    "- history: 3\n  depth: 0\n  reliability: 1\n  durability: 2\n  deadline:\n    sec: 9223372036\n"
    "    nsec: 854775807\n  lifespan:\n    sec: 9223372036\n    nsec: 854775807\n  liveliness: 1\n"
    "  liveliness_lease_duration:\n    sec: 9223372036\n    nsec: 854775807\n"
    "  avoid_ros_namespace_conventions: false";

struct TopicWritten {
    std::string name, type;
    std::size_t count = 0;
};

// The three topics into an MCAP file; returns them with their counts.
std::vector<TopicWritten> write_mcap(const fs::path& file, const std::vector<PointCloud>& clouds,
                                     const std::vector<PoseRecord>& poses, const BagWriteOptions& o) {
    McapWriter w(file, McapCompression::zstd);
    std::vector<TopicWritten> topics{{"/tf", "tf2_msgs/msg/TFMessage", clouds.size()},
                                     {o.odom_topic, "nav_msgs/msg/Odometry", clouds.size()},
                                     {o.cloud_topic, "sensor_msgs/msg/PointCloud2", clouds.size()}};
    std::vector<std::uint16_t> ids;
    for (const auto& t : topics)
        ids.push_back(w.add_channel(t.name, t.type, ros2_definition(t.type), {{"offered_qos_profiles", default_qos}}));
    for (std::size_t i = 0; i < clouds.size(); ++i) {
        const double stamp = o.start + *poses[i].time;
        const auto ns = static_cast<std::uint64_t>(std::llround(stamp * 1e9));
        const StampedTransform t = transform(poses[i], stamp, o);
        w.write(ids[0], ns, cdr::encode_tf({t}));
        w.write(ids[1], ns, cdr::encode_odometry(t));
        w.write(ids[2], ns, cdr::encode_cloud(cloud_message(clouds[i], stamp, o.sensor_frame)));
    }
    w.commit();
    return topics;
}

// A ROS 2 bag folder as `ros2 bag record -s mcap` leaves it: <name>_0.mcap and metadata.yaml (version
// 5, the format of ROS 2 Humble's rosbag2, which later releases read too).
void write_ros2_folder(const fs::path& folder, const std::vector<PointCloud>& clouds,
                       const std::vector<PoseRecord>& poses, const BagWriteOptions& o) {
    const std::string name = folder.filename().string();
    std::error_code ec;
    if (fs::exists(folder, ec)) {
        if (!fs::is_directory(folder, ec))
            throw InputError(quoted_path(folder) + " exists and is not a folder (a ROS 2 bag is a folder)");
        const auto ours = [&](const std::string& f) {  // metadata.yaml, <name>_<n>.mcap
            return f == "metadata.yaml" || (f.rfind(name + "_", 0) == 0 && f.size() > name.size() + 6 &&
                                            f.compare(f.size() - 5, 5, ".mcap") == 0);
        };
        for (const auto& e : fs::directory_iterator(folder))
            if (!e.is_regular_file() || !ours(e.path().filename().string()))
                throw InputError(quoted_path(folder) + " holds '" + e.path().filename().string() +
                                 "', which a ROS 2 bag written by bvc3d does not: choose a new or empty folder");
    }
    AtomicFolder out(folder);
    const std::string storage = name + "_0.mcap";
    const auto topics = write_mcap(out.temp_path() / storage, clouds, poses, o);
    const auto ns = [&](std::size_t i) { return std::llround((o.start + *poses[i].time) * 1e9); };
    const long long start = ns(0), duration = ns(poses.size() - 1) - start;
    std::size_t total = 0;
    for (const auto& t : topics) total += t.count;
    YAML::Emitter y;
    y << YAML::BeginMap << YAML::Key << "rosbag2_bagfile_information" << YAML::Value << YAML::BeginMap;
    y << YAML::Key << "version" << YAML::Value << 5;
    y << YAML::Key << "storage_identifier" << YAML::Value << "mcap";
    y << YAML::Key << "duration" << YAML::Value << YAML::BeginMap << YAML::Key << "nanoseconds" << YAML::Value
      << duration << YAML::EndMap;
    y << YAML::Key << "starting_time" << YAML::Value << YAML::BeginMap << YAML::Key << "nanoseconds_since_epoch"
      << YAML::Value << start << YAML::EndMap;
    y << YAML::Key << "message_count" << YAML::Value << total;
    y << YAML::Key << "topics_with_message_count" << YAML::Value << YAML::BeginSeq;
    for (const auto& t : topics) {
        y << YAML::BeginMap << YAML::Key << "topic_metadata" << YAML::Value << YAML::BeginMap;
        y << YAML::Key << "name" << YAML::Value << t.name << YAML::Key << "type" << YAML::Value << t.type;
        y << YAML::Key << "serialization_format" << YAML::Value << "cdr";
        y << YAML::Key << "offered_qos_profiles" << YAML::Value << YAML::DoubleQuoted << default_qos;
        y << YAML::EndMap << YAML::Key << "message_count" << YAML::Value << t.count << YAML::EndMap;
    }
    y << YAML::EndSeq;
    y << YAML::Key << "compression_format" << YAML::Value << YAML::DoubleQuoted << "";
    y << YAML::Key << "compression_mode" << YAML::Value << YAML::DoubleQuoted << "";
    y << YAML::Key << "relative_file_paths" << YAML::Value << YAML::BeginSeq << storage << YAML::EndSeq;
    y << YAML::Key << "files" << YAML::Value << YAML::BeginSeq << YAML::BeginMap;
    y << YAML::Key << "path" << YAML::Value << storage;
    y << YAML::Key << "starting_time" << YAML::Value << YAML::BeginMap << YAML::Key << "nanoseconds_since_epoch"
      << YAML::Value << start << YAML::EndMap;
    y << YAML::Key << "duration" << YAML::Value << YAML::BeginMap << YAML::Key << "nanoseconds" << YAML::Value
      << duration << YAML::EndMap;
    y << YAML::Key << "message_count" << YAML::Value << total;
    y << YAML::EndMap << YAML::EndSeq << YAML::EndMap << YAML::EndMap;
    write_file_atomically(out.temp_path() / "metadata.yaml", std::string(y.c_str()) + "\n");
    out.commit();
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
    if (o.format == BagFormat::ros2) return write_ros2_folder(file, clouds, poses, o);
    require_not_directory(file, "bag");
    if (o.format == BagFormat::mcap) {
        write_mcap(file, clouds, poses, o);
        return;
    }
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
