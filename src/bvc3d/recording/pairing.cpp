#include "bvc3d/recording/pairing.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numeric>
#include <string>

#include "bvc3d/core/error.hpp"
#include "bvc3d/recording/parsing.hpp"

namespace bvc3d::recording {

namespace {

bool all_timed(const std::vector<std::optional<double>>& scan_times) {
    return std::all_of(scan_times.begin(), scan_times.end(), [](const auto& t) { return t.has_value(); });
}

bool all_timed(const std::vector<PoseRecord>& poses) {
    return std::all_of(poses.begin(), poses.end(), [](const PoseRecord& p) { return p.time.has_value(); });
}

// A time exactly; a gap or a tolerance to 4 significant digits.
std::string seconds(double t) {
    std::string text;
    detail::append_number(text, t);
    return text + " s";
}

std::string short_seconds(double t) {
    char text[32];
    std::snprintf(text, sizeof text, "%.4g s", t);
    return text;
}

// Sorting and searching need real numbers (the file readers never give NaN/inf times).
void check_finite_times(const std::vector<std::optional<double>>& scan_times, const std::vector<PoseRecord>& poses) {
    for (std::size_t i = 0; i < scan_times.size(); ++i)
        if (!std::isfinite(*scan_times[i]))
            throw InputError("cannot pair scans with poses: scan " + std::to_string(i) + " has a non-finite time");
    for (std::size_t i = 0; i < poses.size(); ++i)
        if (!std::isfinite(*poses[i].time))
            throw InputError("cannot pair scans with poses: pose " + std::to_string(i) + " has a non-finite time");
}

// Pose indices sorted by time: a scan's nearest pose is then a binary search away.
std::vector<std::size_t> poses_by_time(const std::vector<PoseRecord>& poses) {
    std::vector<std::size_t> order(poses.size());
    std::iota(order.begin(), order.end(), std::size_t{0});
    std::stable_sort(order.begin(), order.end(),
                     [&](std::size_t a, std::size_t b) { return *poses[a].time < *poses[b].time; });
    return order;
}

std::size_t nearest_pose(const std::vector<PoseRecord>& poses, const std::vector<std::size_t>& by_time, double t) {
    const auto after = std::lower_bound(by_time.begin(), by_time.end(), t,
                                        [&](std::size_t pose, double time) { return *poses[pose].time < time; });
    if (after == by_time.begin()) return *after;
    if (after == by_time.end()) return by_time.back();
    const std::size_t before = *(after - 1);
    return t - *poses[before].time <= *poses[*after].time - t ? before : *after;
}

std::string missing_times(const std::vector<std::optional<double>>& scan_times, const std::vector<PoseRecord>& poses) {
    const bool scans = all_timed(scan_times), pose_times = all_timed(poses);
    if (!scans && !pose_times) return "neither the scans nor the poses have times";
    return !scans ? "the scans have no times" : "the poses have no times";
}

}  // namespace

ScanPosePairing pair_scans_with_poses(const std::vector<std::optional<double>>& scan_times,
                                      const std::vector<PoseRecord>& poses, double tolerance) {
    if (!(tolerance >= 0)) throw InputError("pairing scans with poses: the time tolerance must be >= 0");
    ScanPosePairing pairing;
    if (scan_times.size() == poses.size()) {
        pairing.pose_of_scan.resize(poses.size());
        std::iota(pairing.pose_of_scan.begin(), pairing.pose_of_scan.end(), std::size_t{0});
        return pairing;
    }
    const std::string counts =
        std::to_string(scan_times.size()) + " scans but " + std::to_string(poses.size()) + " poses";
    if (poses.empty()) throw InputError("cannot pair scans with poses: " + counts);
    if (!all_timed(scan_times) || !all_timed(poses))
        throw InputError("cannot pair scans with poses: the counts differ (" + counts +
                         ") and no times are available to pair them (" + missing_times(scan_times, poses) + ")");
    return pair_scans_with_poses_by_time(scan_times, poses, tolerance);
}

ScanPosePairing pair_scans_with_poses_by_time(const std::vector<std::optional<double>>& scan_times,
                                              const std::vector<PoseRecord>& poses, double tolerance) {
    if (!(tolerance >= 0)) throw InputError("pairing scans with poses: the time tolerance must be >= 0");
    if (poses.empty()) throw InputError("cannot pair scans with poses: there are no poses");
    if (!all_timed(scan_times) || !all_timed(poses))
        throw InputError("cannot pair scans with poses by time: " + missing_times(scan_times, poses));
    ScanPosePairing pairing;
    check_finite_times(scan_times, poses);
    pairing.by_time = true;
    const std::vector<std::size_t> by_time = poses_by_time(poses);
    for (std::size_t scan = 0; scan < scan_times.size(); ++scan) {
        const double t = *scan_times[scan];
        const std::size_t pose = nearest_pose(poses, by_time, t);
        const double gap = std::abs(*poses[pose].time - t);
        if (!(gap <= tolerance))
            throw InputError("cannot pair scan " + std::to_string(scan) + " (time " + seconds(t) +
                             ") with a pose: the nearest pose time is " + seconds(*poses[pose].time) + ", " +
                             short_seconds(gap) + " away (tolerance " + short_seconds(tolerance) + ")");
        pairing.pose_of_scan.push_back(pose);
    }
    return pairing;
}

}  // namespace bvc3d::recording
