// bvc3d_ros: the model on a robot running ROS 1 (docs/ros.md#the-node). Subscribes to a
// sensor_msgs/PointCloud2 topic and a pose source (nav_msgs/Odometry or geometry_msgs/PoseStamped on
// a topic, or tf), runs each scan through a model (node_model.hpp) on a worker thread and publishes
//   ~bvc_rates, ~place_rates   std_msgs/Float32MultiArray   every processed scan
//   ~decoded_pose              geometry_msgs/PoseStamped    the nearest template's pose (with templates)
//   ~revisit                   std_msgs/Int64               the recognised earlier scan (SPEC §15)
//   ~revisit_distance          std_msgs/Float32             its distance 1 − cosine
//   ~latency                   std_msgs/Float32             seconds the scan took on the worker
//   ~dropped                   std_msgs/Int64               scans dropped so far (the worker was busy)
// The cloud callback only puts the message in the shared core's one-slot queue (node_core.hpp: a
// newer scan replaces a waiting one, which is counted as dropped), so it never blocks for longer than
// a copy of a pointer.
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

#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "bvc3d/core/error.hpp"
#include "bvc3d/recording/ros_messages.hpp"
#include "node_core.hpp"

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

double seconds(const ros::Time& t) { return t.sec + t.nsec * 1e-9; }

std::vector<bvc3d::recording::StampedTransform> transforms(const tf2_msgs::TFMessage& m) {
    std::vector<bvc3d::recording::StampedTransform> out;
    for (const auto& t : m.transforms) {
        bvc3d::recording::StampedTransform s;
        s.stamp = seconds(t.header.stamp);
        s.parent = t.header.frame_id;
        s.child = t.child_frame_id;
        s.translation = {t.transform.translation.x, t.transform.translation.y, t.transform.translation.z};
        const auto& q = t.transform.rotation;
        s.rotation = Eigen::Quaterniond(q.w, q.x, q.y, q.z);
        out.push_back(s);
    }
    return out;
}

// The node: ROS 1's side of the shared core (node_core.hpp), its parameters from the parameter server.
class Node {
public:
    Node(ros::NodeHandle& nh, ros::NodeHandle& pn)
        : settings_(bvc3d::ros_node::read_settings(
              [&pn](const std::string& name, auto fallback) {
                  decltype(fallback) v;
                  pn.param(name, v, fallback);
                  return v;
              },
              "~")),
          core_(
              settings_, [this](const bvc3d::ros_node::NodeCore::Output& o) { publish(o); },
              [](const std::string& w) { ROS_WARN_THROTTLE(5, "bvc3d_ros: %s", w.c_str()); }) {
        bvc_pub_ = pn.advertise<std_msgs::Float32MultiArray>("bvc_rates", 10);
        place_pub_ = pn.advertise<std_msgs::Float32MultiArray>("place_rates", 10);
        decoded_pub_ = pn.advertise<geometry_msgs::PoseStamped>("decoded_pose", 10);
        revisit_pub_ = pn.advertise<std_msgs::Int64>("revisit", 10);
        distance_pub_ = pn.advertise<std_msgs::Float32>("revisit_distance", 10);
        latency_pub_ = pn.advertise<std_msgs::Float32>("latency", 10);
        dropped_pub_ = pn.advertise<std_msgs::Int64>("dropped", 10, true);
        const auto hints = ros::TransportHints().tcpNoDelay();
        cloud_sub_ = nh.subscribe<sensor_msgs::PointCloud2>(
            settings_.cloud_topic, 2,
            [this](const sensor_msgs::PointCloud2::ConstPtr& m) {
                core_.put([m] { return bvc3d::recording::cloud_message_of(*m, seconds(m->header.stamp)); });
            },
            nullptr, hints);
        auto& poses = core_.poses();
        const auto& p = settings_.poses;
        if (poses.uses_tf()) {
            tf_sub_ = nh.subscribe<tf2_msgs::TFMessage>(
                "/tf", 100, [this](const tf2_msgs::TFMessage::ConstPtr& m) { add_tf(*m, false); }, nullptr, hints);
            tf_static_sub_ = nh.subscribe<tf2_msgs::TFMessage>(
                "/tf_static", 100, [this](const tf2_msgs::TFMessage::ConstPtr& m) { add_tf(*m, true); }, nullptr,
                hints);
        } else if (p.pose_type == "odometry") {
            pose_sub_ = nh.subscribe<nav_msgs::Odometry>(
                p.pose_topic, 100,
                [this](const nav_msgs::Odometry::ConstPtr& m) {
                    add_pose(m->header.stamp, m->pose.pose.position, m->pose.pose.orientation);
                },
                nullptr, hints);
        } else {
            pose_sub_ = nh.subscribe<geometry_msgs::PoseStamped>(
                p.pose_topic, 100,
                [this](const geometry_msgs::PoseStamped::ConstPtr& m) {
                    add_pose(m->header.stamp, m->pose.position, m->pose.orientation);
                },
                nullptr, hints);
        }
        const auto& model = core_.model();
        ROS_INFO("bvc3d_ros: model %s (%zu BVCs, %zu place cells), %zu templates; clouds on %s, poses from %s",
                 model.model_name().c_str(), model.n_bvc(), model.n_place(), model.templates(),
                 cloud_sub_.getTopic().c_str(), poses.uses_tf() ? "tf" : pose_sub_.getTopic().c_str());
    }

    void stop() { core_.stop(); }
    std::size_t processed() const { return core_.processed(); }
    std::size_t dropped() const { return core_.dropped(); }
    std::size_t skipped() const { return core_.skipped(); }

private:
    void add_pose(const ros::Time& stamp, const geometry_msgs::Point& p, const geometry_msgs::Quaternion& q) {
        try {
            core_.poses().add_pose(seconds(stamp), {p.x, p.y, p.z}, Eigen::Quaterniond(q.w, q.x, q.y, q.z));
        } catch (const bvc3d::InputError& e) {
            ROS_WARN_THROTTLE(5, "bvc3d_ros: a pose is refused: %s", e.what());
        }
    }
    void add_tf(const tf2_msgs::TFMessage& m, bool is_static) {
        try {
            core_.poses().add_tf(transforms(m), is_static);
        } catch (const bvc3d::InputError& e) {
            ROS_WARN_THROTTLE(5, "bvc3d_ros: %s", e.what());
        }
    }
    void publish(const bvc3d::ros_node::NodeCore::Output& o) {
        const auto& r = o.result;
        std_msgs::Float32MultiArray bvc, place;
        bvc.data = r.bvc;
        place.data = r.place;
        bvc_pub_.publish(bvc);
        place_pub_.publish(place);
        if (r.decoded) {
            geometry_msgs::PoseStamped p;
            p.header.stamp.fromSec(o.stamp);
            p.header.frame_id = settings_.fixed_frame;
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
        latency.data = static_cast<float>(o.latency_s);
        latency_pub_.publish(latency);
        std_msgs::Int64 dropped;
        dropped.data = static_cast<std::int64_t>(o.dropped);
        dropped_pub_.publish(dropped);
    }

    bvc3d::ros_node::NodeSettings settings_;
    ros::Publisher bvc_pub_, place_pub_, decoded_pub_, revisit_pub_, distance_pub_, latency_pub_, dropped_pub_;
    ros::Subscriber cloud_sub_, pose_sub_, tf_sub_, tf_static_sub_;
    bvc3d::ros_node::NodeCore core_;  // last: its worker stops (in its destructor) before the publishers go
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
