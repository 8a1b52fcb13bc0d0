#pragma once
// The ROS messages a recording reads from a bag, as plain structs whatever the bag's encoding (ROS 1
// serialization or ROS 2's CDR): sensor_msgs/PointCloud2, the poses of nav_msgs/Odometry and
// geometry_msgs/PoseStamped, and the transforms of tf2_msgs/TFMessage. Takes: decoded fields.
// Gives: a cloud's x, y, z as a PointCloud (fields x, y, z of float32 or float64 at any offset and
// point step, other fields ignored, either byte order, organised or not, non-finite points dropped)
// and stamped rigid transforms. Errors (InputError) say what is wrong; the caller prefixes where.
#include <Eigen/Geometry>
#include <cstdint>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "bvc3d/recording/point_cloud.hpp"

namespace bvc3d::recording {

// sensor_msgs/PointField's datatype codes.
enum class PointFieldType : std::uint8_t {
    int8 = 1,
    uint8 = 2,
    int16 = 3,
    uint16 = 4,
    int32 = 5,
    uint32 = 6,
    float32 = 7,
    float64 = 8
};

struct PointFieldInfo {
    std::string name;
    std::uint32_t offset = 0;
    std::uint8_t datatype = 0;
    std::uint32_t count = 1;
};

struct CloudMessage {
    double stamp = 0;  // header.stamp, seconds
    std::string frame_id;
    std::uint32_t height = 0, width = 0;
    std::vector<PointFieldInfo> fields;
    bool is_bigendian = false;
    std::uint32_t point_step = 0, row_step = 0;
    std::vector<std::uint8_t> data;
};

// A ROS 1 sensor_msgs/PointCloud2 (the library's bag reader's and the node's: any type with its members) as a
// CloudMessage, its header's stamp given in seconds; the data moved when `m` is an rvalue.
template <class PointCloud2>
CloudMessage cloud_message_of(PointCloud2&& m, double stamp) {
    CloudMessage c;
    c.stamp = stamp;
    c.frame_id = m.header.frame_id;
    c.height = m.height;
    c.width = m.width;
    for (const auto& f : m.fields) c.fields.push_back({f.name, f.offset, f.datatype, f.count});
    c.is_bigendian = m.is_bigendian;
    c.point_step = m.point_step;
    c.row_step = m.row_step;
    c.data = std::forward<PointCloud2>(m).data;
    return c;
}

// A rigid transform at a time: parent_from_child (the pose of `child` in `parent`), as nav_msgs/Odometry
// (header.frame_id ← child_frame_id), geometry_msgs/PoseStamped (header.frame_id ← the pose's own
// frame, child empty) and each geometry_msgs/TransformStamped of a tf message give it.
struct StampedTransform {
    double stamp = 0;
    std::string parent, child;
    Eigen::Vector3d translation = Eigen::Vector3d::Zero();
    Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();  // as stored (normalised by the users)
};

// The points of a cloud in its frame. Errors: no x, y or z field, a field that is not float32 or
// float64 or has count 0, a field that does not fit in the point step, data shorter than
// height × row_step or a row_step shorter than width × point_step, and a cloud with no finite point.
PointCloud cloud_points(const CloudMessage& cloud);

// A frame name as tf compares it: without leading slashes.
std::string_view bare_frame(std::string_view frame);

// The rotation of `q`, normalised; an InputError when its norm is not within 1e-3 of 1 (or is not finite).
Eigen::Quaterniond checked_rotation(const Eigen::Quaterniond& q);

}  // namespace bvc3d::recording
