#pragma once
// Geometry shared by every stage: vectors and the pose of an agent or a sensor in the world frame
// (x east, y north, z up; docs/model-reference.md#conventions).
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <string>

namespace bvc3d {

using Vec2 = Eigen::Vector2d;
using Vec3 = Eigen::Vector3d;

// A rigid pose. Orientation: heading (yaw, from +x counter-clockwise), then pitch (nose up
// positive), then roll about the forward axis: R = Rz(heading)·Ry(−pitch)·Rx(roll), so the forward
// axis R·x̂ is (cos p·cos h, cos p·sin h, sin p). A ground robot stands level on the floor:
// Pose::on_floor(x, y, heading) has z = pitch = roll = 0.
struct Pose {
    double x = 0.0, y = 0.0, z = 0.0;               // m
    double heading = 0.0, pitch = 0.0, roll = 0.0;  // rad

    static Pose on_floor(double x, double y, double heading) { return Pose{x, y, 0.0, heading, 0.0, 0.0}; }
    // The pose with this rotation; heading is the yaw of the forward axis projected on the floor.
    static Pose from_rotation(const Vec3& position, const Eigen::Matrix3d& rotation);

    Vec3 position() const { return {x, y, z}; }
    bool level() const { return pitch == 0.0 && roll == 0.0; }
    bool finite() const;
    Eigen::Matrix3d rotation() const;
};

// "(x, y)" with each number as format_number writes it, for messages that name a point.
std::string point_text(const Vec2& p);

}  // namespace bvc3d
