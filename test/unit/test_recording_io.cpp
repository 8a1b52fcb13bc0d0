// Recording stage: scan readers/writers (PCD, PLY, KITTI .bin), scan lists, pose files, pairing,
// extrinsics, and the errors malformed files give (file name + reason). Hand-made files are built
// byte by byte here, independently of the writers.
#include <gtest/gtest.h>
#include <lzf.h>
#include <signal.h>
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <numbers>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "../support/temp_dir.hpp"
#include "bvc3d/core/error.hpp"
#include "bvc3d/recording/extrinsics.hpp"
#include "bvc3d/recording/kitti_bin.hpp"
#include "bvc3d/recording/pairing.hpp"
#include "bvc3d/recording/pcd.hpp"
#include "bvc3d/recording/ply.hpp"
#include "bvc3d/recording/pose_file.hpp"
#include "bvc3d/recording/scan_file.hpp"
#include "bvc3d/recording/scan_list.hpp"

using namespace bvc3d;
using namespace bvc3d::recording;
namespace fs = std::filesystem;

namespace {

const double not_a_number = std::numeric_limits<double>::quiet_NaN();
const double infinity = std::numeric_limits<double>::infinity();

using bvc3d::test::TempDir;

// ---- bytes, built by hand ----

template <class T>
std::string little(T value) {
    std::string bytes(sizeof(T), '\0');
    std::memcpy(bytes.data(), &value, sizeof(T));
    if constexpr (std::endian::native == std::endian::big) std::reverse(bytes.begin(), bytes.end());
    return bytes;
}

template <class T>
std::string big(T value) {
    std::string bytes = little(value);
    std::reverse(bytes.begin(), bytes.end());
    return bytes;
}

std::string lzf(const std::string& block) {
    std::string packed(block.size() * 2 + 64, '\0');
    const unsigned size = lzf_compress(block.data(), static_cast<unsigned>(block.size()), packed.data(),
                                       static_cast<unsigned>(packed.size()));
    EXPECT_GT(size, 0u);
    packed.resize(size);
    return packed;
}

std::string pcd_header(const std::string& fields, const std::string& size, const std::string& type,
                       const std::string& count, std::size_t width, std::size_t height, const std::string& data) {
    return "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\nFIELDS " + fields + "\nSIZE " + size + "\nTYPE " +
           type + "\nCOUNT " + count + "\nWIDTH " + std::to_string(width) + "\nHEIGHT " + std::to_string(height) +
           "\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS " + std::to_string(width * height) + "\nDATA " + data + "\n";
}

// Three points, x y z float, for the error cases to corrupt.
std::string xyz_header(const std::string& data, std::size_t points = 3) {
    return pcd_header("x y z", "4 4 4", "F F F", "1 1 1", points, 1, data);
}
const std::string xyz_ascii_body = "1 2 3\n4 5 6\n7 8 9\n";

using Points = std::vector<std::array<double, 3>>;

void expect_points(const PointCloud& cloud, const Points& expected) {
    ASSERT_EQ(cloud.size(), expected.size());
    for (std::size_t i = 0; i < expected.size(); ++i)
        for (std::size_t k = 0; k < 3; ++k)
            EXPECT_EQ(cloud.xyz[3 * i + k], expected[i][k]) << "point " << i << " axis " << k;
}

PointCloud random_cloud(std::size_t n, unsigned seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> coordinate(-60.0, 60.0);
    PointCloud cloud;
    for (std::size_t i = 0; i < 3 * n; ++i) cloud.xyz.push_back(coordinate(rng));
    cloud.xyz[0] = 1e-7;  // small and exact-looking values, too
    cloud.xyz[1] = 0.1;
    cloud.xyz[2] = -0.0;
    return cloud;
}

// The cloud as a float32 writer stores it.
PointCloud rounded_to_float(PointCloud cloud) {
    for (double& v : cloud.xyz) v = static_cast<float>(v);
    return cloud;
}

// `action` throws InputError whose message names `file` and contains every one of `reasons`.
void expect_input_error(const std::function<void()>& action, const std::string& file,
                        const std::vector<std::string>& reasons) {
    try {
        action();
        ADD_FAILURE() << "no InputError; expected: " << (reasons.empty() ? "" : reasons.front());
    } catch (const InputError& e) {
        const std::string message = e.what();
        EXPECT_NE(message.find(file), std::string::npos) << "file '" << file << "' not named in: " << message;
        for (const std::string& reason : reasons)
            EXPECT_NE(message.find(reason), std::string::npos) << "expected '" << reason << "' in: " << message;
    }
}

// Writing `bytes` as `name` and reading it as a scan fails with `reasons`.
void expect_scan_error(const std::string& name, const std::string& bytes, const std::vector<std::string>& reasons) {
    TempDir dir;
    const fs::path file = dir.write(name, bytes);
    expect_input_error([&] { read_scan(file); }, file.string(), reasons);
}

void expect_pose_error(const std::string& text, PoseFormat format, const std::vector<std::string>& reasons) {
    TempDir dir;
    const fs::path file = dir.write("poses.txt", text);
    expect_input_error([&] { read_poses(file, format); }, file.string(), reasons);
}

// R = I + sin θ K + (1 − cos θ) K², K the cross-product matrix of the unit axis (Rodrigues).
Eigen::Matrix3d rodrigues(Eigen::Vector3d axis, double angle) {
    axis.normalize();
    Eigen::Matrix3d k;
    k << 0, -axis.z(), axis.y(), axis.z(), 0, -axis.x(), -axis.y(), axis.x(), 0;
    return Eigen::Matrix3d::Identity() + std::sin(angle) * k + (1 - std::cos(angle)) * k * k;
}

Eigen::Isometry3d pose_of(const Eigen::Vector3d& axis, double angle, const Eigen::Vector3d& translation) {
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    pose.linear() = rodrigues(axis, angle);
    pose.translation() = translation;
    return pose;
}

}  // namespace

// ======================= Round trips: writer -> reader =======================

TEST(RecordingRoundTrip, PcdEveryEncodingAndPrecision) {
    TempDir dir;
    const PointCloud cloud = random_cloud(1000, 1);
    for (const PcdEncoding encoding : {PcdEncoding::ascii, PcdEncoding::binary, PcdEncoding::binary_compressed})
        for (const PcdPrecision precision : {PcdPrecision::f4, PcdPrecision::f8}) {
            SCOPED_TRACE("encoding " + std::to_string(static_cast<int>(encoding)) + " precision " +
                         std::to_string(static_cast<int>(precision)));
            const fs::path file = dir / "cloud.pcd";
            write_pcd(file, cloud, encoding, precision);
            const PointCloud back = read_pcd(file);
            // F8 is exact; F4 is the float32 rounding, the same for every encoding.
            EXPECT_EQ(back.xyz, precision == PcdPrecision::f8 ? cloud.xyz : rounded_to_float(cloud).xyz);
            EXPECT_EQ(back.dropped_nonfinite, 0u);
        }
}

TEST(RecordingRoundTrip, PlyEveryEncodingAndPrecision) {
    TempDir dir;
    const PointCloud cloud = random_cloud(1000, 2);
    for (const PlyEncoding encoding :
         {PlyEncoding::ascii, PlyEncoding::binary_little_endian, PlyEncoding::binary_big_endian})
        for (const PlyPrecision precision : {PlyPrecision::float32, PlyPrecision::float64}) {
            SCOPED_TRACE("encoding " + std::to_string(static_cast<int>(encoding)) + " precision " +
                         std::to_string(static_cast<int>(precision)));
            const fs::path file = dir / "cloud.ply";
            write_ply(file, cloud, encoding, precision);
            const PointCloud back = read_ply(file);
            EXPECT_EQ(back.xyz, precision == PlyPrecision::float64 ? cloud.xyz : rounded_to_float(cloud).xyz);
        }
}

TEST(RecordingRoundTrip, KittiBin) {
    TempDir dir;
    const PointCloud cloud = random_cloud(1000, 3);
    write_kitti_bin(dir / "000000.bin", cloud);
    EXPECT_EQ(fs::file_size(dir / "000000.bin"), 16u * 1000);
    EXPECT_EQ(read_scan(dir / "000000.bin").xyz, rounded_to_float(cloud).xyz);
}

TEST(RecordingRoundTrip, NonFinitePointsAreWrittenAndDroppedOnRead) {
    TempDir dir;
    PointCloud cloud;
    cloud.xyz = {1, 2, 3, not_a_number, 0, 0, 4, infinity, 6, 7, 8, 9};
    write_pcd(dir / "a.pcd", cloud, PcdEncoding::ascii);
    write_pcd(dir / "b.pcd", cloud, PcdEncoding::binary_compressed);
    write_ply(dir / "c.ply", cloud, PlyEncoding::binary_big_endian);
    for (const char* name : {"a.pcd", "b.pcd", "c.ply"}) {
        const PointCloud back = read_scan(dir / name);
        expect_points(back, {{1, 2, 3}, {7, 8, 9}});
        EXPECT_EQ(back.dropped_nonfinite, 2u) << name;
    }
}

TEST(RecordingRoundTrip, ReadScanChoosesTheReaderByExtensionInAnyCase) {
    TempDir dir;
    const PointCloud cloud = random_cloud(10, 4);
    write_pcd(dir / "A.PCD", cloud, PcdEncoding::binary, PcdPrecision::f8);
    write_ply(dir / "b.Ply", cloud, PlyEncoding::ascii, PlyPrecision::float64);
    EXPECT_EQ(read_scan(dir / "A.PCD").xyz, cloud.xyz);
    EXPECT_EQ(read_scan(dir / "b.Ply").xyz, cloud.xyz);
    EXPECT_EQ(scan_format_of("x.bin"), ScanFormat::kitti_bin);
    EXPECT_FALSE(scan_format_of("x.las").has_value());
}

// ======================= Writers: all or nothing =======================

TEST(RecordingWriters, FailedWriteLeavesNoFileAndNamesTheReason) {
    // Writers go through core/atomic_file, as every output of the program does: a missing folder
    // is created; a target that is a folder, or a folder path through a file, is an error.
    TempDir dir;
    const PointCloud cloud = random_cloud(10, 5);
    write_pcd(dir / "missing" / "a.pcd", cloud, PcdEncoding::binary, PcdPrecision::f8);
    EXPECT_EQ(read_pcd(dir / "missing" / "a.pcd").xyz, cloud.xyz);
    fs::create_directories(dir / "folder.pcd");
    expect_input_error([&] { write_pcd(dir / "folder.pcd", cloud); }, (dir / "folder.pcd").string(),
                       {"is a folder, not a file"});
    write_kitti_bin(dir / "file.bin", cloud);
    expect_input_error([&] { write_ply(dir / "file.bin" / "a.ply", cloud); }, (dir / "file.bin").string(),
                       {"is not a folder"});
    EXPECT_EQ(dir.file_count(), 3u);  // the two folders and file.bin: no temporary left behind
    EXPECT_EQ(std::distance(fs::directory_iterator(dir / "folder.pcd"), fs::directory_iterator()), 0);
}

TEST(RecordingWriters, WriteErrorKeepsTheOldFileAndRemovesTheTemporary) {
    // A file-size limit makes write() fail as a full disk would (EFBIG instead of ENOSPC).
    TempDir dir;
    const fs::path file = dir / "scan.pcd";
    const PointCloud small = random_cloud(10, 6);
    write_pcd(file, small, PcdEncoding::binary, PcdPrecision::f8);
    const auto old_size = fs::file_size(file);

    rlimit saved{};
    ASSERT_EQ(getrlimit(RLIMIT_FSIZE, &saved), 0);
    const auto old_handler = signal(SIGXFSZ, SIG_IGN);
    rlimit limited = saved;
    limited.rlim_cur = 4096;
    ASSERT_EQ(setrlimit(RLIMIT_FSIZE, &limited), 0);
    std::string message;
    try {
        write_pcd(file, random_cloud(100000, 7), PcdEncoding::binary);
    } catch (const InputError& e) {
        message = e.what();
    }
    setrlimit(RLIMIT_FSIZE, &saved);
    signal(SIGXFSZ, old_handler);

    EXPECT_NE(message.find(file.string()), std::string::npos) << message;
    EXPECT_NE(message.find("cannot write"), std::string::npos) << message;
    EXPECT_NE(message.find("File too large"), std::string::npos) << message;
    EXPECT_EQ(fs::file_size(file), old_size);
    EXPECT_EQ(read_pcd(file).xyz, small.xyz);
    EXPECT_EQ(dir.file_count(), 1u);
}

TEST(RecordingWriters, WritesReadableFiles) {
    TempDir dir;
    write_kitti_bin(dir / "a.bin", random_cloud(5, 8));
    EXPECT_EQ(fs::status(dir / "a.bin").permissions() & fs::perms::others_read, fs::perms::others_read);
}

TEST(RecordingWriters, RejectsAPartialPoint) {
    TempDir dir;
    PointCloud cloud;
    cloud.xyz = {1, 2, 3, 4};
    expect_input_error([&] { write_ply(dir / "a.ply", cloud); }, (dir / "a.ply").string(), {"not a multiple of 3"});
}

// ======================= PCD, hand-made =======================

TEST(RecordingPcd, AsciiWithExtraFieldsAndCounts) {
    const std::string text =
        pcd_header("x y z intensity normal", "4 4 4 2 4", "F F F U F", "1 1 1 1 3", 2, 1, "ascii") +
        "1.5 -2 3 7 0.1 0.2 0.3\n-4 5.25 6e1 65535 1 2 3\n";
    TempDir dir;
    expect_points(read_scan(dir.write("a.pcd", text)), {{1.5, -2, 3}, {-4, 5.25, 60}});
}

TEST(RecordingPcd, AsciiFloatValuesReadAsFloat32AndCrlfAndShortVersion) {
    const std::string text =
        "VERSION .7\r\nFIELDS x y z\r\nSIZE 4 4 8\r\nTYPE F F F\r\nWIDTH 1\r\nHEIGHT 1\r\nPOINTS 1\r\nDATA ascii\r\n"
        "0.1 0.2 0.3\r\n";
    TempDir dir;
    expect_points(read_pcd(dir.write("a.pcd", text)), {{double(0.1f), double(0.2f), 0.3}});
}

TEST(RecordingPcd, AsciiPaddingFieldsHaveNoValues) {
    // PCL writes no values for "_" padding fields in ascii.
    const std::string text =
        pcd_header("x y z _ i", "4 4 4 1 4", "F F F U F", "1 1 1 4 1", 1, 1, "ascii") + "1 2 3 9\n";
    TempDir dir;
    expect_points(read_pcd(dir.write("a.pcd", text)), {{1, 2, 3}});
}

TEST(RecordingPcd, BinaryWithFieldsBeforeBetweenAndAfterXyz) {
    // label U1×3 | x F4 | y F4 | intensity U2 | z F8 | normal F4×2 = 3+4+4+2+8+8 = 29 bytes, unaligned.
    std::string text =
        pcd_header("label x y intensity z normal", "1 4 4 2 8 4", "U F F U F F", "3 1 1 1 1 2", 2, 1, "binary");
    const Points points = {{1.25, -2.5, 1e-3}, {100, 200, -300.125}};
    for (std::size_t i = 0; i < points.size(); ++i)
        text += "abc" + little(float(points[i][0])) + little(float(points[i][1])) + little(std::uint16_t(65535)) +
                little(points[i][2]) + little(1.0f) + little(2.0f);
    TempDir dir;
    expect_points(read_pcd(dir.write("a.pcd", text)), points);
}

TEST(RecordingPcd, OrganizedCloudDropsNaNAndInfPoints) {
    // WIDTH 3 × HEIGHT 2, as a LiDAR driver writes it: "no return" cells are NaN.
    std::string text = pcd_header("x y z", "4 4 4", "F F F", "1 1 1", 3, 2, "binary");
    const float fnan = std::numeric_limits<float>::quiet_NaN(), finf = std::numeric_limits<float>::infinity();
    const std::vector<std::array<float, 3>> cells = {{1, 2, 3},    {fnan, fnan, fnan}, {4, 5, 6},
                                                     {7, finf, 9}, {fnan, 0, 0},       {10, 11, 12}};
    for (const auto& c : cells) text += little(c[0]) + little(c[1]) + little(c[2]);
    TempDir dir;
    const PointCloud cloud = read_pcd(dir.write("a.pcd", text));
    expect_points(cloud, {{1, 2, 3}, {4, 5, 6}, {10, 11, 12}});
    EXPECT_EQ(cloud.dropped_nonfinite, 3u);
}

TEST(RecordingPcd, OrganizedAsciiWithNaN) {
    const std::string text =
        pcd_header("x y z", "4 4 4", "F F F", "1 1 1", 2, 2, "ascii") + "nan nan nan\n1 2 3\n4 5 6\nNaN 1 1\n";
    TempDir dir;
    const PointCloud cloud = read_pcd(dir.write("a.pcd", text));
    expect_points(cloud, {{1, 2, 3}, {4, 5, 6}});
    EXPECT_EQ(cloud.dropped_nonfinite, 2u);
}

TEST(RecordingPcd, BinaryCompressedBuiltByHand) {
    // Field-major block: all x (F4), all y (F4), all z (F8), all intensity (U1), then LZF.
    const Points points = {{1, 2, 3}, {-4.5, 5.5, 6.25}, {7, 8, 9}, {0.5, 0.25, 0.125}};
    std::string block;
    for (const auto& p : points) block += little(float(p[0]));
    for (const auto& p : points) block += little(float(p[1]));
    for (const auto& p : points) block += little(p[2]);
    for (std::size_t i = 0; i < points.size(); ++i) block += char(i);
    const std::string packed = lzf(block);
    const std::string text = pcd_header("x y z intensity", "4 4 8 1", "F F F U", "1 1 1 1", 4, 1, "binary_compressed") +
                             little(std::uint32_t(packed.size())) + little(std::uint32_t(block.size())) + packed;
    TempDir dir;
    expect_points(read_pcd(dir.write("a.pcd", text)), points);
}

// ======================= PLY, hand-made =======================

TEST(RecordingPly, AsciiWithFacesAndExtraProperties) {
    const std::string text =
        "ply\nformat ascii 1.0\ncomment made by hand\nobj_info none\nelement vertex 3\nproperty float x\n"
        "property uchar red\nproperty float y\nproperty double z\nproperty float32 nx\n"
        "element face 2\nproperty list uchar int vertex_indices\nproperty int flags\nend_header\n"
        "1 255 2 3.5 0\n-1 0 -2 -3.5 1\n\n0.5 7 0.25 0.125 0\n3 0 1 2 9\n4 0 1 2 0 8\n";
    TempDir dir;
    expect_points(read_scan(dir.write("a.ply", text)), {{1, 2, 3.5}, {-1, -2, -3.5}, {0.5, 0.25, 0.125}});
}

TEST(RecordingPly, BigEndianWithFacesAndExtraVertexProperties) {
    std::string text =
        "ply\r\nformat binary_big_endian 1.0\r\nelement vertex 2\r\nproperty float x\r\nproperty float y\r\n"
        "property float z\r\nproperty uchar red\r\nproperty double quality\r\nproperty short s\r\n"
        "element face 2\r\nproperty list uchar int vertex_indices\r\nproperty float area\r\nend_header\r\n";
    text += big(1.5f) + big(-2.0f) + big(3.25f) + char(200) + big(0.5) + big(std::int16_t(-7));
    text += big(4.0f) + big(5.0f) + big(-6.0f) + char(1) + big(1.5) + big(std::int16_t(7));
    text += char(3) + big(std::int32_t(0)) + big(std::int32_t(1)) + big(std::int32_t(0)) + big(2.0f);
    text += char(0) + big(0.0f);
    TempDir dir;
    expect_points(read_ply(dir.write("a.ply", text)), {{1.5, -2, 3.25}, {4, 5, -6}});
}

TEST(RecordingPly, LittleEndianWithListsBeforeAndInsideTheVertexElement) {
    std::string text =
        "ply\nformat binary_little_endian 1.0\nelement camera 1\nproperty list int float params\n"
        "element vertex 2\nproperty double x\nproperty list ushort char tags\nproperty float y\nproperty float64 z\n"
        "end_header\n";
    text += little(std::int32_t(2)) + little(1.0f) + little(2.0f);
    text += little(1.0 / 3) + little(std::uint16_t(2)) + "ab" + little(0.5f) + little(-7.0);
    text += little(-1e3) + little(std::uint16_t(0)) + little(2.5f) + little(1e-9);
    TempDir dir;
    expect_points(read_ply(dir.write("a.ply", text)), {{1.0 / 3, 0.5, -7}, {-1e3, 2.5, 1e-9}});
}

// ======================= KITTI, hand-made =======================

TEST(RecordingKitti, BinByHand) {
    const std::string bytes = little(1.0f) + little(-2.0f) + little(3.5f) + little(0.7f) + little(10.0f) +
                              little(20.0f) + little(30.0f) + little(0.0f);
    TempDir dir;
    expect_points(read_scan(dir.write("000001.bin", bytes)), {{1, -2, 3.5}, {10, 20, 30}});
}

// ======================= Broken files =======================

TEST(RecordingFileErrors, MissingFolderEmptyAndUnknown) {
    TempDir dir;
    expect_input_error([&] { read_scan(dir / "nope.pcd"); }, (dir / "nope.pcd").string(), {"no such file"});
    fs::create_directories(dir / "folder.ply");
    expect_input_error([&] { read_scan(dir / "folder.ply"); }, (dir / "folder.ply").string(),
                       {"is a folder, expected a file"});
    expect_input_error([] { read_pcd("/dev/null"); }, "/dev/null", {"not a regular file"});
    expect_scan_error("empty.pcd", "", {"empty file"});
    expect_scan_error("empty.bin", "", {"empty file"});
    expect_scan_error("scan.xyz", "1 2 3\n", {"unknown scan file extension '.xyz'"});
    expect_scan_error("scan", "1 2 3\n", {"unknown scan file extension"});
}

TEST(RecordingPcdErrors, Header) {
    const std::string body = xyz_ascii_body;
    expect_scan_error("a.pcd", "hello world\n" + body, {"line 1", "not a PCD file"});
    expect_scan_error("a.pcd", std::string("\x89PNG\r\n\x1a\n", 8), {"not a PCD file"});
    expect_scan_error("a.pcd", "# only a comment\n", {"not a PCD file: no header"});
    expect_scan_error("a.pcd", "VERSION 0.6\nFIELDS x y z\n", {"line 1", "unsupported PCD version '0.6'"});
    expect_scan_error("a.pcd", "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\n", {"header has no DATA line"});
    expect_scan_error("a.pcd", "VERSION 0.7\nSIZE 4 4 4\nTYPE F F F\nWIDTH 3\nHEIGHT 1\nDATA ascii\n" + body,
                      {"header has no FIELDS line"});
    expect_scan_error("a.pcd", "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nHEIGHT 1\nDATA ascii\n" + body,
                      {"header has no WIDTH line"});
    expect_scan_error("a.pcd", "VERSION 0.7\nFIELDS x y z\nBOGUS 1\n", {"line 3", "unknown header entry 'BOGUS'"});
    expect_scan_error("a.pcd", "FIELDS x y z\nWIDTH 3\nWIDTH 3\n", {"line 3", "second WIDTH line"});
    expect_scan_error("a.pcd", pcd_header("x y z", "4 4 4", "F F F", "1 1 1", 3, 1, "lzma") + body,
                      {"line 11", "unknown DATA encoding 'lzma'"});
}

TEST(RecordingPcdErrors, Fields) {
    const std::string body = xyz_ascii_body;
    expect_scan_error("a.pcd", pcd_header("a y z", "4 4 4", "F F F", "1 1 1", 3, 1, "ascii") + body,
                      {"line 3", "missing field 'x'"});
    expect_scan_error("a.pcd", pcd_header("x y x", "4 4 4", "F F F", "1 1 1", 3, 1, "ascii") + body,
                      {"field 'x' appears twice"});
    expect_scan_error("a.pcd", pcd_header("x y z", "4 4 4", "U F F", "1 1 1", 3, 1, "ascii") + body,
                      {"line 5", "field 'x' is TYPE U SIZE 4", "must be float"});
    expect_scan_error("a.pcd", pcd_header("x y z", "4 2 4", "F F F", "1 1 1", 3, 1, "ascii") + body,
                      {"field 'y' is TYPE F SIZE 2", "must be float"});
    expect_scan_error("a.pcd", pcd_header("x y z", "4 4 4", "F F F", "1 1 2", 3, 1, "ascii") + body,
                      {"line 6", "field 'z' has COUNT 2"});
    expect_scan_error("a.pcd", pcd_header("x y z", "4 4", "F F F", "1 1 1", 3, 1, "ascii") + body,
                      {"line 4", "SIZE has 2 entries but FIELDS (line 3) has 3"});
    expect_scan_error("a.pcd", pcd_header("x y z", "4 4 4", "F F F F", "1 1 1", 3, 1, "ascii") + body,
                      {"line 5", "TYPE has 4 entries but FIELDS (line 3) has 3"});
    expect_scan_error("a.pcd", pcd_header("x y z", "4 4 4", "F F F", "1 1", 3, 1, "ascii") + body,
                      {"line 6", "COUNT has 2 entries but FIELDS (line 3) has 3"});
    expect_scan_error("a.pcd", pcd_header("x y z", "4 4 3", "F F F", "1 1 1", 3, 1, "ascii") + body,
                      {"SIZE of field 'z' is '3'"});
    expect_scan_error("a.pcd", pcd_header("x y z", "4 4 4", "F F D", "1 1 1", 3, 1, "ascii") + body,
                      {"TYPE of field 'z' is 'D'"});
    expect_scan_error("a.pcd", pcd_header("x y z i", "4 4 4 4", "F F F U", "1 1 1 0", 3, 1, "ascii") + body,
                      {"COUNT of field 'i' is '0'"});
}

TEST(RecordingPcdErrors, PointCounts) {
    std::string text = xyz_header("ascii") + xyz_ascii_body;
    text.replace(text.find("POINTS 3"), 8, "POINTS 4");
    expect_scan_error("a.pcd", text, {"line 10", "POINTS 4 does not equal WIDTH * HEIGHT = 3 * 1 = 3"});
    std::string huge = xyz_header("binary");
    huge.replace(huge.find("WIDTH 3"), 7, "WIDTH 4294967296");
    huge.replace(huge.find("HEIGHT 1"), 8, "HEIGHT 4294967296");
    huge.replace(huge.find("POINTS 3"), 8, "POINTS 0");
    expect_scan_error("a.pcd", huge, {"WIDTH * HEIGHT is too large"});
    expect_scan_error("a.pcd", xyz_header("binary", 0), {"empty scan"});
    expect_scan_error("a.pcd", xyz_header("ascii", 0), {"empty scan"});
}

TEST(RecordingPcdErrors, AsciiData) {
    expect_scan_error("a.pcd", xyz_header("ascii") + "1 2 3\n4 5 6\n",
                      {"truncated", "declares 3 points", "has 2 lines"});
    expect_scan_error("a.pcd", xyz_header("ascii") + xyz_ascii_body + "\n10 11 12\n",
                      {"line 16", "trailing data after the 3 points"});
    expect_scan_error("a.pcd", xyz_header("ascii") + "1 2 3\n4 five 6\n7 8 9\n",
                      {"line 13", "bad number 'five' in field 'y'"});
    expect_scan_error("a.pcd", xyz_header("ascii") + "1 2 3\n4 5\n7 8 9\n",
                      {"line 13", "expected 3 values for point 1, found 2"});
    expect_scan_error("a.pcd", xyz_header("ascii") + "nan 1 1\n1 inf 1\n1 1 -inf\n", {"empty scan", "3 dropped"});
}

TEST(RecordingPcdErrors, BinaryData) {
    std::string points;
    for (int i = 0; i < 9; ++i) points += little(float(i));
    expect_scan_error("a.pcd", xyz_header("binary") + points.substr(0, 35),
                      {"truncated", "3 points of 12 bytes needs 36 bytes but only 35"});
    expect_scan_error("a.pcd", xyz_header("binary") + points + "\n", {"trailing data: 1 bytes"});
    // A header claiming 10^12 points must not make the reader allocate for them.
    expect_scan_error("a.pcd", xyz_header("binary", 1000000000000) + points,
                      {"truncated", "needs 12000000000000 bytes"});
    std::string nans;
    for (int i = 0; i < 9; ++i) nans += little(std::numeric_limits<float>::quiet_NaN());
    expect_scan_error("a.pcd", xyz_header("binary") + nans, {"empty scan"});
}

TEST(RecordingPcdErrors, CompressedData) {
    std::string block;
    for (int i = 0; i < 9; ++i) block += little(float(i));
    const std::string packed = lzf(block);
    const std::string header = xyz_header("binary_compressed");
    const auto sizes = [](std::size_t compressed, std::size_t uncompressed) {
        return little(std::uint32_t(compressed)) + little(std::uint32_t(uncompressed));
    };
    TempDir dir;
    EXPECT_EQ(read_pcd(dir.write("ok.pcd", header + sizes(packed.size(), 36) + packed)).size(), 3u);
    expect_scan_error("a.pcd", header + "abc", {"truncated", "8-byte size header"});
    expect_scan_error("a.pcd", header + sizes(packed.size(), 40) + packed,
                      {"compressed size mismatch", "unpacks to 40 bytes", "3 points of 12 bytes = 36"});
    expect_scan_error("a.pcd", header + sizes(packed.size() + 5, 36) + packed, {"truncated"});
    expect_scan_error("a.pcd", header + sizes(packed.size(), 36) + packed + "xy", {"trailing data: 2 bytes"});
    expect_scan_error("a.pcd", header + sizes(6, 36) + "\xff\xff\xff\xff\xff\xff", {"LZF decompression failed"});
    // A block claiming far more than LZF can unpack from its size is refused before allocating.
    expect_scan_error("a.pcd", xyz_header("binary_compressed", 100000000) + sizes(4, 1200000000) + "abcd",
                      {"compressed size mismatch", "cannot unpack to 1200000000 bytes"});
}

TEST(RecordingPlyErrors, Header) {
    const std::string vertex = "element vertex 1\nproperty float x\nproperty float y\nproperty float z\n";
    expect_scan_error("a.ply", "plx\nformat ascii 1.0\nend_header\n", {"line 1", "not a PLY file"});
    expect_scan_error("a.ply", "ply\nformat ascii\n", {"line 2", "bad format line"});
    expect_scan_error("a.ply", "ply\nformat binary_middle_endian 1.0\n", {"unknown PLY format 'binary_middle_endian'"});
    expect_scan_error("a.ply", "ply\nformat ascii 2.0\n", {"unsupported PLY version '2.0'"});
    expect_scan_error("a.ply", "ply\n" + vertex + "end_header\n1 2 3\n", {"header has no format line"});
    expect_scan_error("a.ply", "ply\nformat ascii 1.0\n" + vertex, {"header has no end_header line"});
    expect_scan_error("a.ply", "ply\nformat ascii 1.0\n" + vertex + "1 2 3\n",
                      {"line 7", "unknown header line '1' (is end_header missing?)"});
    expect_scan_error("a.ply", "ply\nformat ascii 1.0\nproperty float x\n", {"line 3", "property before any element"});
    expect_scan_error("a.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float128 x\n",
                      {"line 4", "unknown property type 'float128'"});
    expect_scan_error("a.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty list float int x\n",
                      {"list length type 'float' is not an integer type"});
    expect_scan_error("a.ply", "ply\nformat ascii 1.0\nelement vertex many\n", {"bad element count 'many'"});
    expect_scan_error("a.ply", "ply\nformat ascii 1.0\nelement face 0\nend_header\n", {"header has no vertex element"});
    expect_scan_error("a.ply",
                      "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float z\nend_header\n",
                      {"line 3", "vertex element has no 'y' property"});
    expect_scan_error("a.ply",
                      "ply\nformat ascii 1.0\nelement vertex 1\nproperty int x\nproperty float y\nproperty float z\n"
                      "end_header\n1 2 3\n",
                      {"vertex property 'x' is of type 'int'", "must be float or double"});
    expect_scan_error("a.ply", "ply\nformat ascii 1.0\n" + vertex + "property float x\n",
                      {"line 7", "property 'x' appears twice"});
    expect_scan_error("a.ply", "ply\nformat ascii 1.0\n" + vertex + "bogus\n", {"unknown header line 'bogus'"});
    expect_scan_error("a.ply", "ply\nformat ascii 1.0\n" + vertex + "proprety float w\nend_header\n1 2 3\n",
                      {"line 7", "unknown header line 'proprety'"});
}

TEST(RecordingPlyErrors, AsciiData) {
    const std::string header =
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
        "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";
    expect_scan_error("a.ply", header + "1 2 3\n4 5 6\n", {"truncated", "claims 3 vertices", "ends at vertex 2"});
    expect_scan_error("a.ply", header + "1 2 3\n4 5 6\n7 8 9\n", {"truncated", "claims 1 'face' elements"});
    expect_scan_error("a.ply", header + "1 2 3\n4 5 6\n7 8 9\n3 0 1\n", {"line 13", "too few values for face 0"});
    expect_scan_error("a.ply", header + "1 2 3\n4 5 6 7\n7 8 9\n3 0 1 2\n",
                      {"line 11", "too many values for vertex 1: 4 given, its properties take 3"});
    expect_scan_error("a.ply", header + "1 2 3\n4 x 6\n7 8 9\n3 0 1 2\n", {"line 11", "bad number 'x' in vertex 1"});
    expect_scan_error("a.ply", header + "1 2 3\n4 5 6\n7 8 9\n-3 0 1 2\n", {"bad list length '-3' in face 0"});
    expect_scan_error("a.ply", header + "1 2 3\n4 5 6\n7 8 9\n3 0 1 2\n0 0 0\n", {"line 14", "trailing data"});
    expect_scan_error("a.ply", header + "nan 2 3\n4 nan 6\n7 8 nan\n3 0 1 2\n", {"empty scan"});
}

TEST(RecordingPlyErrors, BinaryData) {
    const std::string header =
        "ply\nformat binary_little_endian 1.0\nelement vertex 2\nproperty float x\n"
        "property float y\nproperty float z\nelement face 1\nproperty list char int idx\n"
        "end_header\n";
    const std::string vertices =
        little(1.0f) + little(2.0f) + little(3.0f) + little(4.0f) + little(5.0f) + little(6.0f);
    const std::string face = char(2) + little(std::int32_t(0)) + little(std::int32_t(1));
    TempDir dir;
    EXPECT_EQ(read_ply(dir.write("ok.ply", header + vertices + face)).size(), 2u);
    expect_scan_error("a.ply", header + vertices.substr(0, 20),
                      {"truncated", "claims 2 vertices of 12 bytes but only 20 bytes remain"});
    expect_scan_error("a.ply", header + vertices + face.substr(0, 6), {"truncated", "ends at face 0"});
    expect_scan_error("a.ply", header + vertices + char(-1), {"face 0", "negative list length -1"});
    expect_scan_error("a.ply", header + vertices + face + "!", {"trailing data: 1 bytes"});
    // A header claiming 10^15 vertices must not make the reader allocate for them.
    std::string huge = header;
    huge.replace(huge.find("vertex 2"), 8, "vertex 1000000000000000");
    expect_scan_error("a.ply", huge + vertices + face, {"truncated", "claims 1000000000000000 vertices"});
    std::string empty = header;
    empty.replace(empty.find("vertex 2"), 8, "vertex 0");
    expect_scan_error("a.ply", empty + face, {"empty scan"});
}

TEST(RecordingKittiErrors, SizeAndEmptyScan) {
    expect_scan_error("a.bin", std::string(20, '\0'), {"size 20 bytes is not a multiple of 16"});
    const float fnan = std::numeric_limits<float>::quiet_NaN();
    expect_scan_error("a.bin", little(fnan) + little(1.0f) + little(1.0f) + little(0.0f), {"empty scan"});
}

// ======================= Scan lists =======================

TEST(RecordingScanList, NaturalOrder) {
    EXPECT_TRUE(natural_less("2.pcd", "10.pcd"));
    EXPECT_FALSE(natural_less("10.pcd", "2.pcd"));
    EXPECT_TRUE(natural_less("scan9.pcd", "scan10.pcd"));
    EXPECT_TRUE(natural_less("a2b3", "a2b12"));
    EXPECT_TRUE(natural_less("0009.pcd", "0010.pcd"));
    EXPECT_TRUE(natural_less("1.pcd", "01.pcd"));  // same number: fewer leading zeros first
    EXPECT_FALSE(natural_less("x.pcd", "x.pcd"));
    EXPECT_TRUE(natural_less("a", "ab"));
    EXPECT_TRUE(natural_less("a.pcd", "b.pcd"));
}

TEST(RecordingScanList, FolderInNaturalOrderWithoutOtherFiles) {
    TempDir dir;
    for (const char* name : {"10.pcd", "2.ply", "1.bin", "notes.txt", "poses.csv"}) dir.write(name, "x");
    fs::create_directories(dir / "sub.pcd");
    const auto scans = list_scans(dir.path());
    ASSERT_EQ(scans.size(), 3u);
    EXPECT_EQ(scans[0].path.filename(), "1.bin");
    EXPECT_EQ(scans[1].path.filename(), "2.ply");
    EXPECT_EQ(scans[2].path.filename(), "10.pcd");
    EXPECT_FALSE(scans[0].time.has_value());
}

TEST(RecordingScanList, ListFileWithTimesCommentsAndRelativePaths) {
    TempDir dir;
    dir.write("scans/a.pcd", "x");
    dir.write("scans/b c.pcd", "x");
    const fs::path absolute = dir.write("elsewhere/d.bin", "x");
    const fs::path list = dir.write(
        "scans/list.txt", "# scans of the hall\n\na.pcd 10.5\n  b c.pcd,11\n" + absolute.string() + " , 12.25\n");
    const auto scans = list_scans(list);
    ASSERT_EQ(scans.size(), 3u);
    EXPECT_EQ(scans[0].path, dir / "scans/a.pcd");
    EXPECT_EQ(scans[1].path, dir / "scans/b c.pcd");
    EXPECT_EQ(scans[2].path, absolute);
    EXPECT_EQ(scan_times(scans), (std::vector<std::optional<double>>{10.5, 11.0, 12.25}));
}

TEST(RecordingScanList, ListFileWithoutTimesAndSingleScan) {
    TempDir dir;
    dir.write("a.pcd", "x");
    dir.write("b.ply", "x");
    const auto scans = list_scans(dir.write("list", "a.pcd\nb.ply\n"));
    ASSERT_EQ(scans.size(), 2u);
    EXPECT_FALSE(scans[1].time.has_value());
    const auto single = list_scans(dir / "a.pcd");
    ASSERT_EQ(single.size(), 1u);
    EXPECT_EQ(single[0].path, dir / "a.pcd");
}

TEST(RecordingScanList, Errors) {
    TempDir dir;
    dir.write("a.pcd", "x");
    const auto expect_list_error = [&](const std::string& text, const std::vector<std::string>& reasons) {
        const fs::path list = dir.write("list.txt", text);
        expect_input_error([&] { list_scans(list); }, list.string(), reasons);
    };
    expect_list_error("a.pcd 1\nmissing.pcd 2\n", {"line 2", "scan file '", "missing.pcd' not found"});
    expect_list_error("a.pcd 1\na.txt 2\n", {"line 2", "unknown extension"});
    expect_list_error("a.pcd 1\n\na.pcd\n", {"line 3", "has no time but line 1 has one"});
    expect_list_error("a.pcd\na.pcd 5\n", {"line 2", "has a time but line 1 has none"});
    expect_list_error("a.pcd inf\n", {"line 1", "not finite"});
    expect_list_error("# nothing\n\n", {"the list names no scans"});
    expect_input_error([&] { list_scans(dir / "nothing"); }, (dir / "nothing").string(), {"no such file or folder"});
    fs::create_directories(dir / "empty");
    dir.write("empty/readme.md", "x");
    expect_input_error([&] { list_scans(dir / "empty"); }, (dir / "empty").string(), {"no scan files"});
}

// ======================= Poses =======================

TEST(RecordingPoses, Kitti) {
    TempDir dir;
    const fs::path file = dir.write("00.txt",
                                    "1 0 0 0.5 0 1 0 -1 0 0 1 2\n"
                                    "0 -1 0 10 1 0 0 20 0 0 1 30\n");
    const auto poses = read_poses(file, PoseFormat::kitti);
    ASSERT_EQ(poses.size(), 2u);
    EXPECT_TRUE(poses[0].world_from_sensor.translation().isApprox(Eigen::Vector3d(0.5, -1, 2)));
    EXPECT_TRUE(poses[1].world_from_sensor.linear().isApprox(rodrigues({0, 0, 1}, std::numbers::pi / 2), 1e-15));
    EXPECT_EQ((poses[1].world_from_sensor * Eigen::Vector3d(1, 0, 0)), Eigen::Vector3d(10, 21, 30));
    EXPECT_FALSE(poses[0].time.has_value());
    EXPECT_EQ(detect_pose_format(file), PoseFormat::kitti);
}

TEST(RecordingPoses, TumQuaternionMatchesAxisAngle) {
    // q = (axis · sin(θ/2), cos(θ/2)) for the axis-angle pair; the reader's rotation must be
    // Rodrigues' matrix of the same pair.
    const Eigen::Vector3d axis = Eigen::Vector3d(1, -2, 0.5).normalized();
    const double angle = 0.7;
    const Eigen::Vector3d v = axis * std::sin(angle / 2);
    std::ostringstream text;
    text.precision(17);
    text << "# timestamp tx ty tz qx qy qz qw\n"
         << "1630577758.5 1 2 3 " << v.x() << " " << v.y() << " " << v.z() << " " << std::cos(angle / 2) << "\n"
         << "1630577759.5 0 0 0 0 0 0 1.0004\n";  // norm within 1e-3 of 1: normalized
    TempDir dir;
    const fs::path file = dir.write("traj.txt", text.str());
    const auto poses = read_poses(file, PoseFormat::tum);
    ASSERT_EQ(poses.size(), 2u);
    EXPECT_LT((poses[0].world_from_sensor.linear() - rodrigues(axis, angle)).cwiseAbs().maxCoeff(), 1e-14);
    EXPECT_EQ(poses[0].world_from_sensor.translation(), Eigen::Vector3d(1, 2, 3));
    EXPECT_EQ(*poses[0].time, 1630577758.5);
    EXPECT_LT((poses[1].world_from_sensor.linear() - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff(), 1e-15);
    EXPECT_EQ(detect_pose_format(file), PoseFormat::tum);
}

TEST(RecordingPoses, MatrixWithTimesAndTrailingCommas) {
    TempDir dir;
    const fs::path file = dir.write("poses.csv",
                                    "1,0,0,1.5,\n0,1,0,2,\n0,0,1,3,\n0,0,0,100.25,\n"
                                    "0 -1 0 0\n1 0 0 0\n0 0 1 0\n0 0 0 101.25\n");
    const auto poses = read_poses(file);
    ASSERT_EQ(poses.size(), 2u);
    EXPECT_EQ(*poses[0].time, 100.25);
    EXPECT_EQ(*poses[1].time, 101.25);
    EXPECT_EQ(poses[0].world_from_sensor.translation(), Eigen::Vector3d(1.5, 2, 3));
    EXPECT_EQ(detect_pose_format(file), PoseFormat::matrix);
}

TEST(RecordingPoses, MatrixWithBottomRowsAllOneHasNoTimes) {
    TempDir dir;
    const auto poses = read_poses(dir.write("poses.txt",
                                            "1 0 0 0\n0 1 0 0\n0 0 1 0\n0 0 0 1\n"
                                            "1 0 0 1\n0 1 0 0\n0 0 1 0\n0 0 0 1\n"),
                                  PoseFormat::matrix);
    ASSERT_EQ(poses.size(), 2u);
    EXPECT_FALSE(poses[0].time.has_value());
    EXPECT_FALSE(poses[1].time.has_value());
}

TEST(RecordingPoses, FormatNames) {
    EXPECT_EQ(parse_pose_format("kitti"), PoseFormat::kitti);
    EXPECT_EQ(parse_pose_format("tum"), PoseFormat::tum);
    EXPECT_EQ(parse_pose_format("matrix"), PoseFormat::matrix);
    EXPECT_EQ(parse_pose_format("auto"), PoseFormat::detect);
    EXPECT_THROW(parse_pose_format("csv"), InputError);
}

TEST(RecordingPoses, WritersRoundTrip) {
    std::vector<PoseRecord> poses;
    for (int i = 0; i < 5; ++i)
        poses.push_back({pose_of({1, 2, 3.0 + i}, 0.3 * i, {0.1 * i, -2.0 / 3, 1e5 + i}), 1630577758.569490 + i});
    TempDir dir;
    write_kitti_poses(dir / "k.txt", poses);
    write_tum_poses(dir / "t.txt", poses);
    write_matrix_poses(dir / "m.csv", poses);
    const auto kitti = read_poses(dir / "k.txt");
    const auto tum = read_poses(dir / "t.txt");
    const auto matrix = read_poses(dir / "m.csv");
    ASSERT_EQ(kitti.size(), 5u);
    ASSERT_EQ(tum.size(), 5u);
    ASSERT_EQ(matrix.size(), 5u);
    for (std::size_t i = 0; i < poses.size(); ++i) {
        EXPECT_EQ(kitti[i].world_from_sensor.matrix(), poses[i].world_from_sensor.matrix());
        EXPECT_EQ(matrix[i].world_from_sensor.matrix(), poses[i].world_from_sensor.matrix());
        EXPECT_EQ(matrix[i].time, poses[i].time);
        EXPECT_EQ(tum[i].time, poses[i].time);
        EXPECT_EQ(tum[i].world_from_sensor.translation(), poses[i].world_from_sensor.translation());
        EXPECT_LT((tum[i].world_from_sensor.linear() - poses[i].world_from_sensor.linear()).cwiseAbs().maxCoeff(),
                  1e-14);
    }
    poses[2].time.reset();
    expect_input_error([&] { write_tum_poses(dir / "t2.txt", poses); }, (dir / "t2.txt").string(),
                       {"pose 2 without a time"});
    expect_input_error([&] { write_matrix_poses(dir / "m2.csv", poses); }, (dir / "m2.csv").string(),
                       {"pose 2 without a time"});
    for (PoseRecord& pose : poses) pose.time.reset();
    write_matrix_poses(dir / "m3.csv", poses);
    EXPECT_FALSE(read_poses(dir / "m3.csv")[0].time.has_value());
}

TEST(RecordingPoseErrors, DetectionAndCounts) {
    expect_pose_error("1 2 3 4 5 6 7\n", PoseFormat::detect, {"line 1", "cannot tell the pose format: 7 values"});
    expect_pose_error("1 0 0 0 0 1 0 0 0 0 1 0\n0 0 0 0 0 0 1 1\n", PoseFormat::detect,
                      {"line 2", "cannot tell the pose format: 8 values here but 12 on line 1"});
    expect_pose_error("# nothing\n\n", PoseFormat::detect, {"no poses"});
    expect_pose_error("1 0 0 0 0 1 0 0 0 0 1\n", PoseFormat::kitti, {"line 1", "expected 12 values", "found 11"});
    expect_pose_error("0 0 0 0 0 0 0 1\n1 2\n", PoseFormat::tum, {"line 2", "expected 8 values", "found 2"});
    expect_pose_error("1 0 0 0\n0 1 0 0\n0 0 1 0\n0 0 0 5\n1 0 0 0\n0 1 0 0\n", PoseFormat::matrix,
                      {"line 5", "truncated: the last pose has only 2 of its 4 matrix rows"});
    expect_pose_error("1 0 0 0\n0 1 0 0\n0 0 1 0\n0 0.5 0 5\n", PoseFormat::matrix,
                      {"line 4", "the 4th row of a pose matrix must be 0 0 0 T"});
    expect_pose_error("1 0 0 0\n0 1 0\n0 0 1 0\n0 0 0 5\n", PoseFormat::matrix, {"line 2", "expected 4 values"});
}

TEST(RecordingPoseErrors, ValuesAndRotations) {
    expect_pose_error("1 0 0 0 0 1 0 nan 0 0 1 0\n", PoseFormat::kitti, {"line 1", "value 'nan' is not finite"});
    expect_pose_error("1 0 0 0 0 1 0 inf 0 0 1 0\n", PoseFormat::detect, {"line 1", "value 'inf' is not finite"});
    expect_pose_error("1 0 0 0 0 1 0 x 0 0 1 0\n", PoseFormat::kitti, {"line 1", "bad number 'x'"});
    expect_pose_error("\n1 0 0 0 0 1 0 0 0 0 1 0\n2 0 0 0 0 1 0 0 0 0 1 0\n", PoseFormat::kitti,
                      {"line 3 (pose 1)", "not a rotation: max |R^T R - I| = 3"});
    expect_pose_error("1 0 0 0 0 1 0 0 0 0 -1 0\n", PoseFormat::kitti, {"line 1 (pose 0)", "determinant -1"});
    expect_pose_error("1 0 0 0 0 0 0 1.1\n", PoseFormat::tum, {"line 1", "quaternion norm 1.1"});
    expect_pose_error("1 0 0 0 0 0 0 0\n", PoseFormat::tum, {"line 1", "zero quaternion"});
    expect_pose_error("1,0,0,0,\n0,1,0,0,\n0,0,1.01,0,\n0,0,0,7,\n", PoseFormat::detect,
                      {"line 1 (pose 0)", "not a rotation"});
}

// ======================= Pairing =======================

TEST(RecordingPairing, InOrderWhenCountsAgree) {
    const std::vector<PoseRecord> poses(3);
    const auto pairing = pair_scans_with_poses({std::nullopt, std::nullopt, std::nullopt}, poses);
    EXPECT_EQ(pairing.pose_of_scan, (std::vector<std::size_t>{0, 1, 2}));
    EXPECT_FALSE(pairing.by_time);
}

TEST(RecordingPairing, ByNearestTimeWithinTolerance) {
    std::vector<PoseRecord> poses;
    for (const double t : {10.0, 10.5, 11.0, 11.5, 12.0}) poses.push_back({Eigen::Isometry3d::Identity(), t});
    std::swap(poses[1], poses[3]);  // pose times need not be sorted
    const auto pairing = pair_scans_with_poses({10.02, 11.49, 11.97}, poses);
    EXPECT_TRUE(pairing.by_time);
    EXPECT_EQ(pairing.pose_of_scan, (std::vector<std::size_t>{0, 1, 4}));
}

TEST(RecordingPairing, Errors) {
    std::vector<PoseRecord> poses;
    for (const double t : {10.0, 11.0}) poses.push_back({Eigen::Isometry3d::Identity(), t});
    expect_input_error(
        [&] {
            pair_scans_with_poses({10.0, 10.5, 11.0}, poses, 0.05);
        },
        "scan 1", {"time 10.5 s", "nearest pose time is 10 s", "0.5 s away", "tolerance 0.05 s"});
    expect_input_error(
        [&] {
            pair_scans_with_poses({10.0, std::nullopt, 11.0}, poses);
        },
        "3 scans but 2 poses", {"counts differ", "no times are available", "the scans have no times"});
    expect_input_error(
        [&] {
            pair_scans_with_poses({10.0, not_a_number, 11.0}, poses);
        },
        "scan 1", {"non-finite time"});
    poses[0].time.reset();
    expect_input_error(
        [&] {
            pair_scans_with_poses({10.0, 10.5, 11.0}, poses);
        },
        "3 scans but 2 poses", {"the poses have no times"});
}

// ======================= Extrinsics =======================

TEST(RecordingExtrinsics, FromFileAndTextAndComposed) {
    TempDir dir;
    const Eigen::Isometry3d base_from_sensor =
        read_extrinsics(dir.write("extrinsics.txt", "# base_from_sensor\n0 -1 0 0.1\n1 0 0 0\n0 0 1 0.5\n0 0 0 1\n"));
    EXPECT_EQ(base_from_sensor.matrix(), parse_extrinsics("0,-1,0,0.1, 1,0,0,0, 0,0,1,0.5").matrix());
    std::vector<PoseRecord> poses = {{pose_of({0, 0, 1}, std::numbers::pi / 2, {10, 0, 0}), 3.0}};
    apply_extrinsics(poses, base_from_sensor);
    // A point 1 m ahead of the sensor: in the base frame (0.1, 1, 0.5), in the world (9, 0.1, 0.5).
    EXPECT_TRUE((poses[0].world_from_sensor * Eigen::Vector3d(1, 0, 0)).isApprox(Eigen::Vector3d(9, 0.1, 0.5)));
    EXPECT_EQ(poses[0].time, 3.0);
}

TEST(RecordingExtrinsics, Errors) {
    expect_input_error([] { parse_extrinsics("1 0 0 0 0 1 0 0 0 0 1", "--extrinsics"); }, "--extrinsics",
                       {"expected 12 values", "found 11"});
    expect_input_error([] { parse_extrinsics("1 0 0 0 0 1 0 0 0 0 1 0 0 0 0 2", "--extrinsics"); }, "--extrinsics",
                       {"last row of a 4x4 transform must be 0 0 0 1"});
    expect_input_error([] { parse_extrinsics("2 0 0 0 0 1 0 0 0 0 1 0", "--extrinsics"); }, "--extrinsics",
                       {"not a rotation"});
    TempDir dir;
    expect_input_error([&] { read_extrinsics(dir / "none.txt"); }, (dir / "none.txt").string(), {"no such file"});
}

// ======================= Real data: hall-lidar =======================

TEST(RecordingHallLidar, ReadsEveryScanAndPose) {
    const fs::path data = BVC3D_SOURCE_DIR "/../shared/data/hall-lidar";
    if (!fs::exists(data / "poses.csv"))
        GTEST_SKIP() << "hall-lidar data not found at " << data.string() << ": skipped";

    const auto scans = list_scans(data);
    ASSERT_EQ(scans.size(), 60u);
    EXPECT_EQ(scans.front().path.filename(), "0000.pcd");
    EXPECT_EQ(scans.back().path.filename(), "0059.pcd");
    EXPECT_EQ(detect_pose_format(data / "poses.csv"), PoseFormat::matrix);
    const auto poses = read_poses(data / "poses.csv");
    ASSERT_EQ(poses.size(), 60u);
    EXPECT_FALSE(pair_scans_with_poses(scan_times(scans), poses).by_time);

    // The README rounds: 64 055-90 252 points a scan, nearest returns at 0.515 m, and a few isolated
    // returns (at most 2 a scan, in 7 scans) far beyond the 55 m walls, out to 481 m.
    for (const ScanEntry& scan : scans) {
        const PointCloud cloud = read_scan(scan.path);
        EXPECT_EQ(cloud.dropped_nonfinite, 0u) << scan.path;
        EXPECT_GE(cloud.size(), 62000u) << scan.path;
        EXPECT_LE(cloud.size(), 91000u) << scan.path;
        std::vector<double> ranges;
        for (std::size_t i = 0; i < cloud.size(); ++i)
            ranges.push_back(Eigen::Vector3d(cloud.xyz[3 * i], cloud.xyz[3 * i + 1], cloud.xyz[3 * i + 2]).norm());
        std::sort(ranges.begin(), ranges.end());
        EXPECT_GE(ranges.front(), 0.5) << scan.path;
        EXPECT_GE(ranges.back(), 20.0) << scan.path;
        EXPECT_LE(std::count_if(ranges.begin(), ranges.end(), [](double r) { return r > 56.0; }), 5) << scan.path;
        const double median = ranges[ranges.size() / 2];
        EXPECT_GT(median, 4.0) << scan.path;
        EXPECT_LT(median, 9.0) << scan.path;
    }
    for (std::size_t i = 0; i < poses.size(); ++i) {
        ASSERT_TRUE(poses[i].time.has_value());
        EXPECT_GT(*poses[i].time, 1.6e9);  // Unix time
        EXPECT_TRUE(rotation_problem(poses[i].world_from_sensor.linear()).empty());
        EXPECT_NEAR(poses[i].world_from_sensor.linear().determinant(), 1.0, 1e-4);
        if (i > 0) {
            EXPECT_NEAR(*poses[i].time - *poses[i - 1].time, 1.0, 0.01) << "pose " << i;
        }
    }
    // Still for the first 10 scans, then about 0.9 m a scan: a 45 m path (ending near its start).
    double path = 0;
    for (std::size_t i = 1; i < poses.size(); ++i) {
        const double step =
            (poses[i].world_from_sensor.translation() - poses[i - 1].world_from_sensor.translation()).norm();
        if (i < 10) {
            EXPECT_LT(step, 0.02) << "pose " << i;
        }
        path += step;
    }
    EXPECT_NEAR(path, 45.0, 3.0);
}
