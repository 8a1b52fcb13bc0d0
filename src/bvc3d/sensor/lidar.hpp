#pragma once
// Sensor stage: range scanners on the agent.
// Takes: a World and the agent's pose. Gives: the hits as (range, allocentric azimuth, elevation)
// relative to the sensor (docs/model-reference.md#sensors); beams with no hit within max_range are
// dropped. return_source.hpp is the seam through which a model step gets its returns.
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "bvc3d/core/geometry.hpp"
#include "bvc3d/core/params.hpp"
#include "bvc3d/world/world.hpp"

namespace bvc3d {

// One return. Laid out as three doubles so a scan is an (N, 3) array for numpy.
struct LidarReturn {
    double range;      // m
    double azimuth;    // allocentric, radians in (-pi, pi], 0 = +x (east)
    double elevation;  // radians, positive up
};
using Scan = std::vector<LidarReturn>;

// How a scan's returns are labeled with angles (docs/worlds.md#sensors). The defaults give each
// return its beam's own direction, turned into the world frame exactly; the others transcribe how
// the authors' code labeled its range image.
enum class AzimuthLabels {
    exact,     // column j: azimuth_offset + j·2π/n
    linspace,  // column j: azimuth_offset + j·2π/(n − 1), numpy.linspace(0, 2π, n) (first and last both 0)
};
enum class HeadingRoll {
    exact,          // allocentric azimuth = heading + the column's label
    whole_columns,  // the image rolled by the heading truncated to whole columns: column j gets the
                    // label of column (j + floor(heading / (2π/n))) mod n, heading taken in [0, 2π)
};

// A beam table: every elevation (row, top first) × azimuth_count columns at robot-frame azimuth
// azimuth_offset + j·2π/azimuth_count. Beam index = row·azimuth_count + column.
struct LidarSpec {
    std::string name = "custom";
    std::vector<double> elevations{0.0};  // radians
    int azimuth_count = 720;
    double azimuth_offset = 0.0;  // radians
    double height = 0.08;         // m above the agent's base (for a ground robot, above the floor)
    double min_range = 0.0;       // m, nearer returns are dropped (a real scanner's blind zone)
    double max_range = 20.0;      // m
    double range_noise_sd = 0.0;  // m, Gaussian noise added to each range
    double dropout = 0.0;         // probability that a beam returns nothing
    // Angle labels (level poses only when not exact): the beams are cast in their own directions
    // whatever the labels; only the angles the returns carry change.
    AzimuthLabels azimuth_labels = AzimuthLabels::exact;
    HeadingRoll heading_roll = HeadingRoll::exact;
    std::vector<double> elevation_labels;  // rad, one per row; empty: the rows' own elevations

    // The paper's 2-D scanner: 720 beams, 0.5° apart, at 0.08 m.
    static LidarSpec horizontal();
    // The paper's 3-D scanner: the 90 × 180 range image at 0.18 m; `upper_only` keeps rows 0-44.
    static LidarSpec spherical(bool upper_only = true);
    // The flying agents' scanner: all 90 rows of the spherical one, both halves, at the body's
    // center (height 0; docs/flying.md#models).
    static LidarSpec spherical_full();
    // The same image labeled as the authors' code labels it: columns linspace(0, 2π, 180), rows
    // linspace(π/2, −π/2, 90), rolled by the heading truncated to whole 2° columns.
    static LidarSpec spherical_as_authors(bool upper_only = true);

    std::size_t beam_count() const { return elevations.size() * static_cast<std::size_t>(azimuth_count); }
    // The elevation the returns of each row carry.
    const std::vector<double>& row_labels() const { return elevation_labels.empty() ? elevations : elevation_labels; }
    bool exact_labels() const {
        return azimuth_labels == AzimuthLabels::exact && heading_roll == HeadingRoll::exact && elevation_labels.empty();
    }
    // Same beams, same labels, same noise: scans are identical whatever the names.
    bool same_beams(const LidarSpec& o) const {
        return elevations == o.elevations && azimuth_count == o.azimuth_count && azimuth_offset == o.azimuth_offset &&
               height == o.height && min_range == o.min_range && max_range == o.max_range &&
               range_noise_sd == o.range_noise_sd && dropout == o.dropout && azimuth_labels == o.azimuth_labels &&
               heading_roll == o.heading_roll && elevation_labels == o.elevation_labels;
    }
    static const params::Table<LidarSpec>& table();
    void validate() const;                    // throws params::ParamError naming the bad field
    static constexpr double max_beams = 1e7;  // rows × azimuth_count: beyond it a scan would not fit
};

// Seeds the optional range noise and dropout. The noise of beam b in scan s depends only on
// (seed, s, b), so casting a subset of beams never changes the other beams' noise.
struct NoiseKey {
    std::uint64_t seed = 0;
    std::uint64_t scan_index = 0;
};

class Lidar {
public:
    explicit Lidar(LidarSpec spec);
    const LidarSpec& spec() const { return spec_; }

    // Cast the beams from `pose` and append the hits to `out` (which is cleared first). The sensor
    // sits `height` above the pose along its up axis and turns with it; returns are in the world
    // frame (allocentric). `rows`, if not empty, flags which rows to cast (one flag per elevation);
    // only a level pose takes a row mask, since a tilted sensor's rows no longer have one elevation.
    void scan(const World& world, const Pose& pose, Scan& out, const NoiseKey& noise = {},
              const std::vector<char>& rows = {}) const;
    Scan scan(const World& world, const Pose& pose, const NoiseKey& noise = {}) const {
        Scan s;
        scan(world, pose, s, noise);
        return s;
    }

private:
    void scan_tilted(const World& world, const Pose& pose, Scan& out, const NoiseKey& noise) const;
    // The steps of a level scan: the columns' azimuths_, the cast rows' dirs_ (and ranges_ sized
    // for them), then the returns from ranges_ into the cleared `out`.
    void set_azimuths(double heading) const;
    void set_beams(double heading) const;
    template <bool noisy>
    void write_returns(Scan& out, const NoiseKey& noise) const;
    // Adds the beam's noise to r; false if the beam drops out or leaves [min_range, max_range].
    bool add_noise(double& r, const NoiseKey& noise, std::uint64_t beam) const;

    LidarSpec spec_;
    std::vector<double> cos_el_, sin_el_, column_azimuth_, column_cos_, column_sin_;
    std::vector<double> column_label_;  // the azimuth label of each column (azimuth_labels)
    // Scratch space reused between scans: a Lidar is not shared between threads.
    mutable std::vector<Vec3> dirs_;
    mutable std::vector<Vec2> horizontal_;
    mutable std::vector<double> ranges_, azimuths_;
    mutable std::vector<std::size_t> cast_rows_;
    // The heading and rows that azimuths_ and dirs_ were set for (NaN: none).
    mutable double beams_heading_ = NAN;
    mutable std::vector<std::size_t> beams_rows_;
};

}  // namespace bvc3d
