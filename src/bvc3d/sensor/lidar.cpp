#include "bvc3d/sensor/lidar.hpp"

#include <algorithm>
#include <cmath>

#include "bvc3d/core/angles.hpp"
#include "bvc3d/core/error.hpp"
#include "bvc3d/core/format.hpp"
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

LidarSpec LidarSpec::spherical_full() {
    LidarSpec s = spherical(false);
    s.name = "spherical-full";
    s.height = 0.0;
    return s;
}

LidarSpec LidarSpec::spherical_as_authors(bool upper_only) {
    LidarSpec s = spherical(upper_only);
    s.name = "spherical-authors";
    s.azimuth_labels = AzimuthLabels::linspace;
    s.heading_roll = HeadingRoll::whole_columns;
    constexpr int image_rows = 90;  // linspace(π/2, −π/2, 90) over the whole image; the kept rows first
    s.elevation_labels.resize(s.elevations.size());
    for (std::size_t i = 0; i < s.elevation_labels.size(); ++i)
        s.elevation_labels[i] = pi / 2 - static_cast<double>(i) * pi / (image_rows - 1);
    return s;
}

const params::Table<LidarSpec>& LidarSpec::table() {
    using namespace params;
    static const Table<LidarSpec> t(
        "sensor",
        {text("name", &LidarSpec::name, "a label (scans are identical whatever the name)"),
         reals("elevations", &LidarSpec::elevations, closed(-pi / 2, pi / 2), "rad, the rows' elevations, top first")
             .in_radians()
             .sizes(1, 100000),
         integer("azimuth_count", &LidarSpec::azimuth_count, closed(1, 1000000), "columns per row, evenly spaced"),
         real("azimuth_offset", &LidarSpec::azimuth_offset, closed(-2 * pi, 2 * pi), "rad, the first column's azimuth")
             .in_radians(),
         real("height", &LidarSpec::height, closed(0, 1000), "m above the agent's base"),
         real("min_range", &LidarSpec::min_range, closed_open(0, 1e5), "m, nearest return (nearer ones are dropped)")
             .quiet_at_default(),
         real("max_range", &LidarSpec::max_range, open_closed(0, 1e5), "m, farthest return"),
         real("range_noise_sd", &LidarSpec::range_noise_sd, closed(0, 1000), "m, Gaussian noise added to each range"),
         real("dropout", &LidarSpec::dropout, closed_open(0, 1), "probability that a beam returns nothing"),
         choice("azimuth_labels", &LidarSpec::azimuth_labels,
                {{AzimuthLabels::exact, "exact"}, {AzimuthLabels::linspace, "linspace"}},
                "column j's azimuth: exact (j·2π/n) or linspace (j·2π/(n−1), the authors' code)")
             .quiet_at_default(),
         choice("heading_roll", &LidarSpec::heading_roll,
                {{HeadingRoll::exact, "exact"}, {HeadingRoll::whole_columns, "whole_columns"}},
                "to the world frame: exact (+ heading) or whole_columns (rolled by whole columns, the authors' code)")
             .quiet_at_default(),
         reals("elevation_labels", &LidarSpec::elevation_labels, closed(-pi / 2, pi / 2),
               "rad, the elevation each row's returns carry; [] for the rows' own")
             .in_radians()
             .quiet_at_default()});
    return t;
}

void LidarSpec::validate() const {
    table().check(*this);
    if (!(min_range < max_range))
        table().fail("min_range", "must be less than max_range (" + format_number(max_range) + " m)");
    if (!elevation_labels.empty() && elevation_labels.size() != elevations.size())
        table().fail("elevation_labels", "must list one label per row (" + std::to_string(elevations.size()) +
                                             "), got " + std::to_string(elevation_labels.size()));
    const double beams = static_cast<double>(elevations.size()) * azimuth_count;
    if (beams > max_beams)
        table().fail("azimuth_count", "makes " + std::to_string(elevations.size()) + " rows × " +
                                          std::to_string(azimuth_count) + " columns = " + format_number(beams) +
                                          " beams; the limit is " + format_number(max_beams));
}

Lidar::Lidar(LidarSpec spec) : spec_(std::move(spec)) {
    spec_.validate();
    for (double e : spec_.elevations) {
        cos_el_.push_back(std::cos(e));
        sin_el_.push_back(std::sin(e));
    }
    const int n = spec_.azimuth_count;
    for (int j = 0; j < n; ++j) {
        column_azimuth_.push_back(spec_.azimuth_offset + j * two_pi / n);
        column_cos_.push_back(std::cos(column_azimuth_.back()));
        column_sin_.push_back(std::sin(column_azimuth_.back()));
        column_label_.push_back(spec_.azimuth_labels == AzimuthLabels::exact || n == 1
                                    ? column_azimuth_.back()
                                    : spec_.azimuth_offset + j * two_pi / (n - 1));
    }
}

void Lidar::scan(const World& world, const Pose& pose, Scan& out, const NoiseKey& noise,
                 const std::vector<char>& rows) const {
    out.clear();
    // Poses far outside any world are mistakes, and beyond ~1e18 Embree rejects the rays outright.
    if (!pose.finite() || std::abs(pose.x) > 1e6 || std::abs(pose.y) > 1e6 || std::abs(pose.z) > 1e6)
        throw InputError("scan pose (" + std::to_string(pose.x) + ", " + std::to_string(pose.y) + ", " +
                         std::to_string(pose.z) + ", heading " + std::to_string(pose.heading) +
                         "): coordinates must be finite and within ±1e6 m");
    if (!pose.level()) {
        if (!rows.empty()) throw InputError("a row mask applies to level poses only");
        if (!spec_.exact_labels())
            throw InputError("sensor '" + spec_.name + "': angle labels other than exact apply to level poses only");
        scan_tilted(world, pose, out, noise);
        return;
    }
    const std::size_t n_rows = spec_.elevations.size();
    if (!rows.empty() && rows.size() != n_rows) throw InputError("row mask has the wrong length");
    const Vec3 origin(pose.x, pose.y, pose.z + spec_.height);
    // Every row to cast in one call, column by column: the rays of one ray packet then share an
    // azimuth or two and meet the same walls, which Embree traverses a third faster than packets
    // that sweep 16 columns of one row. Each ray's range is its own; the returns keep the beam
    // table's order (row by row).
    cast_rows_.clear();
    for (std::size_t i = 0; i < n_rows; ++i)
        if (rows.empty() || rows[i]) cast_rows_.push_back(i);
    // The columns' azimuths and the beams' directions depend on the heading and the rows only: a
    // walk keeps its heading for several steps, and these are then the last scan's.
    if (!(pose.heading == beams_heading_) || cast_rows_ != beams_rows_) {
        set_azimuths(pose.heading);
        set_beams(pose.heading);
        beams_heading_ = pose.heading;
        beams_rows_ = cast_rows_;
    }
    world.rays().cast(origin, dirs_, spec_.max_range, ranges_);
    if (spec_.range_noise_sd > 0 || spec_.dropout > 0) write_returns<true>(out, noise);
    else write_returns<false>(out, noise);
}

// The beams of the cast rows, column by column: each column's horizontal unit vector (the
// robot-frame table rotated by the heading, which saves a sin and cos per beam) scaled by each
// row's cos(elevation).
void Lidar::set_beams(double heading) const {
    const std::size_t n_cols = column_azimuth_.size(), n_cast = cast_rows_.size();
    const double ch = std::cos(heading), sh = std::sin(heading);
    horizontal_.resize(n_cols);
    for (std::size_t j = 0; j < n_cols; ++j)
        horizontal_[j] = Vec2(ch * column_cos_[j] - sh * column_sin_[j], sh * column_cos_[j] + ch * column_sin_[j]);
    dirs_.resize(n_cols * n_cast);
    ranges_.resize(n_cols * n_cast);
    const Vec2* h = horizontal_.data();
    for (std::size_t c = 0; c < n_cast; ++c) {
        const double ce = cos_el_[cast_rows_[c]], se = sin_el_[cast_rows_[c]];
        Vec3* d = dirs_.data() + c;
        for (std::size_t j = 0; j < n_cols; ++j) d[j * n_cast] = Vec3(ce * h[j].x(), ce * h[j].y(), se);
    }
}

// Allocentric azimuths of the columns (exact; docs/model-reference.md#conventions), or the labels
// the image rolled by whole columns carries (HeadingRoll::whole_columns).
void Lidar::set_azimuths(double heading) const {
    const std::size_t n_cols = column_azimuth_.size();
    azimuths_.resize(n_cols);
    if (spec_.heading_roll == HeadingRoll::exact) {
        // The labels increase with the column, and so do their sums with the heading (rounding is
        // monotonic). When these lie in (-π, 3π), wrap_pi keeps those up to π and turns the others
        // back by 2π: two loops split at the first column past π do it without a branch per column.
        const double* label = column_label_.data();
        if (heading + label[0] > -pi && heading + label[n_cols - 1] < 3 * pi) {
            const std::size_t turn = static_cast<std::size_t>(
                std::partition_point(label, label + n_cols, [&](double l) { return heading + l <= pi; }) - label);
            for (std::size_t j = 0; j < turn; ++j) azimuths_[j] = heading + label[j];
            for (std::size_t j = turn; j < n_cols; ++j) azimuths_[j] = (heading + label[j]) - two_pi;
            return;
        }
        for (std::size_t j = 0; j < n_cols; ++j) azimuths_[j] = wrap_pi(heading + label[j]);
        return;
    }
    // The heading in [0, 2π), truncated to whole columns.
    double h = std::fmod(heading, two_pi);
    if (h < 0) h += two_pi;
    const auto roll = static_cast<std::size_t>(std::floor(h / (two_pi / static_cast<double>(n_cols)))) % n_cols;
    for (std::size_t j = 0; j < n_cols; ++j) azimuths_[j] = wrap_pi(column_label_[(j + roll) % n_cols]);
}

// The hits of the cast rows (ranges_, column by column) as returns, row by row; noisy: with range
// noise and dropout, a beam's noise depending on its index in the beam table.
template <bool noisy>
void Lidar::write_returns(Scan& out, const NoiseKey& noise) const {
    const std::size_t n_cols = azimuths_.size(), n_cast = cast_rows_.size();
    out.reserve(n_cols * n_cast);
    const double* azimuth = azimuths_.data();
    const double* range = ranges_.data();
    const std::vector<double>& row_label = spec_.row_labels();
    for (std::size_t c = 0; c < n_cast; ++c) {
        const std::size_t i = cast_rows_[c];
        const double elevation = row_label[i];
        for (std::size_t j = 0; j < n_cols; ++j) {
            double r = range[j * n_cast + c];
            if (r == RayCaster::no_hit) continue;
            if constexpr (noisy) {
                if (!add_noise(r, noise, i * n_cols + j)) continue;
            } else if (r < spec_.min_range) {
                continue;
            }
            out.push_back({r, azimuth[j], elevation});
        }
    }
}

bool Lidar::add_noise(double& r, const NoiseKey& noise, std::uint64_t beam) const {
    if (spec_.dropout > 0 && hash_uniform(noise.seed, noise.scan_index, 2 * beam) < spec_.dropout) return false;
    if (spec_.range_noise_sd > 0) {
        const double u1 = 1.0 - hash_uniform(noise.seed, noise.scan_index, 2 * beam + 1);
        const double u2 = hash_uniform(noise.seed ^ 0x5bd1e995u, noise.scan_index, 2 * beam + 1);
        r += spec_.range_noise_sd * std::sqrt(-2.0 * std::log(u1)) * std::cos(two_pi * u2);
        if (r <= 0.0 || r > spec_.max_range) return false;
    }
    return r >= spec_.min_range;
}

void Lidar::scan_tilted(const World& world, const Pose& pose, Scan& out, const NoiseKey& noise) const {
    beams_heading_ = NAN;  // dirs_ and ranges_ are this scan's own
    // The beam table turns with the sensor; each hit's angles are measured in the world frame.
    const Eigen::Matrix3d R = pose.rotation();
    const Vec3 origin = pose.position() + R * Vec3(0.0, 0.0, spec_.height);
    const std::size_t n_rows = spec_.elevations.size(), n_cols = column_azimuth_.size();
    const bool noisy = spec_.range_noise_sd > 0 || spec_.dropout > 0;
    dirs_.resize(n_cols);
    ranges_.resize(n_cols);
    for (std::size_t i = 0; i < n_rows; ++i) {
        for (std::size_t j = 0; j < n_cols; ++j)
            dirs_[j] = R * Vec3(cos_el_[i] * column_cos_[j], cos_el_[i] * column_sin_[j], sin_el_[i]);
        world.rays().cast(origin, dirs_, spec_.max_range, ranges_);
        for (std::size_t j = 0; j < n_cols; ++j) {
            double r = ranges_[j];
            if (r == RayCaster::no_hit || (noisy ? !add_noise(r, noise, i * n_cols + j) : r < spec_.min_range))
                continue;
            const Vec3& d = dirs_[j];
            out.push_back({r, wrap_pi(std::atan2(d.y(), d.x())), std::atan2(d.z(), std::hypot(d.x(), d.y()))});
        }
    }
}

}  // namespace bvc3d
