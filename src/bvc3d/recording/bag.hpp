#pragma once
// Bags: the recordings of ROS. Takes: a ROS 1 `.bag` file (read by Debian's rosbag storage library),
// an `.mcap` file, or a ROS 2 bag folder (its metadata.yaml and `.db3` files, SQLite, or `.mcap`
// files). Gives: the topics (name, type, encoding, count, time span) and any message of a topic,
// by its index in the topic (log-time order), decoded into the structs of ros_messages.hpp.
// Errors (InputError) name the file, the topic, the message index and the reason.
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "bvc3d/recording/ros_messages.hpp"

namespace bvc3d::recording {

enum class MessageEncoding { ros1, cdr, unknown };

struct BagTopic {
    std::string name;
    std::string type;  // as the bag writes it: "sensor_msgs/PointCloud2" or "sensor_msgs/msg/PointCloud2"
    MessageEncoding encoding = MessageEncoding::ros1;
    std::string encoding_name = "ros1";  // as the bag names it ("ros1", "cdr", "json", ...)
    std::size_t count = 0;
    double first = 0, last = 0;  // log (receive) times of the first and last message, s
};

// "'<path>'" for messages (built so that GCC 12's -Wrestrict false positive on "'" + string&& stays quiet).
std::string quoted_path(const std::filesystem::path& path);

// The message types bvc3d reads, whatever the ROS version spells them.
enum class MessageKind { point_cloud2, odometry, pose_stamped, tf, other };
MessageKind message_kind(const std::string& type);

class BagReader {
public:
    virtual ~BagReader() = default;
    const std::filesystem::path& path() const { return path_; }
    virtual std::string format() const = 0;  // "ROS 1 bag", "ROS 2 bag (sqlite3)", "MCAP", ...
    const std::vector<BagTopic>& topics() const { return topics_; }
    // The topic's index; an InputError listing the bag's topics when it has none of that name.
    std::size_t topic(const std::string& name) const;

    // Message k of topic t (index into topics()), decoded. The topic must be of the right kind
    // (else an InputError naming its type). Safe to call from several threads.
    CloudMessage cloud(std::size_t t, std::size_t k) const;
    StampedTransform pose(std::size_t t, std::size_t k) const;                     // Odometry or PoseStamped
    std::vector<StampedTransform> transforms(std::size_t t, std::size_t k) const;  // TFMessage

    // "'<file>', topic '/points', message 12": where an error is.
    std::string where(std::size_t t, std::size_t k) const;

    // Message k of topic t as serialized in the bag (ROS 1 serialization, or CDR with its header);
    // k < topics()[t].count.
    virtual std::vector<std::uint8_t> serialized(std::size_t t, std::size_t k) const = 0;

protected:
    explicit BagReader(std::filesystem::path path) : path_(std::move(path)) {}
    std::vector<BagTopic> topics_;

private:
    void expect(std::size_t t, std::size_t k, MessageKind kind) const;
    std::filesystem::path path_;
};

// Opens a bag by what `path` is: a folder (ROS 2), its metadata.yaml, a `.db3` or `.mcap` file, or a
// ROS 1 bag.
std::unique_ptr<BagReader> open_bag(const std::filesystem::path& path);

// The three kinds, for tests and tools that know which they have.
std::unique_ptr<BagReader> open_ros1_bag(const std::filesystem::path& file);
std::unique_ptr<BagReader> open_mcap(const std::filesystem::path& file);
// A folder: with metadata.yaml as it says (zstd FILE or MESSAGE compression undone); without, from its
// .db3 or .mcap files (as `ros2 bag reindex` would). A storage file alone (.db3 or .mcap).
std::unique_ptr<BagReader> open_ros2_bag(const std::filesystem::path& folder);
std::unique_ptr<BagReader> open_ros2_storage(const std::filesystem::path& file);

// ROS 1 serialization of the same messages (through the Debian message packages' own code). The
// generated ROS 1 headers need C++17 (std::allocator<void>::rebind), so only ros1_bag.cpp, compiled
// as C++17, includes them; this header stays within C++17 for it.
namespace ros1 {
CloudMessage decode_cloud(const std::vector<std::uint8_t>& bytes);
StampedTransform decode_odometry(const std::vector<std::uint8_t>& bytes);
StampedTransform decode_pose_stamped(const std::vector<std::uint8_t>& bytes);
std::vector<StampedTransform> decode_tf(const std::vector<std::uint8_t>& bytes);
// A bag of cloud i on `cloud_topic`, transforms[i] as nav_msgs/Odometry on `odom_topic` and as a
// TFMessage on /tf, all logged at the cloud's stamp, chunks compressed with lz4. Writes `file` as
// it goes: the caller writes to a temporary name.
void write_bag(const std::filesystem::path& file, const std::vector<CloudMessage>& clouds,
               const std::vector<StampedTransform>& transforms, const std::string& cloud_topic,
               const std::string& odom_topic);
}  // namespace ros1

}  // namespace bvc3d::recording
