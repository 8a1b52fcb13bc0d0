#pragma once
// A recording: scans in order, each with its pose and time (docs/recordings.md). Takes: a scan
// folder or list, a pose file, and how to read and pair them (or a bag: bag_recording.hpp). Gives:
// the paired recording, each scan's points on demand from its store (scan files, a bag's clouds),
// and writing a recording (scans and poses) into a folder.
#include <Eigen/Geometry>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "bvc3d/recording/point_cloud.hpp"
#include "bvc3d/recording/pose_file.hpp"
#include "bvc3d/recording/scan_list.hpp"

namespace bvc3d::recording {

struct RecordingOptions {
    PoseFormat pose_format = PoseFormat::detect;
    double time_tolerance = 0.05;                       // s, for pairing by time
    std::optional<Eigen::Isometry3d> base_from_sensor;  // extrinsics: poses are the base's when given
};

// Where a recording's points come from: scan files, or the cloud messages of a bag.
class ScanStore {
public:
    virtual ~ScanStore() = default;
    // Scan i's points in its sensor frame; errors name the file (and topic, message). Thread-safe.
    virtual PointCloud load(std::size_t i) const = 0;
    // Text that changes when the data does (see Recording::fingerprint).
    virtual std::string fingerprint() const = 0;
    // A short name of scan i for people: its file's name, or its topic and message index.
    virtual std::string scan_name(std::size_t i) const = 0;
};

struct Recording {
    std::string name;  // the scan folder's name (a list file's: the folder holding it; one scan's: its stem)
    std::filesystem::path scans_source, poses_source;  // a bag's: "<bag>:<topic>" (or ":tf FIXED SENSOR")
    std::shared_ptr<const ScanStore> store;
    std::vector<ScanEntry> scans;   // in recording order (a bag's: the bag's path and the cloud's stamp)
    std::vector<PoseRecord> poses;  // world_from_sensor of each scan (paired, extrinsics applied)
    bool paired_by_time = false;

    std::size_t size() const { return scans.size(); }
    // Scan i's points in its sensor frame. Errors name the scan's index and file.
    PointCloud load(std::size_t i) const;
    // Where scan i's pose was read, for messages: " (pose file 'P', line L)", or "" (a bag's).
    std::string pose_origin(std::size_t i) const;
    // Scan i's time: the list's, else its pose's, else none.
    std::optional<double> time(std::size_t i) const;
    // Text that changes when the recording does: the pose file's bytes and each scan file's name
    // and size (scan contents are not read: an edit that keeps a scan's size goes unnoticed); a bag's
    // files' names and sizes, its topics and the pose source.
    std::string fingerprint() const;
};

// Lists the scans, reads the poses and pairs them (in order, or by time); errors (InputError) name
// the file, line or scan index.
Recording open_recording(const std::filesystem::path& scans, const std::filesystem::path& poses,
                         const RecordingOptions& options = {});

// How export writes a recording's scans.
enum class ScanWriteFormat { pcd_f4, pcd_f8, ply, kitti_bin };
// "pcd", "pcd-f8", "ply", "kitti"; anything else is an InputError.
ScanWriteFormat parse_scan_write_format(const std::string& name);

// Writes `clouds` as <folder>/000000.<ext> ..., `poses` as <folder>/poses.txt (4×4 rows with time
// when every pose has one, else KITTI) and <folder>/scans.txt (the scan list, with times when
// known). All or nothing: the files go to a temporary folder that replaces `folder` at the end.
// `folder` must be new, empty, or an earlier output of this function (only its kind of files).
void write_recording(const std::filesystem::path& folder, const std::vector<PointCloud>& clouds,
                     const std::vector<PoseRecord>& poses, ScanWriteFormat format);

}  // namespace bvc3d::recording
