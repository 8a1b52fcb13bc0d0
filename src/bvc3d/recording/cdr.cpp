#include "bvc3d/recording/cdr.hpp"

#include <bit>
#include <cmath>
#include <cstring>

#include "bvc3d/core/error.hpp"
#include "bvc3d/recording/parsing.hpp"

namespace bvc3d::recording::cdr {

namespace {

using detail::ByteOrder;

std::string at(std::size_t pos) { return " at byte " + std::to_string(pos + 4); }

}  // namespace

Reader::Reader(std::span<const std::uint8_t> bytes) {
    if (bytes.size() < 4)
        throw InputError("CDR: " + std::to_string(bytes.size()) + " bytes, shorter than the encapsulation header");
    if (bytes[0] != 0 || bytes[1] > 1) {
        char id[16];
        std::snprintf(id, sizeof id, "0x%02x%02x", bytes[0], bytes[1]);
        throw InputError(std::string("CDR: unknown encapsulation ") + id +
                         " (only plain CDR, 0x0000 big-endian or 0x0001 little-endian, is read)");
    }
    big_ = bytes[1] == 0;
    data_ = bytes.subspan(4);
}

void Reader::align(std::size_t n) {
    const std::size_t padded = (pos_ + n - 1) / n * n;
    if (padded > data_.size()) throw InputError("CDR: the message ends" + at(pos_) + " (truncated)");
    pos_ = padded;
}

const std::uint8_t* Reader::take(std::size_t n) {
    if (n > data_.size() - pos_)
        throw InputError("CDR: the message ends" + at(pos_) + ", " + std::to_string(n) +
                         " more bytes needed (truncated)");
    const std::uint8_t* p = data_.data() + pos_;
    pos_ += n;
    return p;
}

std::uint8_t Reader::u8() { return *take(1); }

std::uint32_t Reader::u32() {
    align(4);
    return detail::load<std::uint32_t>(reinterpret_cast<const char*>(take(4)),
                                       big_ ? ByteOrder::big : ByteOrder::little);
}

double Reader::f64() {
    align(8);
    return detail::load<double>(reinterpret_cast<const char*>(take(8)), big_ ? ByteOrder::big : ByteOrder::little);
}

std::string Reader::string() {
    const std::size_t start = pos_;
    const std::uint32_t n = u32();
    if (n == 0) return {};  // some writers leave out the NUL of an empty string
    const auto* p = take(n);
    if (p[n - 1] != 0) throw InputError("CDR: the string" + at(start) + " does not end in NUL");
    return std::string(reinterpret_cast<const char*>(p), n - 1);
}

std::uint32_t Reader::count(std::size_t min_element_bytes) {
    const std::size_t start = pos_;
    const std::uint32_t n = u32();
    if (min_element_bytes > 0 && n > remaining() / min_element_bytes)
        throw InputError("CDR: a sequence" + at(start) + " claims " + std::to_string(n) + " elements; " +
                         std::to_string(remaining()) + " bytes are left (truncated or corrupt)");
    return n;
}

void Reader::bytes(std::vector<std::uint8_t>& out) {
    const std::uint32_t n = count(1);
    const auto* p = take(n);
    out.assign(p, p + n);
}

Writer::Writer() : out_{0x00, 0x01, 0x00, 0x00} {}

void Writer::align(std::size_t n) {
    while ((out_.size() - 4) % n) out_.push_back(0);
}

void Writer::u8(std::uint8_t v) { out_.push_back(v); }

void Writer::u32(std::uint32_t v) {
    align(4);
    std::string s;
    detail::store(s, v, ByteOrder::little);
    out_.insert(out_.end(), s.begin(), s.end());
}

void Writer::f64(double v) {
    align(8);
    std::string s;
    detail::store(s, v, ByteOrder::little);
    out_.insert(out_.end(), s.begin(), s.end());
}

void Writer::string(const std::string& s) {
    u32(static_cast<std::uint32_t>(s.size() + 1));
    out_.insert(out_.end(), s.begin(), s.end());
    out_.push_back(0);
}

void Writer::bytes(std::span<const std::uint8_t> b) {
    u32(static_cast<std::uint32_t>(b.size()));
    out_.insert(out_.end(), b.begin(), b.end());
}

namespace {

// std_msgs/Header: builtin_interfaces/Time stamp (int32 sec, uint32 nanosec), string frame_id.
double header(Reader& r, std::string& frame) {
    const std::int32_t sec = r.i32();
    const std::uint32_t nsec = r.u32();
    frame = r.string();
    return sec + nsec * 1e-9;
}

void write_header(Writer& w, double stamp, const std::string& frame) {
    double whole = std::floor(stamp);
    auto nsec = static_cast<std::int64_t>(std::llround((stamp - whole) * 1e9));
    if (nsec >= 1000000000) {
        nsec -= 1000000000;
        whole += 1;
    }
    w.i32(static_cast<std::int32_t>(whole));
    w.u32(static_cast<std::uint32_t>(nsec));
    w.string(frame);
}

// geometry_msgs/Pose (Point, Quaternion) or Transform (Vector3, Quaternion): 7 float64.
void pose(Reader& r, StampedTransform& t) {
    t.translation.x() = r.f64();
    t.translation.y() = r.f64();
    t.translation.z() = r.f64();
    const double x = r.f64(), y = r.f64(), z = r.f64(), w = r.f64();
    t.rotation = Eigen::Quaterniond(w, x, y, z);
}

void write_pose(Writer& w, const StampedTransform& t) {
    for (int i = 0; i < 3; ++i) w.f64(t.translation[i]);
    w.f64(t.rotation.x());
    w.f64(t.rotation.y());
    w.f64(t.rotation.z());
    w.f64(t.rotation.w());
}

}  // namespace

CloudMessage decode_cloud(std::span<const std::uint8_t> bytes) {
    Reader r(bytes);
    CloudMessage c;
    c.stamp = header(r, c.frame_id);
    c.height = r.u32();
    c.width = r.u32();
    const std::uint32_t n = r.count(13);  // name (4+1), offset 4, datatype 1, count 4, at least
    c.fields.resize(n);
    for (auto& f : c.fields) {
        f.name = r.string();
        f.offset = r.u32();
        f.datatype = r.u8();
        f.count = r.u32();
    }
    c.is_bigendian = r.boolean();
    c.point_step = r.u32();
    c.row_step = r.u32();
    r.bytes(c.data);
    r.boolean();  // is_dense: the points are checked one by one anyway
    return c;
}

StampedTransform decode_odometry(std::span<const std::uint8_t> bytes) {
    Reader r(bytes);
    StampedTransform t;
    t.stamp = header(r, t.parent);
    t.child = r.string();
    pose(r, t);  // pose.pose; its covariance and the twist are not needed
    return t;
}

StampedTransform decode_pose_stamped(std::span<const std::uint8_t> bytes) {
    Reader r(bytes);
    StampedTransform t;
    t.stamp = header(r, t.parent);
    pose(r, t);
    return t;
}

std::vector<StampedTransform> decode_tf(std::span<const std::uint8_t> bytes) {
    Reader r(bytes);
    const std::uint32_t n = r.count(4 + 4 + 4 + 4 + 7 * 8);
    std::vector<StampedTransform> out(n);
    for (auto& t : out) {
        t.stamp = header(r, t.parent);
        t.child = r.string();
        pose(r, t);
    }
    return out;
}

std::vector<std::uint8_t> encode_cloud(const CloudMessage& c) {
    Writer w;
    write_header(w, c.stamp, c.frame_id);
    w.u32(c.height);
    w.u32(c.width);
    w.u32(static_cast<std::uint32_t>(c.fields.size()));
    for (const auto& f : c.fields) {
        w.string(f.name);
        w.u32(f.offset);
        w.u8(f.datatype);
        w.u32(f.count);
    }
    w.boolean(c.is_bigendian);
    w.u32(c.point_step);
    w.u32(c.row_step);
    w.bytes(c.data);
    w.boolean(true);
    return w.data();
}

std::vector<std::uint8_t> encode_odometry(const StampedTransform& t) {
    Writer w;
    write_header(w, t.stamp, t.parent);
    w.string(t.child);
    write_pose(w, t);
    for (int i = 0; i < 36; ++i) w.f64(0);  // pose covariance
    for (int i = 0; i < 6; ++i) w.f64(0);   // twist (linear, angular)
    for (int i = 0; i < 36; ++i) w.f64(0);  // twist covariance
    return w.data();
}

std::vector<std::uint8_t> encode_tf(const std::vector<StampedTransform>& transforms) {
    Writer w;
    w.u32(static_cast<std::uint32_t>(transforms.size()));
    for (const auto& t : transforms) {
        write_header(w, t.stamp, t.parent);
        w.string(t.child);
        write_pose(w, t);
    }
    return w.data();
}

}  // namespace bvc3d::recording::cdr
