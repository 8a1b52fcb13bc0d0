#include "bvc3d/recording/ros_messages.hpp"

#include <bit>
#include <cmath>
#include <cstring>

#include "bvc3d/core/error.hpp"
#include "bvc3d/recording/parsing.hpp"

namespace bvc3d::recording {

namespace {

using detail::ByteOrder;

struct Column {
    std::uint32_t offset = 0;
    std::uint32_t size = 0;  // 4 (float32) or 8 (float64)
};

Column find_column(const CloudMessage& c, const char* name) {
    const PointFieldInfo* found = nullptr;
    for (const auto& f : c.fields)
        if (f.name == name) found = &f;
    if (!found) {
        std::string names;
        for (const auto& f : c.fields) names += (names.empty() ? "" : ", ") + f.name;
        throw InputError(std::string("the cloud has no field '") + name +
                         "' (fields: " + (names.empty() ? "none" : names) + ")");
    }
    const auto type = static_cast<PointFieldType>(found->datatype);
    if (type != PointFieldType::float32 && type != PointFieldType::float64)
        throw InputError(std::string("field '") + name + "' has datatype " + std::to_string(found->datatype) +
                         "; x, y, z must be FLOAT32 (7) or FLOAT64 (8)");
    if (found->count == 0) throw InputError(std::string("field '") + name + "' has count 0");
    Column col{found->offset, type == PointFieldType::float32 ? 4u : 8u};
    if (std::uint64_t{col.offset} + col.size > c.point_step)
        throw InputError(std::string("field '") + name + "' (offset " + std::to_string(col.offset) + ", " +
                         std::to_string(col.size) + " bytes) does not fit in the point step of " +
                         std::to_string(c.point_step) + " bytes");
    return col;
}

// Every point of every row, x y z of one type T in the host's byte order: the common case, a
// straight loop the compiler keeps in registers.
template <class T>
void gather_native(const CloudMessage& c, std::uint64_t row_stride, const Column (&col)[3], PointCloud& out) {
    // Written through a pointer into room made first (push_back's checks cost as much as the copy).
    out.xyz.resize(3 * std::size_t{c.width} * c.height);
    double* o = out.xyz.data();
    const std::uint8_t* base = c.data.data();
    for (std::uint32_t row = 0; row < c.height; ++row) {
        const std::uint8_t* p = base + row * row_stride;
        for (std::uint32_t i = 0; i < c.width; ++i, p += c.point_step) {
            T v[3];
            std::memcpy(&v[0], p + col[0].offset, sizeof(T));
            std::memcpy(&v[1], p + col[1].offset, sizeof(T));
            std::memcpy(&v[2], p + col[2].offset, sizeof(T));
            o[0] = v[0];
            o[1] = v[1];
            o[2] = v[2];
            // Branch-free: a point with a non-finite coordinate is written, then overwritten by the next.
            const bool finite = std::isfinite(o[0]) && std::isfinite(o[1]) && std::isfinite(o[2]);
            o += finite ? 3 : 0;
            out.dropped_nonfinite += finite ? 0 : 1;
        }
    }
    out.xyz.resize(static_cast<std::size_t>(o - out.xyz.data()));
}

double load_value(const std::uint8_t* p, std::uint32_t size, ByteOrder order) {
    const char* b = reinterpret_cast<const char*>(p);
    return size == 4 ? static_cast<double>(detail::load<float>(b, order)) : detail::load<double>(b, order);
}

// Any mix of types and byte orders.
void gather_any(const CloudMessage& c, std::uint64_t row_stride, const Column (&col)[3], ByteOrder order,
                PointCloud& out) {
    const std::uint8_t* base = c.data.data();
    for (std::uint32_t row = 0; row < c.height; ++row) {
        const std::uint8_t* p = base + row * row_stride;
        for (std::uint32_t i = 0; i < c.width; ++i, p += c.point_step) {
            const double x = load_value(p + col[0].offset, col[0].size, order);
            const double y = load_value(p + col[1].offset, col[1].size, order);
            const double z = load_value(p + col[2].offset, col[2].size, order);
            if (std::isfinite(x) && std::isfinite(y) && std::isfinite(z)) {
                out.xyz.push_back(x);
                out.xyz.push_back(y);
                out.xyz.push_back(z);
            } else {
                ++out.dropped_nonfinite;
            }
        }
    }
}

}  // namespace

PointCloud cloud_points(const CloudMessage& c) {
    if (c.point_step == 0) throw InputError("the cloud's point_step is 0");
    // (Rows without points would still be walked one by one: billions of them, for a corrupt height.)
    if (c.width == 0 || c.height == 0)
        throw InputError("empty cloud: " + std::to_string(c.height) + " × " + std::to_string(c.width) + " points");
    const Column col[3] = {find_column(c, "x"), find_column(c, "y"), find_column(c, "z")};
    const std::uint64_t row_bytes = std::uint64_t{c.width} * c.point_step;
    if (c.height > 1 && c.row_step < row_bytes)
        throw InputError("the cloud's row_step " + std::to_string(c.row_step) +
                         " is less than width × point_step = " + std::to_string(row_bytes));
    // The last row needs only its points; the rows before it a row_step each.
    const std::uint64_t needed = c.height == 0 ? 0 : std::uint64_t{c.height - 1} * c.row_step + row_bytes;
    if (c.data.size() < needed)
        throw InputError("the cloud's data holds " + std::to_string(c.data.size()) + " bytes; " +
                         std::to_string(c.height) + " rows of " + std::to_string(c.width) + " points need " +
                         std::to_string(needed));
    const std::uint64_t points = std::uint64_t{c.width} * c.height;
    PointCloud out;
    const ByteOrder order = c.is_bigendian ? ByteOrder::big : ByteOrder::little;
    const bool native = (order == ByteOrder::little) == (std::endian::native == std::endian::little);
    const bool same = col[0].size == col[1].size && col[1].size == col[2].size;
    if (!native || !same) out.xyz.reserve(3 * points);
    // A single-row cloud's row_step may be anything (some drivers leave it 0): rows are never stepped.
    const std::uint64_t stride = c.height <= 1 ? row_bytes : c.row_step;
    if (native && same && col[0].size == 4) gather_native<float>(c, stride, col, out);
    else if (native && same) gather_native<double>(c, stride, col, out);
    else gather_any(c, stride, col, order, out);
    if (out.size() == 0)
        throw InputError("empty cloud: no finite points (" + std::to_string(out.dropped_nonfinite) +
                         " dropped for NaN/inf coordinates)");
    return out;
}

std::string_view bare_frame(std::string_view frame) {
    while (!frame.empty() && frame.front() == '/') frame.remove_prefix(1);
    return frame;
}

Eigen::Quaterniond checked_rotation(const Eigen::Quaterniond& q) {
    const double norm = q.norm();
    if (!std::isfinite(norm) || std::abs(norm - 1) > 1e-3)
        throw InputError("quaternion (" + std::to_string(q.x()) + ", " + std::to_string(q.y()) + ", " +
                         std::to_string(q.z()) + ", " + std::to_string(q.w()) + ") has norm " + std::to_string(norm) +
                         ", not 1 (within 1e-3): not a rotation");
    return q.normalized();
}

}  // namespace bvc3d::recording
