#include "node_core.hpp"

#include <cmath>

#include "bvc3d/core/error.hpp"
#include "bvc3d/recording/bag.hpp"

namespace bvc3d::ros_node {

namespace {
constexpr double keep_s = 30;  // seconds of poses and tf kept
}  // namespace

void split_tf_frames(const std::string& text, const std::string& name, PoseParams& p) {
    if (text.empty()) return;
    const auto comma = text.find(',');
    if (comma == std::string::npos || comma == 0 || comma + 1 == text.size())
        throw InputError(name + " '" + text + "' is not FIXED,SENSOR");
    p.fixed_frame_tf = text.substr(0, comma);
    p.sensor_frame_tf = text.substr(comma + 1);
}

void PoseSource::add_pose(double stamp, const Eigen::Vector3d& position, const Eigen::Quaterniond& orientation) {
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    pose.linear() = recording::checked_rotation(orientation).toRotationMatrix();
    pose.translation() = position;
    {
        const std::lock_guard lock(mutex_);
        if (!poses_.empty() && stamp <= poses_.back().first) poses_.clear();  // time went back: a new run
        poses_.emplace_back(stamp, pose);
        while (poses_.size() > 2 && poses_.front().first < stamp - keep_s) poses_.pop_front();
    }
    changed_.notify_all();
}

void PoseSource::add_tf(const std::vector<recording::StampedTransform>& transforms, bool is_static) {
    std::string refused;
    {
        const std::lock_guard lock(mutex_);
        double latest = 0;
        for (const auto& t : transforms) {
            try {
                tree_.add(t, is_static);
            } catch (const InputError& e) {
                refused = e.what();
            }
            latest = std::max(latest, t.stamp);
        }
        if (!is_static) tree_.forget_before(latest - keep_s);
    }
    changed_.notify_all();
    if (!refused.empty()) throw InputError("a tf transform is refused: " + refused);
}

std::optional<Eigen::Isometry3d> PoseSource::at(double stamp, const std::string& frame,
                                                std::chrono::duration<double> wait, std::string& why) {
    std::unique_lock lock(mutex_);
    const auto until =
        std::chrono::steady_clock::now() + std::chrono::duration_cast<std::chrono::steady_clock::duration>(wait);
    for (;;) {
        if (auto p = lookup(stamp, frame, false, why)) return p;
        if (changed_.wait_until(lock, until) == std::cv_status::timeout) return lookup(stamp, frame, true, why);
    }
}

std::optional<Eigen::Isometry3d> PoseSource::lookup(double stamp, const std::string& frame, bool final,
                                                    std::string& why) const {
    if (uses_tf()) {
        if (!frame.empty() && recording::bare_frame(frame) != recording::bare_frame(p_.sensor_frame_tf)) {
            why = "the cloud is in frame '" + frame + "', not the sensor frame '" + p_.sensor_frame_tf + "'";
            return std::nullopt;
        }
        try {
            return tree_.lookup(p_.fixed_frame_tf, p_.sensor_frame_tf, stamp, p_.tf_tolerance, final);
        } catch (const InputError& e) {
            why = e.what();
            return std::nullopt;
        }
    }
    if (!final && (poses_.empty() || poses_.back().first < stamp)) {
        why = "no pose at or after the cloud's stamp yet";
        return std::nullopt;
    }
    const std::pair<double, Eigen::Isometry3d>* best = nullptr;
    for (const auto& p : poses_)
        if (!best || std::abs(p.first - stamp) < std::abs(best->first - stamp)) best = &p;
    if (best && std::abs(best->first - stamp) <= p_.time_tolerance) return best->second;
    why = best ? "the nearest pose is " + std::to_string(best->first - stamp) + " s away" : "no pose yet";
    return std::nullopt;
}

NodeCore::NodeCore(const NodeSettings& settings, Publish publish, Warn warn)
    : model_(settings.model),
      poses_(settings.poses),
      pose_wait_(settings.poses.pose_wait),
      publish_(std::move(publish)),
      warn_(std::move(warn)) {
    worker_ = std::thread([this] { work(); });
}

NodeCore::~NodeCore() { stop(); }

void NodeCore::put(Cloud cloud) {
    {
        const std::lock_guard lock(mutex_);
        if (pending_) ++dropped_;  // the worker has not taken the last one: the newer replaces it
        pending_ = std::move(cloud);
    }
    ready_.notify_one();
}

void NodeCore::stop() {
    {
        const std::lock_guard lock(mutex_);
        stopping_ = true;
    }
    ready_.notify_all();
    poses_.wake();
    if (worker_.joinable()) worker_.join();
}

void NodeCore::work() {
    for (;;) {
        Cloud cloud;
        {
            std::unique_lock lock(mutex_);
            ready_.wait(lock, [this] { return stopping_ || pending_; });
            if (stopping_) return;
            cloud.swap(pending_);
        }
        process(cloud);
    }
}

void NodeCore::process(const Cloud& cloud) {
    const auto start = std::chrono::steady_clock::now();
    Output out;
    try {
        const recording::CloudMessage m = cloud();
        out.stamp = m.stamp;
        std::string why;
        const auto pose = poses_.at(m.stamp, m.frame_id, std::chrono::duration<double>(pose_wait_), why);
        if (!pose) {
            ++skipped_;
            warn_("a cloud at " + std::to_string(m.stamp) + " s is skipped: no pose (" + why + ")");
            return;
        }
        out.result = model_.step(recording::cloud_points(m).xyz, *pose, m.stamp);
    } catch (const InputError& e) {
        ++skipped_;
        warn_("a cloud at " + std::to_string(out.stamp) + " s is skipped: " + e.what());
        return;
    }
    out.latency_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    out.dropped = dropped_;
    publish_(out);
    ++processed_;
}

}  // namespace bvc3d::ros_node
