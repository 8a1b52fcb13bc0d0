#include "bvc3d/recording/recording.hpp"

#include <unistd.h>

#include <algorithm>
#include <cstdint>
#include <regex>

#include "bvc3d/core/atomic_file.hpp"
#include "bvc3d/core/error.hpp"
#include "bvc3d/recording/extrinsics.hpp"
#include "bvc3d/recording/file_io.hpp"
#include "bvc3d/recording/kitti_bin.hpp"
#include "bvc3d/recording/pairing.hpp"
#include "bvc3d/recording/parsing.hpp"
#include "bvc3d/recording/pcd.hpp"
#include "bvc3d/recording/ply.hpp"
#include "bvc3d/recording/scan_file.hpp"

namespace bvc3d::recording {

namespace fs = std::filesystem;

namespace {

// A folder's name; for a list file, the name of the folder holding it (the recording's folder);
// for a single scan, its stem.
std::string recording_name(const fs::path& scans) {
    const fs::path p = fs::absolute(scans.has_filename() ? scans : scans.parent_path()).lexically_normal();
    if (fs::is_directory(p)) return p.filename().string();
    if (scan_format_of(p)) return p.stem().string();
    return p.parent_path().filename().string();
}

// Scan files, one per scan.
class ScanFiles : public ScanStore {
public:
    ScanFiles(std::vector<ScanEntry> scans, fs::path poses) : scans_(std::move(scans)), poses_(std::move(poses)) {}
    PointCloud load(std::size_t i) const override { return read_scan(scans_.at(i).path); }
    std::string scan_name(std::size_t i) const override { return scans_.at(i).path.filename().string(); }
    std::string fingerprint() const override {
        std::uint64_t h = detail::fnv1a(detail::read_file(poses_));
        for (const auto& s : scans_) {
            std::error_code ec;
            const auto size = fs::file_size(s.path, ec);
            h = detail::fnv1a(s.path.filename().string() + ":" + std::to_string(ec ? 0 : size) + ";", h);
        }
        char text[17];
        std::snprintf(text, sizeof text, "%016llx", static_cast<unsigned long long>(h));
        return text;
    }

private:
    std::vector<ScanEntry> scans_;
    fs::path poses_;
};

}  // namespace

Recording open_recording(const fs::path& scans, const fs::path& poses, const RecordingOptions& options) {
    Recording r;
    r.name = recording_name(scans);
    r.scans_source = scans;
    r.poses_source = poses;
    r.scans = list_scans(scans);
    r.store = std::make_shared<ScanFiles>(r.scans, poses);
    std::vector<PoseRecord> all = read_poses(poses, options.pose_format);
    if (options.base_from_sensor) apply_extrinsics(all, *options.base_from_sensor);
    ScanPosePairing pairing;
    try {
        pairing = pair_scans_with_poses(scan_times(r.scans), all, options.time_tolerance);
    } catch (const InputError& e) {  // name the files paired
        throw InputError("scans '" + scans.string() + "' with pose file '" + poses.string() + "': " + e.what());
    }
    r.paired_by_time = pairing.by_time;
    for (const std::size_t i : pairing.pose_of_scan) r.poses.push_back(all[i]);
    return r;
}

PointCloud Recording::load(std::size_t i) const {
    if (i >= scans.size())
        throw InputError("recording '" + name + "': scan " + std::to_string(i) + " does not exist (" +
                         std::to_string(scans.size()) + " scans)");
    try {
        return store->load(i);
    } catch (const InputError& e) {
        throw InputError("recording '" + name + "', scan " + std::to_string(i) + ": " + e.what());
    }
}

std::string Recording::pose_origin(std::size_t i) const {
    if (i >= poses.size() || poses[i].line == 0 || poses_source.empty()) return "";
    return " (pose file '" + poses_source.string() + "', line " + std::to_string(poses[i].line) + ")";
}

std::optional<double> Recording::time(std::size_t i) const {
    if (scans.at(i).time) return scans[i].time;
    return poses.at(i).time;
}

std::string Recording::fingerprint() const { return store->fingerprint(); }

ScanWriteFormat parse_scan_write_format(const std::string& name) {
    if (name == "pcd") return ScanWriteFormat::pcd_f4;
    if (name == "pcd-f8") return ScanWriteFormat::pcd_f8;
    if (name == "ply") return ScanWriteFormat::ply;
    if (name == "kitti") return ScanWriteFormat::kitti_bin;
    throw InputError("scan format '" + name + "' is not one of pcd, pcd-f8, ply, kitti");
}

namespace {

const char* extension(ScanWriteFormat f) {
    switch (f) {
        case ScanWriteFormat::pcd_f4:
        case ScanWriteFormat::pcd_f8:
            return ".pcd";
        case ScanWriteFormat::ply:
            return ".ply";
        case ScanWriteFormat::kitti_bin:
            return ".bin";
    }
    return "";
}

// What write_recording puts in a folder: scans named by six digits, poses.txt, scans.txt.
bool is_recording_file(const fs::path& p) {
    static const std::regex name(R"(\d{6}\.(pcd|ply|bin)|poses\.txt|scans\.txt)");
    return std::regex_match(p.filename().string(), name);
}

void check_replaceable(const fs::path& folder) {
    std::error_code ec;
    if (!fs::exists(folder, ec)) return;
    if (!fs::is_directory(folder, ec)) throw InputError("'" + folder.string() + "' exists and is not a folder");
    for (const auto& e : fs::directory_iterator(folder))
        if (!e.is_regular_file() || !is_recording_file(e.path()))
            throw InputError("'" + folder.string() + "' holds '" + e.path().filename().string() +
                             "', which a recording written by bvc3d does not: choose a new or empty folder");
}

std::string six_digits(std::size_t i) {
    char name[32];
    std::snprintf(name, sizeof name, "%06zu", i);
    return name;
}

}  // namespace

void write_recording(const fs::path& folder, const std::vector<PointCloud>& clouds,
                     const std::vector<PoseRecord>& poses, ScanWriteFormat format) {
    if (clouds.size() != poses.size()) throw std::logic_error("write_recording: one pose per scan");
    if (clouds.empty()) throw InputError("'" + folder.string() + "': a recording needs at least one scan");
    check_replaceable(without_trailing_slash(folder));
    AtomicFolder out(folder);
    const fs::path& temp = out.temp_path();

    const bool timed = std::all_of(poses.begin(), poses.end(), [](const PoseRecord& p) { return p.time.has_value(); });
    std::string list;
    for (std::size_t i = 0; i < clouds.size(); ++i) {
        const std::string name = six_digits(i) + extension(format);
        const fs::path file = temp / name;
        switch (format) {
            case ScanWriteFormat::pcd_f4:
                write_pcd(file, clouds[i], PcdEncoding::binary, PcdPrecision::f4);
                break;
            case ScanWriteFormat::pcd_f8:
                write_pcd(file, clouds[i], PcdEncoding::binary, PcdPrecision::f8);
                break;
            case ScanWriteFormat::ply:
                write_ply(file, clouds[i]);
                break;
            case ScanWriteFormat::kitti_bin:
                write_kitti_bin(file, clouds[i]);
                break;
        }
        list += name;
        if (timed) {
            list += ' ';
            detail::append_number(list, *poses[i].time);
        }
        list += '\n';
    }
    write_file_atomically(temp / "scans.txt", list);
    if (timed) write_matrix_poses(temp / "poses.txt", poses);
    else write_kitti_poses(temp / "poses.txt", poses);

    out.commit();  // an earlier recording goes only once the new one is there
}

}  // namespace bvc3d::recording
