#pragma once
// Internal to the recording stage: what the scan readers share once a format is decoded.
// Takes: coordinates one point at a time, or columns of a binary block whose bounds the caller
// has checked. Gives: a PointCloud without its non-finite points, or the "empty scan" error; and
// the point loops the writers share.
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "bvc3d/recording/file_io.hpp"
#include "bvc3d/recording/parsing.hpp"
#include "bvc3d/recording/point_cloud.hpp"

namespace bvc3d::recording::detail {

class CloudBuilder {
public:
    // `capacity_hint` must already be bounded by the file's size, never taken from a header alone.
    explicit CloudBuilder(std::size_t capacity_hint) { cloud_.xyz.reserve(3 * capacity_hint); }

    void add(double x, double y, double z) {
        if (std::isfinite(x) && std::isfinite(y) && std::isfinite(z)) {
            cloud_.xyz.push_back(x);
            cloud_.xyz.push_back(y);
            cloud_.xyz.push_back(z);
        } else {
            ++cloud_.dropped_nonfinite;
        }
    }

    // A scan with no finite point is no scan: an error naming the file.
    PointCloud finish(const std::filesystem::path& file) && {
        if (cloud_.size() == 0)
            throw input_error(file, "empty scan: no finite points (" + std::to_string(cloud_.dropped_nonfinite) +
                                        " dropped for NaN/inf coordinates)");
        return std::move(cloud_);
    }

private:
    PointCloud cloud_;
};

// Where one coordinate lives in a binary block: point i's value starts at first_byte + i·stride
// and is a float (size 4) or a double (size 8).
struct CoordinateColumn {
    std::uint64_t first_byte = 0;
    std::uint64_t stride = 0;
    std::uint64_t size = 4;
};

inline double load_coordinate(const char* bytes, std::uint64_t size, ByteOrder order) {
    return size == 4 ? static_cast<double>(load<float>(bytes, order)) : load<double>(bytes, order);
}

// A coordinate read from text, rounded as a field of `size` bytes stores it: a cloud then reads
// back the same from an ascii file as from a binary one.
inline double as_stored(double value, std::uint64_t size) {
    return size == 4 ? static_cast<double>(narrow_to_float(value)) : value;
}

// The x, y, z columns of `points` points; the caller has checked every byte lies inside `block`.
inline PointCloud gather_points(const std::filesystem::path& file, std::string_view block,
                                const CoordinateColumn (&columns)[3], std::uint64_t points, ByteOrder order) {
    CloudBuilder cloud(points);
    const char* base = block.data();
    for (std::uint64_t i = 0; i < points; ++i) {
        const double x = load_coordinate(base + columns[0].first_byte + i * columns[0].stride, columns[0].size, order);
        const double y = load_coordinate(base + columns[1].first_byte + i * columns[1].stride, columns[1].size, order);
        const double z = load_coordinate(base + columns[2].first_byte + i * columns[2].stride, columns[2].size, order);
        cloud.add(x, y, z);
    }
    return std::move(cloud).finish(file);
}

// ---- Writing ----

// One point per line: "x y z", each the shortest text that reads back to the stored value.
template <class T>
void append_text_points(std::string& out, const std::vector<double>& xyz) {
    for (std::size_t i = 0; i < xyz.size(); ++i) {
        append_number(out, narrow_to<T>(xyz[i]));
        out += i % 3 == 2 ? '\n' : ' ';
    }
}

// Point after point: x y z x y z ... as T in `order`.
template <class T>
void append_binary_points(std::string& out, const std::vector<double>& xyz, ByteOrder order) {
    out.reserve(out.size() + xyz.size() * sizeof(T));
    for (const double v : xyz) store<T>(out, narrow_to<T>(v), order);
}

// Writers take whole points only.
inline void check_cloud_shape(const std::filesystem::path& file, const PointCloud& cloud) {
    if (cloud.xyz.size() % 3 != 0)
        throw input_error(
            file, "cannot write a cloud of " + std::to_string(cloud.xyz.size()) + " coordinates: not a multiple of 3");
}

}  // namespace bvc3d::recording::detail
