// bvc3d_ros2: the model on a robot running ROS 2 (docs/ros.md#the-ros-2-node), without ROS 2: a DDS
// participant (Eclipse Cyclone DDS, Debian's cyclonedds-dev) that follows ROS 2's conventions, so a
// ROS 2 graph sees it as a node's topics:
//   - a ROS topic /a/b is the DDS topic "rt/a/b"; the node's private topics are ~/x = /<node>/x;
//   - a message type pkg/msg/Name is the DDS type "pkg::msg::dds_::Name_" (ros2_msgs.idl, whose C
//     types and XCDR1 serializers Cyclone's idlc generates at build time);
//   - the cloud subscriber has ROS 2's sensor-data QoS (best effort, keep last 5, volatile), so a
//     best-effort LiDAR driver feeds it; the other topics ROS 2's default QoS (reliable, keep last 10,
//     volatile); ~/dropped is transient-local (kept for late subscribers, as ROS 1's latching);
//     /tf_static is read as tf2 reads it (reliable, transient local);
//   - the DDS domain is ROS_DOMAIN_ID (0 when unset); parameters come from a ROS 2 parameter file
//     (--ros-args --params-file FILE: `<node>:` or `/**:` then `ros__parameters:`) and
//     `-p name:=value` overrides (values read as YAML); `-r __node:=NAME` renames the node.
// It subscribes to sensor_msgs/msg/PointCloud2 and nav_msgs/msg/Odometry, geometry_msgs/msg/PoseStamped
// or /tf, and publishes what bvc3d_ros publishes (docs/ros.md#the-node): BVC and place-cell rates,
// the decoded pose, revisits and their distance, latency and dropped scans. The model, the poses and
// the one-slot queue with its worker are the ROS 1 node's (app/ros/node_core.hpp). SIGINT or SIGTERM:
// the scan in hand is finished, the counts printed, exit status 0.
#include <dds/dds.h>
#include <yaml-cpp/yaml.h>

#include <atomic>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "bvc3d/core/error.hpp"
#include "node_core.hpp"
#include "ros2_msgs.h"

namespace {

using bvc3d::InputError;
namespace node = bvc3d::ros_node;

std::atomic<bool> interrupted{false};
extern "C" void on_signal(int) { interrupted = true; }

// ---- Parameters: the node's name, its parameters (a YAML file and -p overrides) ----

struct Arguments {
    std::string node_name = "bvc3d_ros2", ns = "/";
    std::map<std::string, YAML::Node> params;
};

void read_params_file(const std::string& file, Arguments& a) {
    YAML::Node root;
    try {
        root = YAML::LoadFile(file);
    } catch (const YAML::Exception& e) {
        throw InputError("--params-file '" + file + "': " + e.what());
    }
    if (!root.IsMap()) throw InputError("--params-file '" + file + "': not a map of node names");
    const std::string full = (a.ns == "/" ? "/" : a.ns + "/") + a.node_name;
    for (const auto& entry : root) {
        const auto key = entry.first.as<std::string>();
        if (key != "/**" && key != a.node_name && key != full) continue;  // another node's
        const YAML::Node p = entry.second["ros__parameters"];
        if (!p || !p.IsMap())
            throw InputError("--params-file '" + file + "': '" + key + "' has no ros__parameters map");
        for (const auto& kv : p) a.params[kv.first.as<std::string>()] = kv.second;
    }
}

// bvc3d_ros2 [--ros-args [--params-file FILE] [-p NAME:=VALUE] [-r __node:=NAME] [-r __ns:=/NS] ...]
Arguments parse_arguments(int argc, char** argv) {
    Arguments a;
    std::vector<std::string> files, overrides;
    bool ros_args = false;
    for (int i = 1; i < argc; ++i) {
        const std::string arg = argv[i];
        const auto next = [&]() -> std::string {
            if (i + 1 >= argc) throw InputError("'" + arg + "' needs a value");
            return argv[++i];
        };
        if (arg == "--ros-args") ros_args = true;
        else if (arg == "--") ros_args = false;
        else if (arg == "--params-file") files.push_back(next());
        else if (ros_args && (arg == "-p" || arg == "--param")) overrides.push_back(next());
        else if (ros_args && (arg == "-r" || arg == "--remap")) {
            const std::string r = next();
            if (r.rfind("__node:=", 0) == 0) a.node_name = r.substr(8);
            else if (r.rfind("__ns:=", 0) == 0) a.ns = r.substr(6);
            else
                throw InputError("'-r " + r +
                                 "': only __node:= and __ns:= are understood (set the topics by parameter)");
        } else if (ros_args && (arg == "--log-level" || arg == "--enclave")) next();  // accepted, not used
        else
            throw InputError("unknown argument '" + arg +
                             "' (bvc3d_ros2 --ros-args --params-file FILE -p NAME:=VALUE)");
    }
    if (a.ns.empty() || a.ns[0] != '/') a.ns = "/" + a.ns;
    if (a.ns.size() > 1 && a.ns.back() == '/') a.ns.pop_back();
    for (const auto& f : files) read_params_file(f, a);
    for (const auto& o : overrides) {
        const auto at = o.find(":=");
        if (at == std::string::npos || at == 0) throw InputError("'-p " + o + "' is not NAME:=VALUE");
        try {
            a.params[o.substr(0, at)] = YAML::Load(o.substr(at + 2));
        } catch (const YAML::Exception& e) {
            throw InputError("'-p " + o + "': " + e.what());
        }
    }
    return a;
}

// A parameter's value as the type of its default; an unknown name is refused once all are read.
class Params {
public:
    explicit Params(std::map<std::string, YAML::Node> values) : values_(std::move(values)) {}
    template <class T>
    T operator()(const std::string& name, const T& fallback) {
        used_.push_back(name);
        const auto found = values_.find(name);
        if (found == values_.end() || found->second.IsNull()) return fallback;
        try {
            return found->second.as<T>();
        } catch (const YAML::Exception&) {
            throw InputError("parameter '" + name + "': '" + YAML::Dump(found->second) + "' is not a " + kind<T>());
        }
    }
    void check_all_known() const {
        for (const auto& [name, value] : values_)
            if (std::find(used_.begin(), used_.end(), name) == used_.end())
                throw InputError("unknown parameter '" + name + "' (docs/ros.md lists the node's parameters)");
    }

private:
    template <class T>
    static const char* kind() {
        if constexpr (std::is_same_v<T, bool>) return "boolean";
        else if constexpr (std::is_integral_v<T>) return "integer";
        else if constexpr (std::is_floating_point_v<T>) return "number";
        else return "string";
    }
    std::map<std::string, YAML::Node> values_;
    std::vector<std::string> used_;
};

// ---- ROS 2 names and QoS on DDS ----

// A ROS name as the node resolves it: absolute as is, ~/x in the node's namespace, x in its namespace.
std::string resolve(const std::string& name, const Arguments& a) {
    const std::string ns = a.ns == "/" ? "" : a.ns;
    if (name.rfind("~/", 0) == 0) return ns + "/" + a.node_name + name.substr(1);
    if (!name.empty() && name[0] == '/') return name;
    return ns + "/" + name;
}

std::string dds_topic(const std::string& ros_name) { return "rt" + ros_name; }

enum class Qos { sensor_data, default_profile, transient_local, tf_static };

dds_qos_t* qos_of(Qos profile) {
    dds_qos_t* q = dds_create_qos();
    switch (profile) {
        case Qos::sensor_data:  // rmw_qos_profile_sensor_data
            dds_qset_reliability(q, DDS_RELIABILITY_BEST_EFFORT, 0);
            dds_qset_history(q, DDS_HISTORY_KEEP_LAST, 5);
            dds_qset_durability(q, DDS_DURABILITY_VOLATILE);
            break;
        case Qos::default_profile:  // rmw_qos_profile_default
            dds_qset_reliability(q, DDS_RELIABILITY_RELIABLE, DDS_MSECS(100));
            dds_qset_history(q, DDS_HISTORY_KEEP_LAST, 10);
            dds_qset_durability(q, DDS_DURABILITY_VOLATILE);
            break;
        case Qos::transient_local:  // a latched publisher: the last value for late subscribers
            dds_qset_reliability(q, DDS_RELIABILITY_RELIABLE, DDS_MSECS(100));
            dds_qset_history(q, DDS_HISTORY_KEEP_LAST, 1);
            dds_qset_durability(q, DDS_DURABILITY_TRANSIENT_LOCAL);
            break;
        case Qos::tf_static:  // tf2_ros's static listener
            dds_qset_reliability(q, DDS_RELIABILITY_RELIABLE, DDS_MSECS(100));
            dds_qset_history(q, DDS_HISTORY_KEEP_LAST, 100);
            dds_qset_durability(q, DDS_DURABILITY_TRANSIENT_LOCAL);
            break;
    }
    return q;
}

void check(dds_return_t rc, const std::string& what) {
    if (rc < 0) throw std::runtime_error(what + ": " + dds_strretcode(rc));
}

class Participant {
public:
    explicit Participant(dds_domainid_t domain) {
        dds_qos_t* q = dds_create_qos();
        const char enclave[] = "enclave=/;";  // what ROS 2's rmw puts in the participant's user data
        dds_qset_userdata(q, enclave, sizeof enclave - 1);
        id_ = dds_create_participant(domain, q, nullptr);
        dds_delete_qos(q);
        check(id_, "cannot create the DDS participant (domain " + std::to_string(domain) + ")");
    }
    ~Participant() { dds_delete(id_); }
    Participant(const Participant&) = delete;
    Participant& operator=(const Participant&) = delete;
    dds_entity_t id() const { return id_; }

    dds_entity_t writer(const dds_topic_descriptor_t& type, const std::string& topic, Qos profile) {
        return endpoint(type, topic, profile, false);
    }
    dds_entity_t reader(const dds_topic_descriptor_t& type, const std::string& topic, Qos profile) {
        return endpoint(type, topic, profile, true);
    }

private:
    dds_entity_t endpoint(const dds_topic_descriptor_t& type, const std::string& topic, Qos profile, bool read) {
        const dds_entity_t t = dds_create_topic(id_, &type, topic.c_str(), nullptr, nullptr);
        check(t, "cannot create the DDS topic " + topic);
        dds_qos_t* q = qos_of(profile);
        const dds_entity_t e = read ? dds_create_reader(id_, t, q, nullptr) : dds_create_writer(id_, t, q, nullptr);
        dds_delete_qos(q);
        check(e, std::string("cannot create a DDS ") + (read ? "reader" : "writer") + " on " + topic);
        return e;
    }
    dds_entity_t id_;
};

// A sample taken from a reader, freed (with what Cyclone allocated inside it) when the last owner goes.
template <class T>
std::shared_ptr<T> take_one(dds_entity_t reader, const dds_topic_descriptor_t& type) {
    auto* sample = static_cast<T*>(dds_alloc(sizeof(T)));
    std::shared_ptr<T> owned(sample, [&type](T* p) { dds_sample_free(p, &type, DDS_FREE_ALL); });
    void* buffers[1] = {sample};
    dds_sample_info_t info;
    const dds_return_t n = dds_take(reader, buffers, &info, 1, 1);
    if (n <= 0 || !info.valid_data) return nullptr;
    return owned;
}

double seconds(const builtin_interfaces_msg_dds__Time_& t) { return t.sec + t.nanosec * 1e-9; }

builtin_interfaces_msg_dds__Time_ stamp_of(double s) {
    builtin_interfaces_msg_dds__Time_ t;
    t.sec = static_cast<std::int32_t>(std::floor(s));
    t.nanosec = static_cast<std::uint32_t>(std::min(999999999.0, std::round((s - t.sec) * 1e9)));
    return t;
}

bvc3d::recording::CloudMessage cloud_message(const sensor_msgs_msg_dds__PointCloud2_& m) {
    bvc3d::recording::CloudMessage c;
    c.stamp = seconds(m.header.stamp);
    c.frame_id = m.header.frame_id ? m.header.frame_id : "";
    c.height = m.height;
    c.width = m.width;
    for (std::uint32_t i = 0; i < m.fields._length; ++i) {
        const auto& f = m.fields._buffer[i];
        c.fields.push_back({f.name ? f.name : "", f.offset, f.datatype, f.count});
    }
    c.is_bigendian = m.is_bigendian;
    c.point_step = m.point_step;
    c.row_step = m.row_step;
    c.data.assign(m.data._buffer, m.data._buffer + m.data._length);
    return c;
}

std::vector<bvc3d::recording::StampedTransform> transforms(const tf2_msgs_msg_dds__TFMessage_& m) {
    std::vector<bvc3d::recording::StampedTransform> out;
    for (std::uint32_t i = 0; i < m.transforms._length; ++i) {
        const auto& t = m.transforms._buffer[i];
        bvc3d::recording::StampedTransform s;
        s.stamp = seconds(t.header.stamp);
        s.parent = t.header.frame_id ? t.header.frame_id : "";
        s.child = t.child_frame_id ? t.child_frame_id : "";
        s.translation = {t.transform.translation.x, t.transform.translation.y, t.transform.translation.z};
        const auto& q = t.transform.rotation;
        s.rotation = Eigen::Quaterniond(q.w, q.x, q.y, q.z);
        out.push_back(s);
    }
    return out;
}

// ---- The node ----

class Node {
public:
    Node(const Arguments& args, Params& params, dds_domainid_t domain)
        : settings_(node::read_settings(params, "")), participant_(domain) {
        params.check_all_known();
        const auto topic = [&](const std::string& name) { return dds_topic(resolve(name, args)); };
        bvc_ =
            participant_.writer(std_msgs_msg_dds__Float32MultiArray__desc, topic("~/bvc_rates"), Qos::default_profile);
        place_ = participant_.writer(std_msgs_msg_dds__Float32MultiArray__desc, topic("~/place_rates"),
                                     Qos::default_profile);
        decoded_ = participant_.writer(geometry_msgs_msg_dds__PoseStamped__desc, topic("~/decoded_pose"),
                                       Qos::default_profile);
        revisit_ = participant_.writer(std_msgs_msg_dds__Int64__desc, topic("~/revisit"), Qos::default_profile);
        distance_ =
            participant_.writer(std_msgs_msg_dds__Float32__desc, topic("~/revisit_distance"), Qos::default_profile);
        latency_ = participant_.writer(std_msgs_msg_dds__Float32__desc, topic("~/latency"), Qos::default_profile);
        dropped_ = participant_.writer(std_msgs_msg_dds__Int64__desc, topic("~/dropped"), Qos::transient_local);
        cloud_topic_ = resolve(settings_.cloud_topic, args);
        cloud_ = participant_.reader(sensor_msgs_msg_dds__PointCloud2__desc, dds_topic(cloud_topic_), Qos::sensor_data);
        const auto& p = settings_.poses;
        if (!p.fixed_frame_tf.empty()) {
            pose_source_ = "tf";
            tf_ = participant_.reader(tf2_msgs_msg_dds__TFMessage__desc, "rt/tf", Qos::default_profile);
            tf_static_ = participant_.reader(tf2_msgs_msg_dds__TFMessage__desc, "rt/tf_static", Qos::tf_static);
        } else {
            pose_source_ = resolve(p.pose_topic, args);
            pose_ = participant_.reader(
                p.pose_type == "odometry" ? nav_msgs_msg_dds__Odometry__desc : geometry_msgs_msg_dds__PoseStamped__desc,
                dds_topic(pose_source_), Qos::default_profile);
        }
        core_ = std::make_unique<node::NodeCore>(
            settings_, [this](const node::NodeCore::Output& o) { publish(o); },
            [](const std::string& w) { std::fprintf(stderr, "bvc3d_ros2: warning: %s\n", w.c_str()); });
        const auto& m = core_->model();
        std::printf(
            "bvc3d_ros2: model %s (%zu BVCs, %zu place cells), %zu templates; clouds on %s, poses from %s; "
            "DDS domain %u\n",
            m.model_name().c_str(), m.n_bvc(), m.n_place(), m.templates(), cloud_topic_.c_str(), pose_source_.c_str(),
            static_cast<unsigned>(domain));
    }

    // Until SIGINT/SIGTERM: wait on the readers, take what came.
    void spin() {
        const dds_entity_t waitset = dds_create_waitset(participant_.id());
        check(waitset, "cannot create a DDS waitset");
        for (const dds_entity_t r : {cloud_, pose_, tf_, tf_static_})
            if (r > 0) check(dds_waitset_attach(waitset, dds_create_readcondition(r, DDS_ANY_STATE), r), "waitset");
        while (!interrupted) {
            dds_attach_t woke[4];
            const dds_return_t n = dds_waitset_wait(waitset, woke, 4, DDS_MSECS(100));
            for (dds_return_t i = 0; i < n; ++i) drain(static_cast<dds_entity_t>(woke[i]));
        }
        dds_delete(waitset);
        core_->stop();
    }
    const node::NodeCore& core() const { return *core_; }

private:
    void drain(dds_entity_t reader) {
        if (reader == cloud_) {
            while (auto m = take_one<sensor_msgs_msg_dds__PointCloud2_>(cloud_, sensor_msgs_msg_dds__PointCloud2__desc))
                core_->put([m] { return cloud_message(*m); });
        } else if (reader == tf_ || reader == tf_static_) {
            while (auto m = take_one<tf2_msgs_msg_dds__TFMessage_>(reader, tf2_msgs_msg_dds__TFMessage__desc))
                warn_on_refusal([&] { core_->poses().add_tf(transforms(*m), reader == tf_static_); });
        } else if (settings_.poses.pose_type == "odometry") {
            while (auto m = take_one<nav_msgs_msg_dds__Odometry_>(reader, nav_msgs_msg_dds__Odometry__desc))
                add_pose(m->header.stamp, m->pose.pose);
        } else {
            while (auto m =
                       take_one<geometry_msgs_msg_dds__PoseStamped_>(reader, geometry_msgs_msg_dds__PoseStamped__desc))
                add_pose(m->header.stamp, m->pose);
        }
    }
    void add_pose(const builtin_interfaces_msg_dds__Time_& stamp, const geometry_msgs_msg_dds__Pose_& p) {
        const auto& q = p.orientation;
        warn_on_refusal([&] {
            core_->poses().add_pose(seconds(stamp), {p.position.x, p.position.y, p.position.z},
                                    Eigen::Quaterniond(q.w, q.x, q.y, q.z));
        });
    }
    template <class F>
    static void warn_on_refusal(F&& f) {
        try {
            f();
        } catch (const InputError& e) {
            std::fprintf(stderr, "bvc3d_ros2: warning: %s\n", e.what());
        }
    }

    static void write(dds_entity_t writer, const void* sample, const char* what) {
        if (const dds_return_t rc = dds_write(writer, sample); rc < 0)
            std::fprintf(stderr, "bvc3d_ros2: warning: cannot publish %s (%s)\n", what, dds_strretcode(rc));
    }
    static void write_rates(dds_entity_t writer, const std::vector<float>& rates, const char* what) {
        std_msgs_msg_dds__Float32MultiArray_ m{};
        m.data._buffer = const_cast<float*>(rates.data());  // serialized from here, not freed
        m.data._length = m.data._maximum = static_cast<std::uint32_t>(rates.size());
        m.data._release = false;
        write(writer, &m, what);
    }
    void publish(const node::NodeCore::Output& o) {
        const auto& r = o.result;
        write_rates(bvc_, r.bvc, "~/bvc_rates");
        write_rates(place_, r.place, "~/place_rates");
        if (r.decoded) {
            geometry_msgs_msg_dds__PoseStamped_ p{};
            p.header.stamp = stamp_of(o.stamp);
            p.header.frame_id = const_cast<char*>(settings_.fixed_frame.c_str());
            const auto& T = r.decoded->world_from_sensor;
            p.pose.position = {T.translation().x(), T.translation().y(), T.translation().z()};
            const Eigen::Quaterniond q(T.linear());
            p.pose.orientation = {q.x(), q.y(), q.z(), q.w()};
            write(decoded_, &p, "~/decoded_pose");
        }
        if (r.revisit) {
            const std_msgs_msg_dds__Int64_ index{r.revisit->scan};
            const std_msgs_msg_dds__Float32_ distance{static_cast<float>(r.revisit->distance)};
            write(revisit_, &index, "~/revisit");
            write(distance_, &distance, "~/revisit_distance");
        }
        const std_msgs_msg_dds__Float32_ latency{static_cast<float>(o.latency_s)};
        write(latency_, &latency, "~/latency");
        const std_msgs_msg_dds__Int64_ dropped{static_cast<std::int64_t>(o.dropped)};
        write(dropped_, &dropped, "~/dropped");
    }

    node::NodeSettings settings_;
    Participant participant_;
    dds_entity_t bvc_ = 0, place_ = 0, decoded_ = 0, revisit_ = 0, distance_ = 0, latency_ = 0, dropped_ = 0;
    dds_entity_t cloud_ = 0, pose_ = 0, tf_ = 0, tf_static_ = 0;
    std::string cloud_topic_, pose_source_;
    std::unique_ptr<node::NodeCore> core_;  // last: its worker stops before the writers go
};

dds_domainid_t domain_id() {
    const char* text = std::getenv("ROS_DOMAIN_ID");
    if (!text || !*text) return 0;
    char* end = nullptr;
    const long id = std::strtol(text, &end, 10);
    if (*end != '\0' || id < 0 || id > 232)
        throw InputError(std::string("ROS_DOMAIN_ID '") + text + "' is not a domain id (0 to 232)");
    return static_cast<dds_domainid_t>(id);
}

}  // namespace

int main(int argc, char** argv) {
    std::setvbuf(stdout, nullptr, _IOLBF, 0);
    try {
        const Arguments args = parse_arguments(argc, argv);
        Params params(args.params);
        Node n(args, params, domain_id());
        std::signal(SIGINT, on_signal);
        std::signal(SIGTERM, on_signal);
        n.spin();
        std::fprintf(stderr, "bvc3d_ros2: stopped after %zu scans (%zu dropped while busy, %zu skipped)\n",
                     n.core().processed(), n.core().dropped(), n.core().skipped());
    } catch (const InputError& e) {
        std::fprintf(stderr, "bvc3d: error: %s\n", e.what());
        return 2;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "bvc3d_ros2: %s\n", e.what());
        return 1;
    }
    return 0;
}
