#pragma once
// A bag as a recording (docs/ros.md). Takes: a bag (bag.hpp), its cloud topic and a pose source —
// a topic of nav_msgs/Odometry or geometry_msgs/PoseStamped, or the tf tree from a fixed frame to
// the clouds' frame. Gives: a Recording whose scans are the clouds (loaded on demand) and whose
// poses are paired by time as SPEC §11 pairs them: each cloud's header stamp with the pose nearest
// in time within the time tolerance (a pose topic), or the tf chain interpolated at that stamp
// (tf). Extrinsics apply as for scan files. Errors name the file, topic, message index and reason:
// missing topics, wrong types, clouds whose stamps do not increase, clouds in another frame than
// the tf sensor frame, poses out of order, tf gaps.
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "bvc3d/recording/bag.hpp"
#include "bvc3d/recording/recording.hpp"

namespace bvc3d::recording {

struct BagSource {
    std::filesystem::path bag;
    std::string cloud_topic;
    std::string pose_topic;           // nav_msgs/Odometry or geometry_msgs/PoseStamped; or
    std::string tf_fixed, tf_sensor;  // the tf chain fixed ← sensor (the clouds' frame)
    double tf_tolerance = 0.2;        // s: the largest gap between a tf link's samples around a stamp
    bool uses_tf() const { return !tf_fixed.empty(); }
};

// "FIXED,SENSOR" → the two frames; an InputError otherwise.
void parse_tf_frames(const std::string& text, BagSource& source);

// The recording; `options`' time tolerance pairs clouds with poses, its extrinsics (base_from_sensor)
// apply to the poses; its pose format is not used.
Recording open_bag_recording(const BagSource& source, const RecordingOptions& options = {});
// The same on a bag already open (the reader is kept for loading the clouds).
Recording open_bag_recording(std::shared_ptr<const BagReader> bag, const BagSource& source,
                             const RecordingOptions& options = {});

// Each message's header stamp (s) and frame of a topic whose messages start with a std_msgs/Header.
struct MessageHeader {
    double stamp = 0;
    std::string frame_id;
};
MessageHeader message_header(const BagReader& bag, std::size_t topic, std::size_t k);

}  // namespace bvc3d::recording
