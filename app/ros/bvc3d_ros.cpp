// bvc3d_ros: the model on a robot running ROS 1 (docs/ros.md#the-node). Subscribes to a
// sensor_msgs/PointCloud2 topic and a pose source (nav_msgs/Odometry or geometry_msgs/PoseStamped on
// a topic, or tf), runs each scan through a model (node_model.hpp) on a worker thread and publishes
//   ~bvc_rates, ~place_rates   std_msgs/Float32MultiArray   every processed scan
//   ~decoded_pose              geometry_msgs/PoseStamped    the nearest template's pose (with templates)
//   ~revisit                   std_msgs/Int64               the recognised earlier scan (SPEC §15)
//   ~revisit_distance          std_msgs/Float32             its distance 1 − cosine
//   ~latency                   std_msgs/Float32             seconds the scan took on the worker
//   ~dropped                   std_msgs/Int64               scans dropped so far (the worker was busy)
// The cloud callback only puts the message in a one-slot queue (a newer scan replaces a waiting
// one, which is counted as dropped), so it never blocks for longer than a copy of a pointer.
// Compiled as C++17: the ROS 1 message headers need it (node_model.hpp keeps to C++17 for it).
#include <geometry_msgs/PoseStamped.h>
#include <nav_msgs/Odometry.h>
#include <ros/ros.h>
#include <sensor_msgs/PointCloud2.h>
#include <std_msgs/Float32.h>
#include <std_msgs/Float32MultiArray.h>
#include <std_msgs/Int64.h>
#include <tf2_msgs/TFMessage.h>

#include <arpa/inet.h>
#include <dlfcn.h>
#include <netinet/in.h>
#include <sys/socket.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <deque>
#include <mutex>
#include <optional>
#include <thread>

#include "bvc3d/core/error.hpp"
#include "bvc3d/recording/ros_messages.hpp"
#include "bvc3d/recording/tf_tree.hpp"
#include "node_model.hpp"

// Nodes listen on the loopback interface only, unless told otherwise. roscpp binds its TCPROS server
// to the address of ROS_IP/ROS_HOSTNAME when that is a loopback one, but Debian's xmlrpcpp always binds
// its server to every interface (INADDR_ANY). This definition of bind(2) in the program comes before
// libc's for the libraries it loads, and turns that one case, an IPv4 bind to every interface while
// the node's host is a loopback address, into a bind to 127.0.0.1; everything else goes to libc as is.
namespace {
bool host_is_loopback() {
    const char* ip = std::getenv("ROS_IP");
    const char* name = std::getenv("ROS_HOSTNAME");
    const std::string host = ip && *ip ? ip : name && *name ? name : "";
    return host.rfind("127.", 0) == 0 || host == "localhost";
}
}  // namespace

extern "C" int bind(int fd, const struct sockaddr* address, socklen_t length) {
    using Bind = int (*)(int, const struct sockaddr*, socklen_t);
    static const auto libc_bind = reinterpret_cast<Bind>(::dlsym(RTLD_NEXT, "bind"));
    if (address && address->sa_family == AF_INET && length >= sizeof(sockaddr_in) && host_is_loopback()) {
        sockaddr_in loopback;
        std::memcpy(&loopback, address, sizeof loopback);
        if (loopback.sin_addr.s_addr == htonl(INADDR_ANY)) {
            loopback.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
            return libc_bind(fd, reinterpret_cast<const sockaddr*>(&loopback), sizeof loopback);
        }
    }
    return libc_bind(fd, address, length);
}

namespace {

using bvc3d::recording::StampedTransform;

double seconds(const ros::Time& t) { return t.sec + t.nsec * 1e-9; }

Eigen::Isometry3d isometry(const Eigen::Vector3d& p, const Eigen::Quaterniond& q) {
    Eigen::Isometry3d m = Eigen::Isometry3d::Identity();
    m.linear() = bvc3d::recording::checked_rotation(q).toRotationMatrix();
    m.translation() = p;
    return m;
}

// Poses by time: from a pose topic (each the nearest within a tolerance, as a replay pairs them) or
// from tf (the chain interpolated at the stamp).
class PoseSource {
public:
    PoseSource(std::string fixed, std::string sensor, double time_tolerance, double tf_tolerance)
        : fixed_(std::move(fixed)), sensor_(std::move(sensor)), time_tol_(time_tolerance), tf_tol_(tf_tolerance) {}
    bool uses_tf() const { return !fixed_.empty(); }

    void add_pose(double stamp, const Eigen::Isometry3d& pose) {
        {
            const std::lock_guard lock(mutex_);
            if (!poses_.empty() && stamp <= poses_.back().first) poses_.clear();  // time went back: a new run
            poses_.emplace_back(stamp, pose);
            while (poses_.size() > 2 && poses_.front().first < stamp - keep_s) poses_.pop_front();
        }
        changed_.notify_all();
    }
    void add_tf(const tf2_msgs::TFMessage& m, bool is_static) {
        {
            const std::lock_guard lock(mutex_);
            double latest = 0;
            for (const auto& t : m.transforms) {
                StampedTransform s;
                s.stamp = seconds(t.header.stamp);
                s.parent = t.header.frame_id;
                s.child = t.child_frame_id;
                s.translation = {t.transform.translation.x, t.transform.translation.y, t.transform.translation.z};
                const auto& q = t.transform.rotation;
                s.rotation = Eigen::Quaterniond(q.w, q.x, q.y, q.z);
                try {
                    tree_.add(s, is_static);
                } catch (const bvc3d::InputError& e) {
                    ROS_WARN_THROTTLE(5, "bvc3d_ros: a tf transform is refused: %s", e.what());
                }
                latest = std::max(latest, s.stamp);
            }
            if (!is_static) tree_.forget_before(latest - keep_s);
        }
        changed_.notify_all();
    }
    // The pose at `stamp`, waiting up to `wait` for data that has not arrived yet: until then only a
    // pose that later data cannot change is taken (a tf sample at or after the stamp on every link; a
    // pose stamped at or after it), then the best there is within the tolerances. nullopt (and why)
    // if there is none.
    std::optional<Eigen::Isometry3d> at(double stamp, const std::string& frame, std::chrono::duration<double> wait,
                                        std::string& why) {
        std::unique_lock lock(mutex_);
        const auto until =
            std::chrono::steady_clock::now() + std::chrono::duration_cast<std::chrono::steady_clock::duration>(wait);
        for (;;) {
            if (auto p = lookup(stamp, frame, false, why)) return p;
            if (changed_.wait_until(lock, until) == std::cv_status::timeout) return lookup(stamp, frame, true, why);
        }
    }
    void wake() { changed_.notify_all(); }

private:
    static constexpr double keep_s = 30;
    std::optional<Eigen::Isometry3d> lookup(double stamp, const std::string& frame, bool final,
                                            std::string& why) const {
        if (uses_tf()) {
            if (!frame.empty() && bvc3d::recording::bare_frame(frame) != bvc3d::recording::bare_frame(sensor_)) {
                why = "the cloud is in frame '" + frame + "', not the sensor frame '" + sensor_ + "'";
                return std::nullopt;
            }
            try {
                return tree_.lookup(fixed_, sensor_, stamp, tf_tol_, final);
            } catch (const bvc3d::InputError& e) {
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
        if (best && std::abs(best->first - stamp) <= time_tol_) return best->second;
        why = best ? "the nearest pose is " + std::to_string(best->first - stamp) + " s away" : "no pose yet";
        return std::nullopt;
    }
    std::string fixed_, sensor_;
    double time_tol_, tf_tol_;
    std::mutex mutex_;
    std::condition_variable changed_;
    std::deque<std::pair<double, Eigen::Isometry3d>> poses_;
    bvc3d::recording::TfTree tree_;
};

bvc3d::recording::CloudMessage cloud_message(const sensor_msgs::PointCloud2& m) {
    return bvc3d::recording::cloud_message_of(m, seconds(m.header.stamp));
}

template <class T>
T param(ros::NodeHandle& nh, const std::string& name, const T& fallback) {
    T v;
    nh.param(name, v, fallback);
    return v;
}

class Node {
public:
    Node(ros::NodeHandle& nh, ros::NodeHandle& pn)
        : model_(params(pn)),
          poses_(frame(pn, 0), frame(pn, 1), param(pn, "time_tolerance", 0.05), param(pn, "tf_tolerance", 0.2)),
          fixed_frame_(param<std::string>(pn, "fixed_frame", "map")),
          pose_wait_(param(pn, "pose_wait", 0.1)) {
        const std::string cloud_topic = param<std::string>(pn, "cloud_topic", "points");
        const std::string pose_topic = param<std::string>(pn, "pose_topic", "");
        const std::string pose_type = param<std::string>(pn, "pose_type", "odometry");
        if (poses_.uses_tf() == !pose_topic.empty())
            throw bvc3d::InputError("give ~pose_topic (with ~pose_type odometry or pose_stamped) or ~tf_frames");
        bvc_pub_ = pn.advertise<std_msgs::Float32MultiArray>("bvc_rates", 10);
        place_pub_ = pn.advertise<std_msgs::Float32MultiArray>("place_rates", 10);
        decoded_pub_ = pn.advertise<geometry_msgs::PoseStamped>("decoded_pose", 10);
        revisit_pub_ = pn.advertise<std_msgs::Int64>("revisit", 10);
        distance_pub_ = pn.advertise<std_msgs::Float32>("revisit_distance", 10);
        latency_pub_ = pn.advertise<std_msgs::Float32>("latency", 10);
        dropped_pub_ = pn.advertise<std_msgs::Int64>("dropped", 10, true);
        const auto hints = ros::TransportHints().tcpNoDelay();
        cloud_sub_ = nh.subscribe(cloud_topic, 2, &Node::on_cloud, this, hints);
        if (poses_.uses_tf()) {
            tf_sub_ = nh.subscribe<tf2_msgs::TFMessage>(
                "/tf", 100, [this](const tf2_msgs::TFMessage::ConstPtr& m) { poses_.add_tf(*m, false); }, nullptr,
                hints);
            tf_static_sub_ = nh.subscribe<tf2_msgs::TFMessage>(
                "/tf_static", 100, [this](const tf2_msgs::TFMessage::ConstPtr& m) { poses_.add_tf(*m, true); }, nullptr,
                hints);
        } else if (pose_type == "odometry") {
            pose_sub_ = nh.subscribe<nav_msgs::Odometry>(
                pose_topic, 100,
                [this](const nav_msgs::Odometry::ConstPtr& m) {
                    add_pose(m->header.stamp, m->pose.pose.position, m->pose.pose.orientation);
                },
                nullptr, hints);
        } else if (pose_type == "pose_stamped") {
            pose_sub_ = nh.subscribe<geometry_msgs::PoseStamped>(
                pose_topic, 100,
                [this](const geometry_msgs::PoseStamped::ConstPtr& m) {
                    add_pose(m->header.stamp, m->pose.position, m->pose.orientation);
                },
                nullptr, hints);
        } else {
            throw bvc3d::InputError("~pose_type '" + pose_type + "' is not odometry or pose_stamped");
        }
        worker_ = std::thread([this] { work(); });
        ROS_INFO("bvc3d_ros: model %s (%zu BVCs, %zu place cells), %zu templates; clouds on %s, poses from %s",
                 model_.model_name().c_str(), model_.n_bvc(), model_.n_place(), model_.templates(),
                 cloud_sub_.getTopic().c_str(), poses_.uses_tf() ? "tf" : pose_sub_.getTopic().c_str());
    }
    ~Node() { stop(); }

    void stop() {
        {
            const std::lock_guard lock(mutex_);
            stopping_ = true;
        }
        ready_.notify_all();
        poses_.wake();
        if (worker_.joinable()) worker_.join();
    }
    std::size_t processed() const { return processed_; }
    std::size_t dropped() const { return dropped_; }
    std::size_t skipped() const { return skipped_; }

private:
    static bvc3d::ros_node::NodeParams params(ros::NodeHandle& pn) {
        bvc3d::ros_node::NodeParams p;
        p.model = param(pn, "model", p.model);
        p.learn = param(pn, "learn", p.learn);
        p.weights = param(pn, "weights", p.weights);
        p.seed = static_cast<std::uint64_t>(param(pn, "seed", 0));
        p.min_range = param(pn, "min_range", p.min_range);
        p.max_range = param(pn, "max_range", p.max_range);
        p.slice_half_width_deg = param(pn, "slice_half_width_deg", p.slice_half_width_deg);
        p.templates_bag = param(pn, "templates_bag", p.templates_bag);
        p.templates_cloud_topic = param(pn, "templates_cloud_topic", p.templates_cloud_topic);
        p.templates_pose_topic = param(pn, "templates_pose_topic", p.templates_pose_topic);
        p.templates_tf_frames = param(pn, "templates_tf_frames", p.templates_tf_frames);
        p.templates_scans = param(pn, "templates_scans", p.templates_scans);
        p.templates_poses = param(pn, "templates_poses", p.templates_poses);
        p.decode_place = param<std::string>(pn, "decode_rates", "bvc") == "place";
        p.revisit_place = param<std::string>(pn, "revisit_rates", "bvc") == "place";
        p.revisit_window_scans = param(pn, "revisit_window_scans", p.revisit_window_scans);
        p.revisit_window_s = param(pn, "revisit_window_s", p.revisit_window_s);
        p.revisit_threshold = param(pn, "revisit_threshold", p.revisit_threshold);
        return p;
    }
    // ~tf_frames "FIXED,SENSOR": part 0 or 1 (empty without it).
    static std::string frame(ros::NodeHandle& pn, int part) {
        const std::string text = param<std::string>(pn, "tf_frames", "");
        if (text.empty()) return "";
        const auto comma = text.find(',');
        if (comma == std::string::npos || comma == 0 || comma + 1 == text.size())
            throw bvc3d::InputError("~tf_frames '" + text + "' is not FIXED,SENSOR");
        return part == 0 ? text.substr(0, comma) : text.substr(comma + 1);
    }
    void add_pose(const ros::Time& stamp, const geometry_msgs::Point& p, const geometry_msgs::Quaternion& q) {
        try {
            poses_.add_pose(seconds(stamp), isometry({p.x, p.y, p.z}, Eigen::Quaterniond(q.w, q.x, q.y, q.z)));
        } catch (const bvc3d::InputError& e) {
            ROS_WARN_THROTTLE(5, "bvc3d_ros: a pose is refused: %s", e.what());
        }
    }
    void on_cloud(const sensor_msgs::PointCloud2::ConstPtr& m) {
        {
            const std::lock_guard lock(mutex_);
            if (pending_) ++dropped_;  // the worker has not taken the last one: the newer replaces it
            pending_ = m;
        }
        ready_.notify_one();
    }
    void work() {
        for (;;) {
            sensor_msgs::PointCloud2::ConstPtr m;
            {
                std::unique_lock lock(mutex_);
                ready_.wait(lock, [this] { return stopping_ || pending_; });
                if (stopping_) return;
                m.swap(pending_);
            }
            process(*m);
        }
    }
    void process(const sensor_msgs::PointCloud2& m) {
        const auto start = std::chrono::steady_clock::now();
        const double stamp = seconds(m.header.stamp);
        std::string why;
        const auto pose = poses_.at(stamp, m.header.frame_id, std::chrono::duration<double>(pose_wait_), why);
        if (!pose) {
            ++skipped_;
            ROS_WARN_THROTTLE(5, "bvc3d_ros: a cloud at %.6f s is skipped: no pose (%s)", stamp, why.c_str());
            return;
        }
        bvc3d::ros_node::ScanResult r;
        try {
            r = model_.step(bvc3d::recording::cloud_points(cloud_message(m)).xyz, *pose, stamp);
        } catch (const bvc3d::InputError& e) {
            ++skipped_;
            ROS_WARN_THROTTLE(5, "bvc3d_ros: a cloud at %.6f s is skipped: %s", stamp, e.what());
            return;
        }
        std_msgs::Float32MultiArray bvc, place;
        bvc.data = std::move(r.bvc);
        place.data = std::move(r.place);
        bvc_pub_.publish(bvc);
        place_pub_.publish(place);
        if (r.decoded) {
            geometry_msgs::PoseStamped p;
            p.header.stamp = m.header.stamp;
            p.header.frame_id = fixed_frame_;
            const auto& T = r.decoded->world_from_sensor;
            p.pose.position.x = T.translation().x();
            p.pose.position.y = T.translation().y();
            p.pose.position.z = T.translation().z();
            const Eigen::Quaterniond q(T.linear());
            p.pose.orientation.x = q.x();
            p.pose.orientation.y = q.y();
            p.pose.orientation.z = q.z();
            p.pose.orientation.w = q.w();
            decoded_pub_.publish(p);
        }
        if (r.revisit) {
            std_msgs::Int64 index;
            index.data = r.revisit->scan;
            std_msgs::Float32 distance;
            distance.data = static_cast<float>(r.revisit->distance);
            revisit_pub_.publish(index);
            distance_pub_.publish(distance);
        }
        std_msgs::Float32 latency;
        latency.data =
            static_cast<float>(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
        latency_pub_.publish(latency);
        std_msgs::Int64 dropped;
        dropped.data = static_cast<std::int64_t>(dropped_.load());
        dropped_pub_.publish(dropped);
        ++processed_;
    }

    bvc3d::ros_node::NodeModel model_;
    PoseSource poses_;
    std::string fixed_frame_;
    double pose_wait_;
    ros::Publisher bvc_pub_, place_pub_, decoded_pub_, revisit_pub_, distance_pub_, latency_pub_, dropped_pub_;
    ros::Subscriber cloud_sub_, pose_sub_, tf_sub_, tf_static_sub_;
    std::mutex mutex_;
    std::condition_variable ready_;
    sensor_msgs::PointCloud2::ConstPtr pending_;
    bool stopping_ = false;
    std::atomic<std::size_t> processed_{0}, dropped_{0}, skipped_{0};
    std::thread worker_;
};

}  // namespace

int main(int argc, char** argv) {
    // Nodes listen on the loopback interface unless told otherwise (ROS_IP or ROS_HOSTNAME).
    if (!std::getenv("ROS_IP") && !std::getenv("ROS_HOSTNAME")) ::setenv("ROS_IP", "127.0.0.1", 0);
    std::setvbuf(stdout, nullptr, _IOLBF, 0);  // log lines appear as they happen, under roslaunch too
    ros::init(argc, argv, "bvc3d_ros");
    ros::NodeHandle nh, pn("~");
    try {
        Node node(nh, pn);
        ros::spin();  // until SIGINT (roscpp's handler calls ros::shutdown) or a shutdown request
        node.stop();
        std::fprintf(stderr, "bvc3d_ros: stopped after %zu scans (%zu dropped while busy, %zu skipped)\n",
                     node.processed(), node.dropped(), node.skipped());
    } catch (const bvc3d::InputError& e) {
        ROS_FATAL("bvc3d_ros: %s", e.what());
        std::fprintf(stderr, "bvc3d: error: %s\n", e.what());
        return 2;
    }
    return 0;
}
