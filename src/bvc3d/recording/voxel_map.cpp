#include "bvc3d/recording/voxel_map.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "bvc3d/core/error.hpp"

namespace bvc3d::recording {

namespace {

// Voxel indices within ±2^20 on each axis pack into 63 bits (±52 km at 5 cm).
constexpr std::int64_t index_limit = std::int64_t{1} << 20;

std::uint64_t pack(std::int64_t i, std::int64_t j, std::int64_t k) {
    const auto u = [](std::int64_t v) { return static_cast<std::uint64_t>(v + index_limit); };
    return (u(i) << 42) | (u(j) << 21) | u(k);
}

}  // namespace

VoxelMap::VoxelMap(VoxelMapParams params) : p_(params) {
    if (!(p_.voxel > 0) || !std::isfinite(p_.voxel)) throw InputError("map: the voxel size must be a positive number");
    if (!(p_.min_range >= 0) || !(p_.max_range >= 0) || (p_.max_range > 0 && p_.max_range <= p_.min_range))
        throw InputError("map: ranges need 0 <= min_range < max_range (max_range 0: no limit)");
    if (p_.min_points < 1) throw InputError("map: min_points must be >= 1");
}

void VoxelMap::add(const PointCloud& scan, const Eigen::Isometry3d& pose) {
    const double inv = 1.0 / p_.voxel;
    const double min2 = p_.min_range * p_.min_range, max2 = p_.max_range > 0 ? p_.max_range * p_.max_range : INFINITY;
    for (std::size_t n = 0; n < scan.size(); ++n) {
        const Eigen::Vector3d s(scan.xyz[3 * n], scan.xyz[3 * n + 1], scan.xyz[3 * n + 2]);
        const double r2 = s.squaredNorm();
        if (!(r2 >= min2 && r2 <= max2)) continue;
        const Eigen::Vector3d w = pose * s;
        const double fi = std::floor(w.x() * inv), fj = std::floor(w.y() * inv), fk = std::floor(w.z() * inv);
        const double lim = static_cast<double>(index_limit);
        if (!(std::abs(fi) < lim && std::abs(fj) < lim && std::abs(fk) < lim))
            throw InputError("map: a point at (" + std::to_string(w.x()) + ", " + std::to_string(w.y()) + ", " +
                             std::to_string(w.z()) +
                             ") lies beyond the voxel grid's reach; use a larger voxel or --max-range");
        Cell& c =
            cells_[pack(static_cast<std::int64_t>(fi), static_cast<std::int64_t>(fj), static_cast<std::int64_t>(fk))];
        c.x += w.x();
        c.y += w.y();
        c.z += w.z();
        ++c.count;
        ++added_;
    }
}

PointCloud VoxelMap::cloud() const {
    std::vector<std::uint64_t> keys;
    keys.reserve(cells_.size());
    for (const auto& [key, cell] : cells_)
        if (cell.count >= static_cast<std::uint64_t>(p_.min_points)) keys.push_back(key);
    std::sort(keys.begin(), keys.end());
    PointCloud out;
    out.xyz.reserve(3 * keys.size());
    for (const auto key : keys) {
        const Cell& c = cells_.at(key);
        const auto n = static_cast<double>(c.count);
        out.xyz.insert(out.xyz.end(), {c.x / n, c.y / n, c.z / n});
    }
    return out;
}

}  // namespace bvc3d::recording
