// The other side of bvc3d_ros2 in its tests (test/python/test_ros2_node.py), on Cyclone DDS's C API and
// the ROS 2 message types of app/ros2/ros2_msgs.idl:
//   ros2_peer play BAG CLOUD_TOPIC POSE_TOPIC RATE   publishes a bag's clouds (sensor_msgs/msg/PointCloud2,
//       best effort, as a LiDAR driver does) and poses (nav_msgs/msg/Odometry, reliable) on rt/<topic>,
//       each pose just before its cloud, at RATE messages... scans per second; waits first until the
//       node's cloud reader is matched.
//   ros2_peer record NODE OUT                        writes what /NODE/... publishes, one line per message
//       ("bvc v...", "place v...", "revisit i", "distance d", "decoded x y z", "latency s", "dropped n"),
//       until SIGINT.
// The domain is ROS_DOMAIN_ID, the network what CYCLONEDDS_URI says (the tests: 127.0.0.1 only).
#include <dds/dds.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <thread>
#include <vector>

#include "bvc3d/recording/bag.hpp"
#include "ros2_msgs.h"

namespace {

std::atomic<bool> interrupted{false};
extern "C" void on_signal(int) { interrupted = true; }

dds_domainid_t domain() {
    const char* id = std::getenv("ROS_DOMAIN_ID");
    return id && *id ? static_cast<dds_domainid_t>(std::atoi(id)) : 0;
}

dds_entity_t endpoint(dds_entity_t participant, const dds_topic_descriptor_t& type, const std::string& topic,
                      bool reliable, bool read, bool transient_local = false) {
    const dds_entity_t t = dds_create_topic(participant, &type, topic.c_str(), nullptr, nullptr);
    dds_qos_t* q = dds_create_qos();
    dds_qset_reliability(q, reliable ? DDS_RELIABILITY_RELIABLE : DDS_RELIABILITY_BEST_EFFORT, DDS_SECS(1));
    dds_qset_history(q, DDS_HISTORY_KEEP_LAST, read ? 1000 : 10);
    if (transient_local) dds_qset_durability(q, DDS_DURABILITY_TRANSIENT_LOCAL);
    const dds_entity_t e =
        read ? dds_create_reader(participant, t, q, nullptr) : dds_create_writer(participant, t, q, nullptr);
    dds_delete_qos(q);
    if (e < 0) {
        std::fprintf(stderr, "ros2_peer: cannot create an endpoint on %s: %s\n", topic.c_str(), dds_strretcode(e));
        std::exit(1);
    }
    return e;
}

builtin_interfaces_msg_dds__Time_ stamp_of(double s) {
    builtin_interfaces_msg_dds__Time_ t;
    t.sec = static_cast<std::int32_t>(std::floor(s));
    t.nanosec = static_cast<std::uint32_t>(std::min(999999999.0, std::round((s - t.sec) * 1e9)));
    return t;
}

void wait_matched(dds_entity_t writer, const char* what) {
    for (int i = 0; i < 600; ++i) {
        dds_publication_matched_status_t s;
        dds_get_publication_matched_status(writer, &s);
        if (s.current_count > 0) return;
        std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
    std::fprintf(stderr, "ros2_peer: nothing subscribed to %s within 60 s\n", what);
    std::exit(1);
}

int play(const std::string& bag_path, const std::string& cloud_topic, const std::string& pose_topic, double rate) {
    const auto bag = bvc3d::recording::open_bag(bag_path);
    const std::size_t clouds = bag->topic(cloud_topic), poses = bag->topic(pose_topic);
    const dds_entity_t participant = dds_create_participant(domain(), nullptr, nullptr);
    const dds_entity_t cloud_writer =
        endpoint(participant, sensor_msgs_msg_dds__PointCloud2__desc, "rt" + cloud_topic, false, false);
    const dds_entity_t pose_writer =
        endpoint(participant, nav_msgs_msg_dds__Odometry__desc, "rt" + pose_topic, true, false);
    wait_matched(cloud_writer, cloud_topic.c_str());
    wait_matched(pose_writer, pose_topic.c_str());
    std::this_thread::sleep_for(std::chrono::milliseconds(500));  // the reliable reader's handshake settles
    const auto n = bag->topics()[clouds].count;
    auto next = std::chrono::steady_clock::now();
    for (std::size_t k = 0; k < n && !interrupted; ++k) {
        const auto c = bag->cloud(clouds, k);
        const auto p = bag->pose(poses, k);  // the export's poses: one per cloud, at its stamp
        nav_msgs_msg_dds__Odometry_ o{};
        o.header.stamp = stamp_of(p.stamp);
        o.header.frame_id = const_cast<char*>(p.parent.c_str());
        o.child_frame_id = const_cast<char*>(p.child.c_str());
        o.pose.pose.position = {p.translation.x(), p.translation.y(), p.translation.z()};
        o.pose.pose.orientation = {p.rotation.x(), p.rotation.y(), p.rotation.z(), p.rotation.w()};
        dds_write(pose_writer, &o);
        std::vector<sensor_msgs_msg_dds__PointField_> fields;
        for (const auto& f : c.fields)
            fields.push_back({const_cast<char*>(f.name.c_str()), f.offset, f.datatype, f.count});
        sensor_msgs_msg_dds__PointCloud2_ m{};
        m.header.stamp = stamp_of(c.stamp);
        m.header.frame_id = const_cast<char*>(c.frame_id.c_str());
        m.height = c.height;
        m.width = c.width;
        m.fields._buffer = fields.data();
        m.fields._length = m.fields._maximum = static_cast<std::uint32_t>(fields.size());
        m.is_bigendian = c.is_bigendian;
        m.point_step = c.point_step;
        m.row_step = c.row_step;
        m.data._buffer = const_cast<std::uint8_t*>(c.data.data());
        m.data._length = m.data._maximum = static_cast<std::uint32_t>(c.data.size());
        m.is_dense = true;
        std::this_thread::sleep_for(std::chrono::milliseconds(5));  // the pose first, as a robot's odometry
        dds_write(cloud_writer, &m);
        next +=
            std::chrono::duration_cast<std::chrono::steady_clock::duration>(std::chrono::duration<double>(1 / rate));
        std::this_thread::sleep_until(next);
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(500));
    dds_delete(participant);
    std::printf("played %zu scans\n", n);
    return 0;
}

template <class T>
bool take(dds_entity_t reader, T& sample) {
    void* buffers[1] = {&sample};
    dds_sample_info_t info;
    return dds_take(reader, buffers, &info, 1, 1) > 0 && info.valid_data;
}

int record(const std::string& node, const std::string& out_path) {
    std::FILE* out = std::fopen(out_path.c_str(), "w");
    if (!out) return 1;
    const dds_entity_t participant = dds_create_participant(domain(), nullptr, nullptr);
    const std::string at = "rt/" + node + "/";
    const auto& rates = std_msgs_msg_dds__Float32MultiArray__desc;
    const dds_entity_t bvc = endpoint(participant, rates, at + "bvc_rates", true, true);
    const dds_entity_t place = endpoint(participant, rates, at + "place_rates", true, true);
    const dds_entity_t revisit = endpoint(participant, std_msgs_msg_dds__Int64__desc, at + "revisit", true, true);
    const dds_entity_t distance =
        endpoint(participant, std_msgs_msg_dds__Float32__desc, at + "revisit_distance", true, true);
    const dds_entity_t decoded =
        endpoint(participant, geometry_msgs_msg_dds__PoseStamped__desc, at + "decoded_pose", true, true);
    const dds_entity_t latency = endpoint(participant, std_msgs_msg_dds__Float32__desc, at + "latency", true, true);
    const dds_entity_t dropped = endpoint(participant, std_msgs_msg_dds__Int64__desc, at + "dropped", true, true, true);
    std::fprintf(out, "ready\n");
    std::fflush(out);
    while (!interrupted) {
        bool any = false;
        for (const auto& [reader, tag] : {std::pair{bvc, "bvc"}, std::pair{place, "place"}}) {
            std_msgs_msg_dds__Float32MultiArray_ m{};
            while (take(reader, m)) {
                any = true;
                std::fprintf(out, "%s", tag);
                for (std::uint32_t i = 0; i < m.data._length; ++i) std::fprintf(out, " %.9g", m.data._buffer[i]);
                std::fprintf(out, "\n");
                dds_sample_free(&m, &rates, DDS_FREE_CONTENTS);
                m = {};
            }
        }
        std_msgs_msg_dds__Int64_ i{};
        while (take(revisit, i)) any = true, std::fprintf(out, "revisit %lld\n", static_cast<long long>(i.data));
        while (take(dropped, i)) any = true, std::fprintf(out, "dropped %lld\n", static_cast<long long>(i.data));
        std_msgs_msg_dds__Float32_ f{};
        while (take(distance, f)) any = true, std::fprintf(out, "distance %.9g\n", f.data);
        while (take(latency, f)) any = true, std::fprintf(out, "latency %.9g\n", f.data);
        geometry_msgs_msg_dds__PoseStamped_ p{};
        while (take(decoded, p)) {
            any = true;
            std::fprintf(out, "decoded %.17g %.17g %.17g\n", p.pose.position.x, p.pose.position.y, p.pose.position.z);
            dds_sample_free(&p, &geometry_msgs_msg_dds__PoseStamped__desc, DDS_FREE_CONTENTS);
            p = {};
        }
        std::fflush(out);
        if (!any) std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    dds_delete(participant);
    std::fclose(out);
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    std::signal(SIGINT, on_signal);
    std::signal(SIGTERM, on_signal);
    const std::vector<std::string> a(argv + 1, argv + argc);
    try {
        if (a.size() == 5 && a[0] == "play") return play(a[1], a[2], a[3], std::stod(a[4]));
        if (a.size() == 3 && a[0] == "record") return record(a[1], a[2]);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "ros2_peer: %s\n", e.what());
        return 1;
    }
    std::fprintf(stderr, "usage: ros2_peer play BAG CLOUD_TOPIC POSE_TOPIC RATE | record NODE OUT\n");
    return 2;
}
