#include "bvc3d/core/geometry.hpp"

#include <cmath>

#include "bvc3d/core/format.hpp"

namespace bvc3d {

Pose Pose::from_rotation(const Vec3& p, const Eigen::Matrix3d& R) {
    // Column 0 is the forward axis (cos p cos h, cos p sin h, sin p); row 2 is (sin p, cos p sin r, cos p cos r).
    Pose pose{p.x(), p.y(), p.z(), std::atan2(R(1, 0), R(0, 0)), 0.0, 0.0};
    pose.pitch = std::atan2(R(2, 0), std::hypot(R(0, 0), R(1, 0)));
    pose.roll = std::atan2(R(2, 1), R(2, 2));
    return pose;
}

bool Pose::finite() const {
    return std::isfinite(x) && std::isfinite(y) && std::isfinite(z) && std::isfinite(heading) && std::isfinite(pitch) &&
           std::isfinite(roll);
}

Eigen::Matrix3d Pose::rotation() const {
    return (Eigen::AngleAxisd(heading, Vec3::UnitZ()) * Eigen::AngleAxisd(-pitch, Vec3::UnitY()) *
            Eigen::AngleAxisd(roll, Vec3::UnitX()))
        .toRotationMatrix();
}

std::string point_text(const Vec2& p) {
    std::string text = "(";  // appended, not "(" + ...: g++ 12 warns falsely on that (-Wrestrict, GCC bug 105329)
    text += format_number(p.x());
    text += ", ";
    text += format_number(p.y());
    return text + ")";
}

}  // namespace bvc3d
