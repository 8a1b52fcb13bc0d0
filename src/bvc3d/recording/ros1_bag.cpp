// ROS 1 bags through Debian's rosbag storage library (librosbag-storage-dev), and ROS 1 messages through
// the Debian message packages' generated code (libsensor-msgs-dev, libnav-msgs-dev, libgeometry-msgs-dev,
// libtf2-msgs-dev): the library reads the file format (chunks, bz2/lz4 compression, indexes), the
// generated code the messages.
#include <geometry_msgs/PoseStamped.h>
#include <nav_msgs/Odometry.h>
#include <rosbag/bag.h>
#include <rosbag/exceptions.h>
#include <rosbag/view.h>
#include <sensor_msgs/PointCloud2.h>
#include <tf2_msgs/TFMessage.h>

#include <map>
#include <mutex>

#include "bvc3d/core/error.hpp"
#include "bvc3d/recording/bag.hpp"
#include "bvc3d/recording/ros1_framing.hpp"

namespace bvc3d::recording {

namespace ros1 {

namespace {

// The lengths a ROS 1 message claims, checked against its bytes before the generated code reads it:
// that code sizes each array from its claim before it reads (a corrupt claim of 4 GB is 4 GB allocated).
class LengthCheck {
public:
    explicit LengthCheck(const std::vector<std::uint8_t>& bytes) : bytes_(bytes) {}
    void skip(std::size_t n) {
        if (n > bytes_.size() - pos_)
            throw InputError("the message is truncated or corrupt (" + std::to_string(n) + " bytes claimed at byte " +
                             std::to_string(pos_) + ", " + std::to_string(bytes_.size() - pos_) + " left)");
        pos_ += n;
    }
    std::uint32_t u32() {
        const std::size_t at = pos_;
        skip(4);
        return static_cast<std::uint32_t>(bytes_[at] | bytes_[at + 1] << 8 | bytes_[at + 2] << 16 |
                                          static_cast<std::uint32_t>(bytes_[at + 3]) << 24);
    }
    void string() { skip(u32()); }
    void header() {
        skip(12);  // seq, stamp
        string();  // frame_id
    }
    // A count of elements of at least `min_bytes` each, checked against what is left.
    std::uint32_t count(std::size_t min_bytes) {
        const std::uint32_t n = u32();
        if (n > (bytes_.size() - pos_) / min_bytes) skip(std::size_t{n} * min_bytes);  // throws with the numbers
        return n;
    }

private:
    const std::vector<std::uint8_t>& bytes_;
    std::size_t pos_ = 0;
};

void check_lengths(const sensor_msgs::PointCloud2*, LengthCheck& c) {
    c.header();
    c.skip(8);  // height, width
    for (std::uint32_t n = c.count(13), i = 0; i < n; ++i) {
        c.string();
        c.skip(9);  // offset, datatype, count
    }
    c.skip(9);           // is_bigendian, point_step, row_step
    c.skip(c.count(1));  // data
}
void check_lengths(const nav_msgs::Odometry*, LengthCheck& c) {
    c.header();
    c.string();
}
void check_lengths(const geometry_msgs::PoseStamped*, LengthCheck& c) { c.header(); }
void check_lengths(const tf2_msgs::TFMessage*, LengthCheck& c) {
    for (std::uint32_t n = c.count(16 + 4 + 56), i = 0; i < n; ++i) {
        c.header();
        c.string();
        c.skip(56);
    }
}

template <class M>
M deserialize(const std::vector<std::uint8_t>& bytes) {
    LengthCheck check(bytes);
    check_lengths(static_cast<const M*>(nullptr), check);
    M msg;
    try {
        ros::serialization::IStream in(const_cast<std::uint8_t*>(bytes.data()),
                                       static_cast<std::uint32_t>(bytes.size()));
        ros::serialization::deserialize(in, msg);
    } catch (const ros::Exception& e) {
        throw InputError(std::string("the message is truncated or corrupt (") + e.what() + ")");
    }
    return msg;
}

double seconds(const ros::Time& t) { return t.sec + t.nsec * 1e-9; }

void copy_pose(const geometry_msgs::Point& p, const geometry_msgs::Quaternion& q, StampedTransform& t) {
    t.translation = Eigen::Vector3d(p.x, p.y, p.z);
    t.rotation = Eigen::Quaterniond(q.w, q.x, q.y, q.z);
}

}  // namespace

CloudMessage decode_cloud(const std::vector<std::uint8_t>& bytes) {
    auto m = deserialize<sensor_msgs::PointCloud2>(bytes);
    const double stamp = seconds(m.header.stamp);
    return cloud_message_of(std::move(m), stamp);
}

StampedTransform decode_odometry(const std::vector<std::uint8_t>& bytes) {
    const auto m = deserialize<nav_msgs::Odometry>(bytes);
    StampedTransform t;
    t.stamp = seconds(m.header.stamp);
    t.parent = m.header.frame_id;
    t.child = m.child_frame_id;
    copy_pose(m.pose.pose.position, m.pose.pose.orientation, t);
    return t;
}

StampedTransform decode_pose_stamped(const std::vector<std::uint8_t>& bytes) {
    const auto m = deserialize<geometry_msgs::PoseStamped>(bytes);
    StampedTransform t;
    t.stamp = seconds(m.header.stamp);
    t.parent = m.header.frame_id;
    copy_pose(m.pose.position, m.pose.orientation, t);
    return t;
}

std::vector<StampedTransform> decode_tf(const std::vector<std::uint8_t>& bytes) {
    const auto m = deserialize<tf2_msgs::TFMessage>(bytes);
    std::vector<StampedTransform> out;
    for (const auto& ts : m.transforms) {
        StampedTransform t;
        t.stamp = seconds(ts.header.stamp);
        t.parent = ts.header.frame_id;
        t.child = ts.child_frame_id;
        const auto& v = ts.transform.translation;
        const auto& q = ts.transform.rotation;
        t.translation = Eigen::Vector3d(v.x, v.y, v.z);
        t.rotation = Eigen::Quaterniond(q.w, q.x, q.y, q.z);
        out.push_back(t);
    }
    return out;
}

void write_bag(const std::filesystem::path& file, const std::vector<CloudMessage>& clouds,
               const std::vector<StampedTransform>& transforms, const std::string& cloud_topic,
               const std::string& odom_topic) {
    try {
        rosbag::Bag bag;
        bag.open(file.string(), rosbag::bagmode::Write);
        bag.setCompression(rosbag::compression::LZ4);
        for (std::size_t i = 0; i < clouds.size(); ++i) {
            const CloudMessage& c = clouds[i];
            const StampedTransform& t = transforms[i];
            ros::Time time;
            time.fromSec(c.stamp);
            std_msgs::Header header;
            header.seq = static_cast<std::uint32_t>(i);
            header.stamp = time;
            sensor_msgs::PointCloud2 pc;
            pc.header = header;
            pc.header.frame_id = c.frame_id;
            pc.height = c.height;
            pc.width = c.width;
            for (const auto& f : c.fields) {
                sensor_msgs::PointField pf;
                pf.name = f.name;
                pf.offset = f.offset;
                pf.datatype = f.datatype;
                pf.count = f.count;
                pc.fields.push_back(pf);
            }
            pc.is_bigendian = c.is_bigendian;
            pc.point_step = c.point_step;
            pc.row_step = c.row_step;
            pc.data = c.data;
            pc.is_dense = true;
            geometry_msgs::Quaternion q;
            q.x = t.rotation.x();
            q.y = t.rotation.y();
            q.z = t.rotation.z();
            q.w = t.rotation.w();
            nav_msgs::Odometry odom;
            odom.header = header;
            odom.header.frame_id = t.parent;
            odom.child_frame_id = t.child;
            odom.pose.pose.position.x = t.translation.x();
            odom.pose.pose.position.y = t.translation.y();
            odom.pose.pose.position.z = t.translation.z();
            odom.pose.pose.orientation = q;
            geometry_msgs::TransformStamped ts;
            ts.header = odom.header;
            ts.child_frame_id = t.child;
            ts.transform.translation.x = t.translation.x();
            ts.transform.translation.y = t.translation.y();
            ts.transform.translation.z = t.translation.z();
            ts.transform.rotation = q;
            tf2_msgs::TFMessage tf;
            tf.transforms.push_back(ts);
            bag.write("/tf", time, tf);
            bag.write(odom_topic, time, odom);
            bag.write(cloud_topic, time, pc);
        }
        bag.close();
    } catch (const ros::Exception& e) {
        throw InputError(quoted_path(file) + ": cannot write the bag (" + e.what() + ")");
    }
}

}  // namespace ros1

namespace {

// The MD5 sum of each message type bvc3d decodes: a bag whose definition differs (another version
// of the message) cannot be read with this one's code.
std::string expected_md5(MessageKind kind) {
    using namespace ros::message_traits;
    switch (kind) {
        case MessageKind::point_cloud2:
            return MD5Sum<sensor_msgs::PointCloud2>::value();
        case MessageKind::odometry:
            return MD5Sum<nav_msgs::Odometry>::value();
        case MessageKind::pose_stamped:
            return MD5Sum<geometry_msgs::PoseStamped>::value();
        case MessageKind::tf:
            return MD5Sum<tf2_msgs::TFMessage>::value();
        case MessageKind::other:
            break;
    }
    return "";
}

class Ros1Bag : public BagReader {
public:
    explicit Ros1Bag(const std::filesystem::path& file) : BagReader(file) {
        std::error_code ec;
        if (!std::filesystem::is_regular_file(file, ec)) throw InputError(quoted_path(file) + " is not a file");
        ros1::check_framing(file);
        try {
            bag_.open(file.string(), rosbag::bagmode::Read);
            rosbag::View all(bag_);
            std::map<std::string, std::size_t> index;
            for (const rosbag::MessageInstance& m : all) {
                auto [it, fresh] = index.emplace(m.getTopic(), topics_.size());
                if (fresh) {
                    BagTopic t;
                    t.name = m.getTopic();
                    t.type = m.getDataType();
                    t.first = m.getTime().toSec();
                    topics_.push_back(t);
                    messages_.emplace_back();
                    md5_.push_back(m.getMD5Sum());
                }
                BagTopic& t = topics_[it->second];
                if (m.getDataType() != t.type)
                    throw InputError(quoted_path(file) + ", topic '" + t.name + "', message " +
                                     std::to_string(t.count) + ": type " + m.getDataType() +
                                     " where the topic's earlier messages are " + t.type);
                t.last = m.getTime().toSec();
                ++t.count;
                messages_[it->second].push_back(m);
            }
        } catch (const ros::Exception& e) {  // rosbag::BagException and the serializers' exceptions
            throw InputError(quoted_path(file) + ": not a readable ROS 1 bag (" + e.what() + ")");
        }
    }
    std::string format() const override { return "ROS 1 bag"; }

    std::vector<std::uint8_t> serialized(std::size_t t, std::size_t k) const override {
        const MessageKind kind = message_kind(topics_[t].type);
        if (kind != MessageKind::other && md5_[t] != "*" && md5_[t] != expected_md5(kind))
            throw InputError("unknown message encoding: " + topics_[t].type + " with MD5 " + md5_[t] +
                             " (this build reads the definition with MD5 " + expected_md5(kind) + ")");
        const std::lock_guard lock(mutex_);  // the bag's file is one stream
        try {
            const rosbag::MessageInstance& m = messages_[t][k];
            std::vector<std::uint8_t> bytes(m.size());
            ros::serialization::OStream out(bytes.data(), static_cast<std::uint32_t>(bytes.size()));
            m.write(out);
            return bytes;
        } catch (const ros::Exception& e) {
            throw InputError(std::string("the bag's data is truncated or corrupt (") + e.what() + ")");
        }
    }

private:
    rosbag::Bag bag_;
    std::vector<std::vector<rosbag::MessageInstance>> messages_;  // per topic, in log-time order
    std::vector<std::string> md5_;
    mutable std::mutex mutex_;
};

}  // namespace

std::unique_ptr<BagReader> open_ros1_bag(const std::filesystem::path& file) { return std::make_unique<Ros1Bag>(file); }

}  // namespace bvc3d::recording
