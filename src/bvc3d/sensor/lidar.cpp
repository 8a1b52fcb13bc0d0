#include "bvc3d/sensor/lidar.hpp"

#include <cmath>

#include "bvc3d/core/angles.hpp"
#include "bvc3d/core/error.hpp"
#include "bvc3d/core/random.hpp"
#include "bvc3d/world/ray_caster.hpp"

namespace bvc3d {

LidarSpec LidarSpec::horizontal() {
    LidarSpec s;
    s.name = "horizontal";
    s.elevations = {0.0};
    s.azimuth_count = 720;
    s.height = 0.08;
    return s;
}

LidarSpec LidarSpec::spherical(bool upper_only) {
    LidarSpec s;
    s.name = "spherical";
    const int rows = upper_only ? 45 : 90;
    s.elevations.resize(rows);
    for (int i = 0; i < rows; ++i) s.elevations[i] = pi / 2 - (i + 0.5) * pi / 90;
    s.azimuth_count = 180;
    s.height = 0.18;
    return s;
}

void LidarSpec::validate() const {
    auto fail = [&](const std::string& what) { throw InputError("sensor '" + name + "': " + what); };
    if (elevations.empty()) fail("elevations must not be empty");
    for (double e : elevations)
        if (!std::isfinite(e) || std::abs(e) > pi / 2) fail("every elevation must lie in [-90°, 90°]");
    if (azimuth_count < 1 || azimuth_count > 1000000) fail("azimuth_count must be in [1, 1000000]");
    if (elevations.size() > 100000) fail("at most 100000 rows");
    if (!std::isfinite(azimuth_offset)) fail("azimuth_offset must be finite");
    if (!std::isfinite(height) || height < 0) fail("height must be >= 0");
    if (!std::isfinite(max_range) || max_range <= 0) fail("max_range must be > 0");
    if (!std::isfinite(range_noise_sd) || range_noise_sd < 0) fail("range_noise_sd must be >= 0");
    if (!std::isfinite(dropout) || dropout < 0 || dropout >= 1) fail("dropout must be in [0, 1)");
}

Lidar::Lidar(LidarSpec spec) : spec_(std::move(spec)) {
    spec_.validate();
    for (double e : spec_.elevations) {
        cos_el_.push_back(std::cos(e));
        sin_el_.push_back(std::sin(e));
    }
    for (int j = 0; j < spec_.azimuth_count; ++j) {
        column_azimuth_.push_back(spec_.azimuth_offset + j * two_pi / spec_.azimuth_count);
        column_cos_.push_back(std::cos(column_azimuth_.back()));
        column_sin_.push_back(std::sin(column_azimuth_.back()));
    }
}

void Lidar::scan(const World& world, const Pose& pose, Scan& out, const NoiseKey& noise,
                 const std::vector<char>& rows) const {
    out.clear();
    // Poses far outside any world are mistakes, and beyond ~1e18 Embree rejects the rays outright.
    if (!std::isfinite(pose.x) || !std::isfinite(pose.y) || !std::isfinite(pose.heading) || std::abs(pose.x) > 1e6 ||
        std::abs(pose.y) > 1e6)
        throw InputError("scan pose (" + std::to_string(pose.x) + ", " + std::to_string(pose.y) + ", " +
                         std::to_string(pose.heading) + "): coordinates must be finite and within ±1e6 m");
    const std::size_t n_rows = spec_.elevations.size(), n_cols = column_azimuth_.size();
    if (!rows.empty() && rows.size() != n_rows) throw InputError("row mask has the wrong length");
    const Vec3 origin(pose.x, pose.y, spec_.height);
    const bool noisy = spec_.range_noise_sd > 0 || spec_.dropout > 0;

    // Allocentric azimuths (exact, SPEC §1) and the horizontal unit vectors of the columns: the
    // robot-frame table rotated by the heading, which saves a sin and cos per beam.
    azimuths_.resize(n_cols);
    horizontal_.resize(n_cols);
    const double ch = std::cos(pose.heading), sh = std::sin(pose.heading);
    for (std::size_t j = 0; j < n_cols; ++j) {
        azimuths_[j] = wrap_pi(pose.heading + column_azimuth_[j]);
        horizontal_[j] = Vec2(ch * column_cos_[j] - sh * column_sin_[j], sh * column_cos_[j] + ch * column_sin_[j]);
    }
    dirs_.resize(n_cols);
    ranges_.resize(n_cols);
    for (std::size_t i = 0; i < n_rows; ++i) {
        if (!rows.empty() && !rows[i]) continue;
        for (std::size_t j = 0; j < n_cols; ++j)
            dirs_[j] = Vec3(cos_el_[i] * horizontal_[j].x(), cos_el_[i] * horizontal_[j].y(), sin_el_[i]);
        world.rays().cast(origin, dirs_, spec_.max_range, ranges_);
        for (std::size_t j = 0; j < n_cols; ++j) {
            double r = ranges_[j];
            if (r == RayCaster::no_hit) continue;
            if (noisy) {
                const std::uint64_t beam = i * n_cols + j;
                if (spec_.dropout > 0 && hash_uniform(noise.seed, noise.scan_index, 2 * beam) < spec_.dropout)
                    continue;
                if (spec_.range_noise_sd > 0) {
                    const double u1 = 1.0 - hash_uniform(noise.seed, noise.scan_index, 2 * beam + 1);
                    const double u2 = hash_uniform(noise.seed ^ 0x5bd1e995u, noise.scan_index, 2 * beam + 1);
                    r += spec_.range_noise_sd * std::sqrt(-2.0 * std::log(u1)) * std::cos(two_pi * u2);
                    if (r <= 0.0 || r > spec_.max_range) continue;
                }
            }
            out.push_back({r, azimuths_[j], spec_.elevations[i]});
        }
    }
}

}  // namespace bvc3d
