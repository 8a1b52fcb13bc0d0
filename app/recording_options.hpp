#pragma once
// Command-line options for reading a recording (--scans, --poses and how to pair and preprocess
// them), shared by the commands that take one (replay, localize, map, choose-elevations).
#include <filesystem>
#include <memory>
#include <optional>
#include <string>

#include <CLI/CLI.hpp>

#include "bvc3d/core/angles.hpp"
#include "bvc3d/core/error.hpp"
#include "bvc3d/recording/extrinsics.hpp"
#include "bvc3d/recording/recording.hpp"
#include "bvc3d/sensor/recorded_returns.hpp"

namespace bvc3d::cli {

// Where scans and poses are, and how to read them.
struct RecordingOptions {
    std::string pose_format = "auto", extrinsics;
    double time_tolerance = 0.05;

    void add_to(CLI::App& cmd) {
        cmd.add_option("--pose-format", pose_format, "Pose file format: auto, kitti, tum or matrix (4x4 rows)")
            ->capture_default_str();
        cmd.add_option(
            "--extrinsics", extrinsics,
            "Sensor mounting (base-from-sensor): a file, or 12 or 16 numbers; the poses are then the base's");
        cmd.add_option("--time-tolerance", time_tolerance, "Seconds within which a scan pairs with a pose by time")
            ->capture_default_str();
    }
    std::shared_ptr<const recording::Recording> open(const std::string& scans, const std::string& poses) const {
        if (poses.empty()) throw InputError("the scans '" + scans + "' need a pose file");
        recording::RecordingOptions o;
        o.pose_format = recording::parse_pose_format(pose_format);
        o.time_tolerance = time_tolerance;
        if (!extrinsics.empty()) {
            std::error_code ec;
            o.base_from_sensor = std::filesystem::is_regular_file(extrinsics, ec)
                                     ? recording::read_extrinsics(extrinsics)
                                     : recording::parse_extrinsics(extrinsics, "--extrinsics");
        }
        return std::make_shared<const recording::Recording>(recording::open_recording(scans, poses, o));
    }
};

// The preprocessing of recorded scans.
struct PreprocessOptions {
    RecordedReturnParams params;
    std::optional<double> slice_deg;

    void add_to(CLI::App& cmd) {
        cmd.add_option("--min-range", params.min_range, "m: nearer points are dropped")->capture_default_str();
        cmd.add_option("--max-range", params.max_range, "m: farther points are dropped")->capture_default_str();
        cmd.add_option("--slice-half-width-deg", slice_deg,
                       "The 2-D models read the returns within this many degrees of the horizontal (default 1)");
    }
    RecordedReturnParams get() const {
        RecordedReturnParams p = params;
        if (slice_deg) p.slice_half_width = deg_to_rad(*slice_deg);
        p.validate();
        return p;
    }
};

}  // namespace bvc3d::cli
