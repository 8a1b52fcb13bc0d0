#include "bvc3d/sensor/recorded_returns.hpp"

#include <cmath>

#include "bvc3d/core/error.hpp"

namespace bvc3d {

std::string selection_name(ReturnSelection s) {
    switch (s) {
        case ReturnSelection::upper_half:
            return "upper_half";
        case ReturnSelection::all:
            return "all";
        case ReturnSelection::horizontal_slice:
            return "horizontal_slice";
    }
    return "";
}

ReturnSelection selection_for(const LidarSpec& sensor, bool planar) {
    if (planar) return ReturnSelection::horizontal_slice;
    for (const double e : sensor.elevations)
        if (e < 0) return ReturnSelection::all;
    return ReturnSelection::upper_half;
}

const params::Table<RecordedReturnParams>& RecordedReturnParams::table() {
    using namespace params;
    static const Table<RecordedReturnParams> t(
        "recorded returns",
        {real("min_range", &RecordedReturnParams::min_range, at_least(0), "m, nearer points are dropped"),
         real("max_range", &RecordedReturnParams::max_range, above(0), "m, farther points are dropped"),
         real("slice_half_width", &RecordedReturnParams::slice_half_width, closed_open(0, pi / 2),
              "rad, the 2-D models read the returns with |elevation| <= this")
             .in_radians()});
    return t;
}

void RecordedReturnParams::validate() const {
    table().check(*this);
    if (!(min_range < max_range)) table().fail("min_range", "must be less than max_range");
}

namespace {

bool keeps_elevation(double phi, const RecordedReturnParams& p, ReturnSelection s) {
    switch (s) {
        case ReturnSelection::upper_half:
            return phi >= 0;
        case ReturnSelection::all:
            return true;
        case ReturnSelection::horizontal_slice:
            return std::abs(phi) <= p.slice_half_width;
    }
    return false;
}

}  // namespace

void returns_from_points(std::span<const double> xyz, const Eigen::Matrix3d& R, const RecordedReturnParams& p,
                         ReturnSelection selection, Scan& out) {
    out.clear();
    const std::size_t n = xyz.size() / 3;
    out.reserve(selection == ReturnSelection::horizontal_slice ? n / 16 : n);
    const bool upper = selection == ReturnSelection::upper_half;
    const bool slice = selection == ReturnSelection::horizontal_slice;
    // A slice's points satisfy |v_z| <= tan(w)·|v_xy|: that test (with a margin for rounding) spares
    // the angles of the points it rejects; the kept ones are decided on φ itself.
    const double tan_w = std::tan(p.slice_half_width) * (1 + 1e-9);
    const double r00 = R(0, 0), r01 = R(0, 1), r02 = R(0, 2), r10 = R(1, 0), r11 = R(1, 1), r12 = R(1, 2),
                 r20 = R(2, 0), r21 = R(2, 1), r22 = R(2, 2);
    for (std::size_t i = 0; i < n; ++i) {
        const double x = xyz[3 * i], y = xyz[3 * i + 1], z = xyz[3 * i + 2];
        const double vz = r20 * x + r21 * y + r22 * z;
        if (upper && vz < 0) continue;
        const double vx = r00 * x + r01 * y + r02 * z, vy = r10 * x + r11 * y + r12 * z;
        const double h2 = vx * vx + vy * vy;
        if (slice && vz * vz > tan_w * tan_w * h2) continue;
        const double r = std::sqrt(h2 + vz * vz);
        if (!(r >= p.min_range && r <= p.max_range)) continue;  // also drops NaN
        const double phi = std::atan2(vz, std::sqrt(h2));
        if (slice && !(std::abs(phi) <= p.slice_half_width)) continue;
        double theta = std::atan2(vy, vx);
        if (theta == -pi) theta = pi;  // (−π, π]
        out.push_back({r, theta, phi});
    }
}

recording::PointCloud points_from_returns(const Scan& scan, const Eigen::Matrix3d& R) {
    recording::PointCloud cloud;
    cloud.xyz.reserve(3 * scan.size());
    for (const auto& r : scan) {
        const double c = std::cos(r.elevation);
        const Vec3 v(r.range * c * std::cos(r.azimuth), r.range * c * std::sin(r.azimuth),
                     r.range * std::sin(r.elevation));
        const Vec3 p = R.transpose() * v;
        cloud.xyz.insert(cloud.xyz.end(), {p.x(), p.y(), p.z()});
    }
    return cloud;
}

Eigen::Isometry3d sensor_pose(const Pose& agent, double height) {
    Eigen::Isometry3d m = Eigen::Isometry3d::Identity();
    m.linear() = agent.rotation();
    m.translation() = agent.position() + m.linear() * Vec3(0, 0, height);
    return m;
}

void filter_returns(Scan& scan, const RecordedReturnParams& p, ReturnSelection selection) {
    std::erase_if(scan, [&](const LidarReturn& r) {
        return !(r.range >= p.min_range && r.range <= p.max_range) || !keeps_elevation(r.elevation, p, selection);
    });
}

RecordedScans::RecordedScans(std::shared_ptr<const recording::Recording> recording)
    : recording_(std::move(recording)) {}

const recording::PointCloud& RecordedScans::cloud(std::size_t i) {
    if (i != loaded_) {
        loaded_ = static_cast<std::size_t>(-1);
        cloud_ = recording_->load(i);
        loaded_ = i;
    }
    return cloud_;
}

RecordedSource::RecordedSource(std::shared_ptr<RecordedScans> scans, RecordedReturnParams params,
                               ReturnSelection selection)
    : scans_(std::move(scans)), params_(params), selection_(selection) {
    params_.validate();
}

void RecordedSource::returns(std::uint64_t step, const Pose&, const std::vector<char>&, Scan& out) {
    const auto& rec = scans_->recording();
    if (step >= rec.size())
        throw InputError("recording '" + rec.name + "' has " + std::to_string(rec.size()) + " scans; step " +
                         std::to_string(step) + " has none");
    const auto i = static_cast<std::size_t>(step);
    returns_from_points(scans_->cloud(i).xyz, rec.poses[i].world_from_sensor.linear(), params_, selection_, out);
}

FilteredSource::FilteredSource(std::shared_ptr<ReturnSource> inner, RecordedReturnParams params,
                               ReturnSelection selection)
    : inner_(std::move(inner)), params_(params), selection_(selection) {
    params_.validate();
    if (const LidarSpec* table = inner_->beam_table())
        for (const double e : table->elevations) allowed_.push_back(keeps_elevation(e, params_, selection_));
}

void FilteredSource::returns(std::uint64_t step, const Pose& pose, const std::vector<char>& rows, Scan& out) {
    if (inner_->beam_table() && pose.level()) {
        mask_ = allowed_;
        if (!rows.empty())
            for (std::size_t i = 0; i < mask_.size(); ++i) mask_[i] = mask_[i] && rows.at(i);
        inner_->returns(step, pose, mask_, out);
    } else {
        inner_->returns(step, pose, rows, out);
    }
    filter_returns(out, params_, selection_);
}

}  // namespace bvc3d
