#include "bvc3d/bvc/scan_context.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "bvc3d/core/error.hpp"

namespace bvc3d {

const params::Table<ScanContextParams>& ScanContextParams::table() {
    using namespace params;
    static const Table<ScanContextParams> t(
        "Scan Context",
        {integer("rings", &ScanContextParams::rings, closed(1, 10000), "rings of equal width out to max_radius"),
         integer("sectors", &ScanContextParams::sectors, closed(1, 10000), "sectors of equal angle around the sensor"),
         real("max_radius", &ScanContextParams::max_radius, above(0), "m, farther points are left out"),
         real("lidar_height", &ScanContextParams::lidar_height, finite(), "m added to every point's z"),
         integer("candidates", &ScanContextParams::candidates, closed(1, 1000000),
                 "nearest ring keys compared in full in a search")});
    return t;
}

namespace {

// 1-based bin along an axis as the reference counts it: ⌈value / width⌉ clamped to [1, count].
int bin_of(double value, double width, int count) {
    const double b = std::ceil(value / width);
    return b < 1 ? 1 : (b > count ? count : static_cast<int>(b));
}

}  // namespace

ScanContext scan_context(std::span<const double> xyz, const ScanContextParams& p) {
    p.validate();
    ScanContext sc;
    sc.rings = p.rings;
    sc.sectors = p.sectors;
    const auto cells = static_cast<std::size_t>(p.rings) * static_cast<std::size_t>(p.sectors);
    constexpr double none = -std::numeric_limits<double>::infinity();
    sc.bins.assign(cells, none);
    const double ring_width = p.max_radius / p.rings, sector_width = 360.0 / p.sectors;
    for (std::size_t i = 0; i < xyz.size() / 3; ++i) {
        const double x = xyz[3 * i], y = xyz[3 * i + 1], z = xyz[3 * i + 2];
        if (!std::isfinite(x) || !std::isfinite(y) || !std::isfinite(z))
            throw InputError("Scan Context: point " + std::to_string(i) + " is not finite");
        const double rho = std::hypot(x, y);
        if (rho > p.max_radius) continue;
        double alpha = std::atan2(y, x) * (180.0 / M_PI);
        if (alpha < 0) alpha += 360.0;
        const int ring = bin_of(rho, ring_width, p.rings) - 1, sector = bin_of(alpha, sector_width, p.sectors) - 1;
        double& b = sc.bins[static_cast<std::size_t>(ring * p.sectors + sector)];
        b = std::max(b, z + p.lidar_height);
    }
    for (double& b : sc.bins)
        if (b == none) b = 0.0;
    return scan_context_from_bins(p.rings, p.sectors, std::move(sc.bins));
}

ScanContext scan_context_from_bins(int rings, int sectors, std::vector<double> bins) {
    if (rings < 1 || sectors < 1 || bins.size() != static_cast<std::size_t>(rings) * static_cast<std::size_t>(sectors))
        throw InputError("Scan Context: " + std::to_string(bins.size()) + " bins are not " + std::to_string(rings) +
                         " rings x " + std::to_string(sectors) + " sectors");
    for (const double b : bins)
        if (!std::isfinite(b)) throw InputError("Scan Context: a bin is not finite");
    ScanContext sc;
    sc.rings = rings;
    sc.sectors = sectors;
    sc.bins = std::move(bins);
    sc.ring_key.assign(static_cast<std::size_t>(rings), 0.0);
    for (int r = 0; r < rings; ++r) {
        double sum = 0;
        for (int s = 0; s < sectors; ++s) sum += sc.bin(r, s);
        sc.ring_key[static_cast<std::size_t>(r)] = sum / sectors;
    }
    sc.unit_columns.assign(sc.bins.size(), 0.0);
    sc.filled.assign(static_cast<std::size_t>(sectors), 0);
    for (int s = 0; s < sectors; ++s) {
        double norm = 0;
        for (int r = 0; r < rings; ++r) norm += sc.bin(r, s) * sc.bin(r, s);
        if (norm == 0) continue;
        norm = std::sqrt(norm);
        sc.filled[static_cast<std::size_t>(s)] = 1;
        for (int r = 0; r < rings; ++r) sc.unit_columns[static_cast<std::size_t>(s * rings + r)] = sc.bin(r, s) / norm;
    }
    return sc;
}

ScanContextMatch scan_context_distance(const ScanContext& a, const ScanContext& b) {
    if (a.rings != b.rings || a.sectors != b.sectors)
        throw InputError("Scan Context: descriptors of " + std::to_string(a.rings) + " x " + std::to_string(a.sectors) +
                         " and " + std::to_string(b.rings) + " x " + std::to_string(b.sectors) + " bins");
    const int S = a.sectors, R = a.rings;
    ScanContextMatch best{std::numeric_limits<double>::infinity(), 0};
    for (int shift = 0; shift < S; ++shift) {
        double sum = 0;
        int count = 0;
        for (int c = 0; c < S; ++c) {
            const int ca = (c + shift) % S;
            if (!a.filled[static_cast<std::size_t>(ca)] || !b.filled[static_cast<std::size_t>(c)]) continue;
            const double* ua = a.unit_columns.data() + static_cast<std::size_t>(ca * R);
            const double* ub = b.unit_columns.data() + static_cast<std::size_t>(c * R);
            double dot = 0;
            for (int r = 0; r < R; ++r) dot += ua[r] * ub[r];
            sum += 1.0 - dot;
            ++count;
        }
        const double d = count ? sum / count : 1.0;
        if (d < best.distance) best = {d, shift};
    }
    return best;
}

}  // namespace bvc3d
