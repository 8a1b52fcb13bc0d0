#pragma once
// The tf tree of a bag or of a live robot: frames linked child → parent by stamped transforms
// (tf2_msgs/TFMessage on /tf, timeless ones on /tf_static). Takes: transforms, in any order. Gives:
// fixed_from_frame at any time, composed along the chain from the frame up to the fixed frame, each
// link interpolated at that time between its two samples around it (translation linearly, rotation
// by slerp). Refused (InputError naming the frames, the time and the gap): a link whose samples
// around the time are further apart than the tolerance, a time further than the tolerance before
// the first or after the last sample of a link, a frame with two parents, a chain that does not
// reach the fixed frame.
#include <Eigen/Geometry>
#include <map>
#include <string>
#include <vector>

#include "bvc3d/recording/ros_messages.hpp"

namespace bvc3d::recording {

class TfTree {
public:
    // Frames are compared without leading slashes. A static transform is valid at every time.
    void add(const StampedTransform& transform, bool is_static);
    // fixed_from_frame at `time` (s); `tolerance` (s) bounds the gap between a link's samples. With
    // `hold_ends` false, a time after a link's last sample is an error whatever the tolerance (a live
    // node: the sample that brackets it may still be on its way).
    Eigen::Isometry3d lookup(const std::string& fixed, const std::string& frame, double time, double tolerance,
                             bool hold_ends = true) const;
    // Samples older than `time` (s) are forgotten, but for each link's last one before it (a live
    // node's buffer).
    void forget_before(double time);
    std::size_t links() const { return links_.size(); }

private:
    struct Sample {
        double stamp;
        Eigen::Vector3d translation;
        Eigen::Quaterniond rotation;
    };
    struct Link {
        std::string parent;
        bool is_static = false;
        std::vector<Sample> samples;  // by stamp
    };
    Eigen::Isometry3d at(const std::string& child, const Link& link, double time, double tolerance,
                         bool hold_ends) const;
    std::map<std::string, Link> links_;  // by child frame
};

}  // namespace bvc3d::recording
