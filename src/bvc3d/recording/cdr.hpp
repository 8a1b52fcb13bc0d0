#pragma once
// CDR, the encoding of ROS 2 messages (OMG DDS-XTypes XCDR version 1, as ROS 2's middleware writes
// it). CDR has no Debian package and is a small public format, so it is read and written here, from
// the specification: a 4-byte encapsulation header (0x00 0x00 big-endian, 0x00 0x01 little-endian,
// two option bytes), then each primitive aligned to its own size (at most 8) counted from the end
// of that header; strings as a uint32 length including the terminating NUL, then the bytes;
// sequences as a uint32 count, then the elements; fixed arrays without a count.
// Takes: a message's bytes. Gives: the messages of ros_messages.hpp (sensor_msgs/PointCloud2,
// nav_msgs/Odometry, geometry_msgs/PoseStamped, tf2_msgs/TFMessage); and the encoders for writing
// them. Errors (InputError): truncated data, an unknown encapsulation, impossible lengths.
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "bvc3d/recording/ros_messages.hpp"

namespace bvc3d::recording::cdr {

class Reader {
public:
    // Reads the encapsulation header; only plain CDR (either byte order) is accepted.
    explicit Reader(std::span<const std::uint8_t> bytes);
    bool big_endian() const { return big_; }

    std::uint8_t u8();
    bool boolean() { return u8() != 0; }
    std::uint32_t u32();
    std::int32_t i32() { return static_cast<std::int32_t>(u32()); }
    double f64();
    std::string string();
    // A sequence's element count, checked against the bytes left at `min_element_bytes` each.
    std::uint32_t count(std::size_t min_element_bytes);
    // A uint8 sequence into `out`.
    void bytes(std::vector<std::uint8_t>& out);
    std::size_t remaining() const { return data_.size() - pos_; }

private:
    void align(std::size_t n);
    const std::uint8_t* take(std::size_t n);
    std::span<const std::uint8_t> data_;  // after the encapsulation header
    std::size_t pos_ = 0;
    bool big_ = false;
};

class Writer {
public:
    Writer();  // little-endian CDR, with its encapsulation header
    void u8(std::uint8_t v);
    void boolean(bool v) { u8(v ? 1 : 0); }
    void u32(std::uint32_t v);
    void i32(std::int32_t v) { u32(static_cast<std::uint32_t>(v)); }
    void f64(double v);
    void string(const std::string& s);
    void bytes(std::span<const std::uint8_t> b);
    const std::vector<std::uint8_t>& data() const { return out_; }

private:
    void align(std::size_t n);
    std::vector<std::uint8_t> out_;
};

// The messages (ROS 2 definitions: builtin_interfaces/Time is int32 sec, uint32 nanosec; the header
// has no seq). Trailing bytes are allowed (later fields of a newer definition).
CloudMessage decode_cloud(std::span<const std::uint8_t> bytes);
StampedTransform decode_odometry(std::span<const std::uint8_t> bytes);
StampedTransform decode_pose_stamped(std::span<const std::uint8_t> bytes);
std::vector<StampedTransform> decode_tf(std::span<const std::uint8_t> bytes);

std::vector<std::uint8_t> encode_cloud(const CloudMessage& cloud);
// nav_msgs/Odometry with zero covariance and twist.
std::vector<std::uint8_t> encode_odometry(const StampedTransform& pose);
std::vector<std::uint8_t> encode_tf(const std::vector<StampedTransform>& transforms);

}  // namespace bvc3d::recording::cdr
