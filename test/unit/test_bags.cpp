// Recording stage, ROS bags (docs/ros.md): the tf tree against rotations about one axis (whose slerp is
// the angle interpolated linearly), cloud layouts against their bytes, CDR against bytes laid out by
// hand, MCAP and ROS 1 bags written and read back, and corrupt files refused with their place named.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <fstream>

#include "../support/temp_dir.hpp"
#include "bvc3d/core/error.hpp"
#include "bvc3d/recording/bag.hpp"
#include "bvc3d/recording/bag_recording.hpp"
#include "bvc3d/recording/cdr.hpp"
#include "bvc3d/recording/mcap.hpp"
#include "bvc3d/recording/tf_tree.hpp"

using namespace bvc3d;
using namespace bvc3d::recording;

namespace {

StampedTransform link(double stamp, const std::string& parent, const std::string& child, Eigen::Vector3d p,
                      double yaw) {
    StampedTransform t;
    t.stamp = stamp;
    t.parent = parent;
    t.child = child;
    t.translation = p;
    t.rotation = Eigen::Quaterniond(std::cos(yaw / 2), 0, 0, std::sin(yaw / 2));
    return t;
}

template <class F>
std::string error_of(F&& f) {
    try {
        f();
    } catch (const InputError& e) {
        return e.what();
    }
    return "no error";
}

void append(std::vector<std::uint8_t>& out, const void* p, std::size_t n) {
    const auto* b = static_cast<const std::uint8_t*>(p);
    out.insert(out.end(), b, b + n);
}

}  // namespace

TEST(TfTree, InterpolatesEachLinkAndComposesTheChain) {
    TfTree tree;
    tree.add(link(0, "map", "odom", {1, 0, 0}, M_PI / 2), true);
    tree.add(link(10.0, "odom", "base", {0, 0, 0}, 0.0), false);
    tree.add(link(10.1, "/odom", "base", {2, 4, 0}, 1.0), false);
    const Eigen::Isometry3d m = tree.lookup("map", "base", 10.03, 0.2);
    // odom <- base at s = 0.3: (0.6, 1.2, 0), yaw 0.3; map <- odom turns it by 90 degrees and shifts by x.
    const double yaw = M_PI / 2 + 0.3;
    EXPECT_NEAR(m.translation().x(), 1 - 1.2, 1e-12);
    EXPECT_NEAR(m.translation().y(), 0.6, 1e-12);
    EXPECT_NEAR(m.translation().z(), 0, 1e-12);
    EXPECT_NEAR(m.linear()(0, 0), std::cos(yaw), 1e-12);
    EXPECT_NEAR(m.linear()(1, 0), std::sin(yaw), 1e-12);
    EXPECT_NEAR(m.linear()(2, 2), 1, 1e-12);
    // Before the first sample, within the tolerance: the first sample.
    EXPECT_NEAR(tree.lookup("map", "base", 9.9, 0.2).translation().x(), 1, 1e-12);
    EXPECT_NE(error_of([&] { tree.lookup("map", "base", 9.7, 0.2); }).find("starts at 10 s"), std::string::npos);
    EXPECT_NE(error_of([&] { tree.lookup("map", "base", 10.03, 0.05); }).find("gap of 0.1"), std::string::npos);
    EXPECT_NE(error_of([&] { tree.lookup("map", "lidar", 10.03, 0.2); }).find("lidar has no parent"),
              std::string::npos);
    EXPECT_NE(error_of([&] {
                  tree.add(link(10.0, "map", "base", {0, 0, 0}, 0), false);
              }).find("two parents"),
              std::string::npos);
}

TEST(CloudPoints, ReadsAnyLayoutAndByteOrder) {
    // Two rows of two points, big-endian, x float64 at 2, y float32 at 10, z float64 at 14, point step
    // 24, rows padded to 56 bytes; one point NaN.
    CloudMessage c;
    c.height = 2;
    c.width = 2;
    c.is_bigendian = true;
    c.point_step = 24;
    c.row_step = 56;
    c.fields = {{"z", 14, 8, 1}, {"x", 2, 8, 1}, {"y", 10, 7, 1}, {"rgb", 0, 2, 1}};
    const double pts[4][3] = {{1.5, -2.25, 3}, {NAN, 1, 1}, {-4, 0.5, 7.125}, {8, 9, -10}};
    auto be = [](auto v) {
        std::uint8_t b[sizeof v];
        std::memcpy(b, &v, sizeof v);
        std::reverse(b, b + sizeof v);
        std::vector<std::uint8_t> out(b, b + sizeof v);
        return out;
    };
    for (int r = 0; r < 2; ++r) {
        for (int i = 0; i < 2; ++i) {
            std::vector<std::uint8_t> p(24, 0xAB);
            const auto x = be(pts[2 * r + i][0]), y = be(static_cast<float>(pts[2 * r + i][1])),
                       z = be(pts[2 * r + i][2]);
            std::copy(x.begin(), x.end(), p.begin() + 2);
            std::copy(y.begin(), y.end(), p.begin() + 10);
            std::copy(z.begin(), z.end(), p.begin() + 14);
            c.data.insert(c.data.end(), p.begin(), p.end());
        }
        c.data.insert(c.data.end(), 8, 0xCD);  // row padding
    }
    const PointCloud cloud = cloud_points(c);
    EXPECT_EQ(cloud.dropped_nonfinite, 1u);
    EXPECT_EQ(cloud.xyz, (std::vector<double>{1.5, -2.25, 3, -4, 0.5, 7.125, 8, 9, -10}));

    CloudMessage no_z = c;
    no_z.fields.erase(no_z.fields.begin());
    EXPECT_NE(error_of([&] { cloud_points(no_z); }).find("no field 'z'"), std::string::npos);
    CloudMessage short_step = c;
    short_step.point_step = 20;
    EXPECT_NE(error_of([&] { cloud_points(short_step); }).find("point step"), std::string::npos);
    CloudMessage short_data = c;
    short_data.data.resize(60);
    EXPECT_NE(error_of([&] { cloud_points(short_data); }).find("data holds 60 bytes"), std::string::npos);
}

TEST(Cdr, ReadsBytesLaidOutByHand) {
    // nav_msgs/Odometry, little-endian: header (sec, nsec, "map"), "base", pose, then what is not read.
    std::vector<std::uint8_t> b{0, 1, 0, 0};
    const std::int32_t sec = 12;
    const std::uint32_t nsec = 500000000, n_map = 4, n_base = 5;
    append(b, &sec, 4);
    append(b, &nsec, 4);
    append(b, &n_map, 4);
    append(b, "map", 4);
    append(b, &n_base, 4);
    append(b, "base", 5);
    b.insert(b.end(), 7, 0);  // to 8-byte alignment: 4 + 4 + 4 + 4 + 4 + 5 = 25 bytes after the header
    const double pose[7] = {1, 2, 3, 0, 0, std::sin(0.25), std::cos(0.25)};
    append(b, pose, sizeof pose);
    const StampedTransform t = cdr::decode_odometry(b);
    EXPECT_DOUBLE_EQ(t.stamp, 12.5);
    EXPECT_EQ(t.parent, "map");
    EXPECT_EQ(t.child, "base");
    EXPECT_EQ(t.translation, Eigen::Vector3d(1, 2, 3));
    EXPECT_DOUBLE_EQ(t.rotation.w(), std::cos(0.25));
    // Cut inside the pose: truncated; an unknown encapsulation: refused.
    const std::vector<std::uint8_t> cut(b.begin(), b.begin() + 40);
    EXPECT_NE(error_of([&] { cdr::decode_odometry(cut); }).find("truncated"), std::string::npos);
    auto xcdr2 = b;
    xcdr2[1] = 0x07;
    EXPECT_NE(error_of([&] { cdr::decode_odometry(xcdr2); }).find("unknown encapsulation"), std::string::npos);
    // The encoder's cloud reads back.
    CloudMessage c;
    c.stamp = 3.25;
    c.frame_id = "lidar";
    c.height = 1;
    c.width = 1;
    c.fields = {{"x", 0, 7, 1}, {"y", 4, 7, 1}, {"z", 8, 7, 1}};
    c.point_step = 12;
    c.row_step = 12;
    const float xyz[3] = {1, 2, 3};
    append(c.data, xyz, 12);
    const CloudMessage back = cdr::decode_cloud(cdr::encode_cloud(c));
    EXPECT_EQ(back.frame_id, "lidar");
    EXPECT_EQ(back.data, c.data);
    EXPECT_DOUBLE_EQ(back.stamp, 3.25);
    EXPECT_EQ(back.fields.size(), 3u);
}

namespace {

CloudMessage small_cloud(double stamp) {
    CloudMessage c;
    c.stamp = stamp;
    c.frame_id = "lidar";
    c.height = 1;
    c.width = 3;
    c.fields = {{"x", 0, 7, 1}, {"y", 4, 7, 1}, {"z", 8, 7, 1}};
    c.point_step = 12;
    c.row_step = 36;
    const float xyz[9] = {1, 2, 3, static_cast<float>(stamp), 5, 6, 7, 8, 9};
    append(c.data, xyz, sizeof xyz);
    return c;
}

}  // namespace

TEST(Bags, McapAndRos1RoundTripsAndCorruptChunks) {
    const test::TempDir dir("bags");
    std::vector<CloudMessage> clouds;
    std::vector<StampedTransform> poses;
    for (int i = 0; i < 4; ++i) {
        clouds.push_back(small_cloud(2.0 + 0.5 * i));
        poses.push_back(link(2.0 + 0.5 * i, "map", "lidar", {double(i), 0, 0}, 0.1 * i));
    }
    for (const auto how : {McapCompression::none, McapCompression::zstd, McapCompression::lz4}) {
        const auto file = dir / ("x" + std::to_string(static_cast<int>(how)) + ".mcap");
        McapWriter w(file, how);
        const auto pc =
            w.add_channel("/points", "sensor_msgs/msg/PointCloud2", ros2_definition("sensor_msgs/msg/PointCloud2"));
        const auto od = w.add_channel("/odom", "nav_msgs/msg/Odometry", ros2_definition("nav_msgs/msg/Odometry"));
        for (std::size_t i = 0; i < clouds.size(); ++i) {
            const auto ns = static_cast<std::uint64_t>(std::llround(clouds[i].stamp * 1e9));
            w.write(od, ns, cdr::encode_odometry(poses[i]));
            w.write(pc, ns, cdr::encode_cloud(clouds[i]));
        }
        w.commit();
        BagSource s;
        s.bag = file;
        s.cloud_topic = "/points";
        s.pose_topic = "/odom";
        const Recording r = open_bag_recording(s);
        ASSERT_EQ(r.size(), 4u);
        EXPECT_EQ(r.load(1).xyz[3], 2.5);
        EXPECT_NEAR(r.poses[3].world_from_sensor.translation().x(), 3, 1e-15);
        EXPECT_NEAR(*r.time(2), 3.0, 1e-9);
        if (how == McapCompression::zstd) {  // flip a byte inside the chunk's compressed records
            std::string bytes;
            {
                std::ifstream in(file, std::ios::binary);
                bytes.assign(std::istreambuf_iterator<char>(in), {});
            }
            // Inside the chunk's compressed records: after its compression name and the records' length.
            const auto at = bytes.find("zstd") + 4 + 8 + 20;
            bytes[at] = static_cast<char>(bytes[at] ^ 0x5A);
            const auto broken = dir.write("broken.mcap", bytes);
            s.bag = broken;
            const std::string e = error_of([&] { open_bag_recording(s); });
            EXPECT_NE(e.find("broken.mcap"), std::string::npos) << e;
            EXPECT_NE(e.find("chunk 0"), std::string::npos) << e;
        }
    }
    const auto bag = dir / "x.bag";
    ros1::write_bag(bag, clouds, poses, "/points", "/odom");
    BagSource s;
    s.bag = bag;
    s.cloud_topic = "/points";
    s.tf_fixed = "map";
    s.tf_sensor = "lidar";
    const Recording r = open_bag_recording(s);
    ASSERT_EQ(r.size(), 4u);
    EXPECT_EQ(r.load(3).xyz[3], 3.5);
    EXPECT_NEAR(r.poses[2].world_from_sensor.translation().x(), 2, 1e-15);
    EXPECT_EQ(open_bag(bag)->format(), "ROS 1 bag");
    s.cloud_topic = "/odom";
    EXPECT_NE(error_of([&] { open_bag_recording(s); }).find("not sensor_msgs/PointCloud2"), std::string::npos);
}
