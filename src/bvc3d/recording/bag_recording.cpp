#include "bvc3d/recording/bag_recording.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "bvc3d/core/error.hpp"
#include "bvc3d/recording/cdr.hpp"
#include "bvc3d/recording/extrinsics.hpp"
#include "bvc3d/recording/file_io.hpp"
#include "bvc3d/recording/pairing.hpp"
#include "bvc3d/recording/tf_tree.hpp"

namespace bvc3d::recording {

namespace fs = std::filesystem;

namespace {

std::string stamp_text(double t) {
    char s[40];
    std::snprintf(s, sizeof s, "%.9f s", t);
    return s;
}

// A bag's clouds, decoded when asked for.
class BagScans : public ScanStore {
public:
    BagScans(std::shared_ptr<const BagReader> bag, std::size_t topic, std::string key)
        : bag_(std::move(bag)), topic_(topic), key_(std::move(key)) {}
    PointCloud load(std::size_t i) const override {
        const CloudMessage cloud = bag_->cloud(topic_, i);
        try {
            return cloud_points(cloud);
        } catch (const InputError& e) {
            throw InputError(bag_->where(topic_, i) + ": " + e.what());
        }
    }
    std::string scan_name(std::size_t i) const override {
        return bag_->topics()[topic_].name + " #" + std::to_string(i);
    }
    std::string fingerprint() const override {
        // The files' names and sizes (their contents are not read again), and what is read from them.
        std::uint64_t h = detail::fnv1a(key_);
        std::error_code ec;
        const fs::path& p = bag_->path();
        std::vector<fs::path> files;
        if (fs::is_directory(p, ec))
            for (const auto& e : fs::directory_iterator(p)) files.push_back(e.path());
        else files.push_back(p);
        std::sort(files.begin(), files.end());
        for (const auto& f : files) {
            const auto size = fs::file_size(f, ec);
            h = detail::fnv1a(f.filename().string() + ":" + std::to_string(ec ? 0 : size) + ";", h);
        }
        char text[17];
        std::snprintf(text, sizeof text, "%016llx", static_cast<unsigned long long>(h));
        return text;
    }

private:
    std::shared_ptr<const BagReader> bag_;
    std::size_t topic_;
    std::string key_;
};

// A bag's name for its recording: the file's stem, or the folder's name.
std::string bag_name(const fs::path& path) {
    const fs::path p = fs::absolute(path).lexically_normal();
    const fs::path named = p.has_filename() ? p : p.parent_path();
    std::error_code ec;
    return fs::is_directory(named, ec) ? named.filename().string() : named.stem().string();
}

PoseRecord pose_record(const StampedTransform& t) {
    PoseRecord p;
    p.world_from_sensor = Eigen::Isometry3d::Identity();
    p.world_from_sensor.linear() = checked_rotation(t.rotation).toRotationMatrix();
    p.world_from_sensor.translation() = t.translation;
    p.time = t.stamp;
    return p;
}

std::vector<PoseRecord> topic_poses(const BagReader& bag, const std::string& topic) {
    const std::size_t t = bag.topic(topic);
    const MessageKind kind = message_kind(bag.topics()[t].type);
    if (kind != MessageKind::odometry && kind != MessageKind::pose_stamped)
        throw InputError(quoted_path(bag.path()) + ", topic '" + topic + "' is of type " + bag.topics()[t].type +
                         ", not nav_msgs/Odometry or geometry_msgs/PoseStamped");
    std::vector<PoseRecord> poses;
    for (std::size_t k = 0; k < bag.topics()[t].count; ++k) {
        const StampedTransform s = bag.pose(t, k);
        try {
            if (!std::isfinite(s.stamp) || !s.translation.allFinite()) throw InputError("a non-finite value");
            poses.push_back(pose_record(s));
        } catch (const InputError& e) {
            throw InputError(bag.where(t, k) + ": " + e.what());
        }
        if (k > 0 && !(s.stamp > *poses[k - 1].time))
            throw InputError(bag.where(t, k) + ": its stamp " + stamp_text(s.stamp) + " does not follow the previous " +
                             stamp_text(*poses[k - 1].time) + " (stamps out of order)");
    }
    if (poses.empty()) throw InputError(quoted_path(bag.path()) + ", topic '" + topic + "' has no messages");
    return poses;
}

TfTree read_tf(const BagReader& bag) {
    TfTree tree;
    for (const auto& [name, is_static] : {std::pair{"/tf", false}, std::pair{"/tf_static", true}}) {
        std::size_t t = bag.topics().size();
        for (std::size_t i = 0; i < bag.topics().size(); ++i)
            if (bare_frame(bag.topics()[i].name) == bare_frame(name)) t = i;
        if (t == bag.topics().size()) continue;
        for (std::size_t k = 0; k < bag.topics()[t].count; ++k) {
            const auto transforms = bag.transforms(t, k);
            try {
                for (const auto& x : transforms) tree.add(x, is_static);
            } catch (const InputError& e) {
                throw InputError(bag.where(t, k) + ": " + e.what());
            }
        }
    }
    if (tree.links() == 0) throw InputError(quoted_path(bag.path()) + " has no transforms on /tf or /tf_static");
    return tree;
}

}  // namespace

void parse_tf_frames(const std::string& text, BagSource& source) {
    const auto comma = text.find(',');
    if (comma == std::string::npos || text.find(',', comma + 1) != std::string::npos || comma == 0 ||
        comma + 1 == text.size())
        throw InputError("--tf-frames '" + text + "' is not FIXED,SENSOR (two frame names, e.g. map,os_sensor)");
    source.tf_fixed = text.substr(0, comma);
    source.tf_sensor = text.substr(comma + 1);
}

MessageHeader message_header(const BagReader& bag, std::size_t t, std::size_t k) {
    const auto bytes = bag.serialized(t, k);
    MessageHeader h;
    try {
        if (bag.topics()[t].encoding == MessageEncoding::cdr) {
            cdr::Reader r(bytes);
            const std::int32_t sec = r.i32();
            const std::uint32_t nsec = r.u32();
            h.stamp = sec + nsec * 1e-9;
            h.frame_id = r.string();
        } else if (bag.topics()[t].encoding == MessageEncoding::ros1) {
            // std_msgs/Header in ROS 1: uint32 seq, time (uint32 sec, uint32 nsec), string frame_id.
            auto u32 = [&](std::size_t at) {
                if (at + 4 > bytes.size()) throw InputError("the message is shorter than its header (truncated)");
                return static_cast<std::uint32_t>(bytes[at] | bytes[at + 1] << 8 | bytes[at + 2] << 16 |
                                                  static_cast<std::uint32_t>(bytes[at + 3]) << 24);
            };
            h.stamp = u32(4) + u32(8) * 1e-9;
            const std::uint32_t n = u32(12);
            if (n > bytes.size() - 16) throw InputError("the header's frame_id is cut off (truncated)");
            h.frame_id.assign(reinterpret_cast<const char*>(bytes.data()) + 16, n);
        } else {
            throw InputError("unknown message encoding '" + bag.topics()[t].encoding_name + "'");
        }
    } catch (const InputError& e) {
        throw InputError(bag.where(t, k) + ": " + e.what());
    }
    return h;
}

Recording open_bag_recording(const BagSource& source, const RecordingOptions& options) {
    return open_bag_recording(std::shared_ptr<const BagReader>(open_bag(source.bag)), source, options);
}

Recording open_bag_recording(std::shared_ptr<const BagReader> bag, const BagSource& source,
                             const RecordingOptions& options) {
    if (source.cloud_topic.empty()) throw InputError("a bag needs --cloud-topic (bvc3d bag-info lists its topics)");
    if (source.pose_topic.empty() == !source.uses_tf())
        throw InputError("a bag needs its poses from --pose-topic or from tf (--tf-frames FIXED,SENSOR), one of them");
    if (!(source.tf_tolerance >= 0)) throw InputError("the tf tolerance must be >= 0 s");
    const std::size_t t = bag->topic(source.cloud_topic);
    if (message_kind(bag->topics()[t].type) != MessageKind::point_cloud2)
        throw InputError(quoted_path(bag->path()) + ", topic '" + source.cloud_topic + "' is of type " +
                         bag->topics()[t].type + ", not sensor_msgs/PointCloud2");
    const std::size_t n = bag->topics()[t].count;
    if (n == 0) throw InputError(quoted_path(bag->path()) + ", topic '" + source.cloud_topic + "' has no messages");

    Recording r;
    r.name = bag_name(source.bag);
    r.scans_source = source.bag.string() + ":" + source.cloud_topic;
    r.poses_source = source.uses_tf() ? source.bag.string() + ":tf " + source.tf_fixed + " " + source.tf_sensor
                                      : source.bag.string() + ":" + source.pose_topic;
    std::vector<MessageHeader> headers;
    for (std::size_t k = 0; k < n; ++k) {
        headers.push_back(message_header(*bag, t, k));
        const double stamp = headers.back().stamp;
        if (k > 0 && !(stamp > headers[k - 1].stamp))
            throw InputError(bag->where(t, k) + ": its stamp " + stamp_text(stamp) +
                             " does not follow the previous cloud's " + stamp_text(headers[k - 1].stamp) +
                             " (stamps out of order)");
        r.scans.push_back({source.bag, stamp});
    }

    std::vector<PoseRecord> poses;
    if (source.uses_tf()) {
        const TfTree tree = read_tf(*bag);
        for (std::size_t k = 0; k < n; ++k) {
            const std::string_view frame = bare_frame(headers[k].frame_id);
            if (!frame.empty() && frame != bare_frame(source.tf_sensor))
                throw InputError(bag->where(t, k) + ": the cloud is in frame '" + headers[k].frame_id +
                                 "', not the sensor frame '" + source.tf_sensor + "' of --tf-frames");
            try {
                PoseRecord p;
                p.world_from_sensor =
                    tree.lookup(source.tf_fixed, source.tf_sensor, headers[k].stamp, source.tf_tolerance);
                p.time = headers[k].stamp;
                poses.push_back(p);
            } catch (const InputError& e) {
                throw InputError(bag->where(t, k) + " (stamp " + stamp_text(headers[k].stamp) + "): " + e.what());
            }
        }
        if (options.base_from_sensor) apply_extrinsics(poses, *options.base_from_sensor);
        r.poses = std::move(poses);
        r.paired_by_time = true;
    } else {
        std::vector<PoseRecord> all = topic_poses(*bag, source.pose_topic);
        if (options.base_from_sensor) apply_extrinsics(all, *options.base_from_sensor);
        try {
            const ScanPosePairing pairing =
                pair_scans_with_poses_by_time(scan_times(r.scans), all, options.time_tolerance);
            for (const std::size_t i : pairing.pose_of_scan) r.poses.push_back(all[i]);
        } catch (const InputError& e) {
            throw InputError(quoted_path(bag->path()) + ", clouds on '" + source.cloud_topic + "' and poses on '" +
                             source.pose_topic + "': " + e.what());
        }
        r.paired_by_time = true;
    }
    char tolerance[32];
    std::snprintf(tolerance, sizeof tolerance, "%.17g", source.tf_tolerance);
    const std::string key = source.cloud_topic + "|" + source.pose_topic + "|" + source.tf_fixed + "|" +
                            source.tf_sensor + "|" + (source.uses_tf() ? tolerance : "");
    r.store = std::make_shared<BagScans>(std::move(bag), t, key);
    return r;
}

}  // namespace bvc3d::recording
