#include "bvc3d/recording/bag.hpp"

#include <algorithm>

#include "bvc3d/core/error.hpp"
#include "bvc3d/recording/cdr.hpp"

namespace bvc3d::recording {

namespace fs = std::filesystem;

std::string quoted_path(const fs::path& path) {
    std::string s(1, '\'');
    s += path.string();
    s += '\'';
    return s;
}

MessageKind message_kind(const std::string& type) {
    // ROS 2 spells a type package/msg/Name, ROS 1 package/Name.
    std::string t = type;
    if (const auto at = t.find("/msg/"); at != std::string::npos) t.erase(at, 4);
    if (t == "sensor_msgs/PointCloud2") return MessageKind::point_cloud2;
    if (t == "nav_msgs/Odometry") return MessageKind::odometry;
    if (t == "geometry_msgs/PoseStamped") return MessageKind::pose_stamped;
    if (t == "tf2_msgs/TFMessage" || t == "tf/tfMessage") return MessageKind::tf;
    return MessageKind::other;
}

std::size_t BagReader::topic(const std::string& name) const {
    for (std::size_t i = 0; i < topics_.size(); ++i)
        if (topics_[i].name == name) return i;
    std::string list;
    for (const auto& t : topics_) list += (list.empty() ? "" : ", ") + t.name + " (" + t.type + ")";
    throw InputError(quoted_path(path_) + " has no topic '" + name +
                     "' (its topics: " + (list.empty() ? "none" : list) + ")");
}

std::string BagReader::where(std::size_t t, std::size_t k) const {
    return quoted_path(path_) + ", topic '" + topics_.at(t).name + "', message " + std::to_string(k);
}

void BagReader::expect(std::size_t t, std::size_t k, MessageKind kind) const {
    const BagTopic& topic = topics_.at(t);
    if (k >= topic.count)
        throw InputError(where(t, k) + ": the topic has " + std::to_string(topic.count) + " messages");
    if (message_kind(topic.type) != kind) {
        const char* wanted = kind == MessageKind::point_cloud2 ? "sensor_msgs/PointCloud2"
                             : kind == MessageKind::tf         ? "tf2_msgs/TFMessage"
                                                               : "nav_msgs/Odometry or geometry_msgs/PoseStamped";
        throw InputError(quoted_path(path_) + ", topic '" + topic.name + "' is of type " + topic.type + ", not " +
                         wanted);
    }
    if (topic.encoding == MessageEncoding::unknown)
        throw InputError(where(t, k) + ": unknown message encoding '" + topic.encoding_name +
                         "' (bvc3d reads cdr and ros1)");
}

namespace {

// Decoding errors get the message's place in front.
template <class F>
auto decoded(const BagReader& bag, std::size_t t, std::size_t k, F&& decode) {
    try {
        return decode();
    } catch (const InputError& e) {
        throw InputError(bag.where(t, k) + ": " + e.what());
    }
}

}  // namespace

CloudMessage BagReader::cloud(std::size_t t, std::size_t k) const {
    expect(t, k, MessageKind::point_cloud2);
    return decoded(*this, t, k, [&] {
        const auto bytes = serialized(t, k);
        return topics_[t].encoding == MessageEncoding::cdr ? cdr::decode_cloud(bytes) : ros1::decode_cloud(bytes);
    });
}

StampedTransform BagReader::pose(std::size_t t, std::size_t k) const {
    const bool odometry = message_kind(topics_.at(t).type) == MessageKind::odometry;
    expect(t, k, odometry ? MessageKind::odometry : MessageKind::pose_stamped);
    return decoded(*this, t, k, [&] {
        const auto bytes = serialized(t, k);
        if (topics_[t].encoding == MessageEncoding::cdr)
            return odometry ? cdr::decode_odometry(bytes) : cdr::decode_pose_stamped(bytes);
        return odometry ? ros1::decode_odometry(bytes) : ros1::decode_pose_stamped(bytes);
    });
}

std::vector<StampedTransform> BagReader::transforms(std::size_t t, std::size_t k) const {
    expect(t, k, MessageKind::tf);
    return decoded(*this, t, k, [&] {
        const auto bytes = serialized(t, k);
        return topics_[t].encoding == MessageEncoding::cdr ? cdr::decode_tf(bytes) : ros1::decode_tf(bytes);
    });
}

std::unique_ptr<BagReader> open_bag(const fs::path& path) {
    std::error_code ec;
    if (!fs::exists(path, ec)) throw InputError("bag '" + path.string() + "' does not exist");
    if (fs::is_directory(path, ec)) return open_ros2_bag(path);
    std::string ext = path.extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
    if (ext == ".mcap") return open_mcap(path);
    if (path.filename() == "metadata.yaml") return open_ros2_bag(path.has_parent_path() ? path.parent_path() : ".");
    if (ext == ".db3") return open_ros2_storage(path);  // a storage file alone, without its metadata
    if (ext == ".zstd")
        throw InputError(quoted_path(path) +
                         " is a zstd-compressed storage file of a ROS 2 bag: give the bag's "
                         "folder (its metadata.yaml says how it is compressed)");
    return open_ros1_bag(path);
}

}  // namespace bvc3d::recording
