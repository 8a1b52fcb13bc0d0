#pragma once
// Which pose goes with which scan. Takes: each scan's time (if known) and the poses. Gives: the
// index of each scan's pose.
//  - Equal counts: scan i gets pose i (times, if any, are not consulted).
//  - Otherwise, when every scan and every pose has a time: each scan gets the pose nearest in
//    time; none within `tolerance` seconds is an InputError naming the scan and the nearest pose
//    time.
//  - Otherwise: an InputError saying the counts differ and no times are there to pair them by.
#include <cstddef>
#include <optional>
#include <vector>

#include "bvc3d/recording/pose_file.hpp"

namespace bvc3d::recording {

struct ScanPosePairing {
    std::vector<std::size_t> pose_of_scan;  // index into the poses, one per scan
    bool by_time = false;                   // false: in order
};

ScanPosePairing pair_scans_with_poses(const std::vector<std::optional<double>>& scan_times,
                                      const std::vector<PoseRecord>& poses, double tolerance = 0.05);

// Each scan with the pose nearest in time, whatever the counts (a bag's scans and poses always have
// times); every scan and pose needs one. Errors as above.
ScanPosePairing pair_scans_with_poses_by_time(const std::vector<std::optional<double>>& scan_times,
                                              const std::vector<PoseRecord>& poses, double tolerance = 0.05);

}  // namespace bvc3d::recording
