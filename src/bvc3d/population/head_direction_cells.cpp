#include "bvc3d/population/head_direction_cells.hpp"

#include <cmath>
#include <numbers>

#include "bvc3d/core/error.hpp"
#include "bvc3d/core/icosahedron.hpp"

namespace bvc3d {

const params::Table<HeadDirectionParams>& HeadDirectionParams::table() {
    using namespace params;
    using P = HeadDirectionParams;
    static const Table<P> t(
        "head-direction cells",
        {integer("n", &P::n, closed(1, 100000), "cells around the heading (planar)"),
         choice("space", &P::space, {{HdSpace::planar, "planar"}, {HdSpace::spherical, "spherical"}},
                "planar: n cells tuned to the heading; spherical: 20 cells (icosahedron faces) tuned to the 3-D "
                "direction of motion")});
    return t;
}

namespace hd {

double preferred_heading(int k, int n) { return 2.0 * std::numbers::pi * k / n; }

const std::array<Vec3, 20>& icosahedron_faces() { return bvc3d::icosahedron_faces(); }

void planar_rates(double heading, std::span<double> out) {
    const int n = static_cast<int>(out.size());
    for (int k = 0; k < n; ++k) out[k] = std::cos(heading - preferred_heading(k, n));
}

void spherical_rates(const Vec3& w, std::span<double> out) {
    const Vec3 u = w.normalized();
    const auto& faces = icosahedron_faces();
    for (std::size_t k = 0; k < faces.size(); ++k) out[k] = faces[k].dot(u);
}

Vec3 direction(double yaw, double pitch) {
    return {std::cos(pitch) * std::cos(yaw), std::cos(pitch) * std::sin(yaw), std::sin(pitch)};
}

}  // namespace hd

HeadDirectionCells::HeadDirectionCells(const HeadDirectionParams& p) : p_(p) { p_.validate(); }

std::size_t HeadDirectionCells::size() const {
    return p_.space == HdSpace::planar ? static_cast<std::size_t>(p_.n) : hd::icosahedron_faces().size();
}

void HeadDirectionCells::step(const StepBlock& block, std::span<const std::span<const double>>, std::span<double> out) {
    const std::size_t n = size();
    for (std::size_t s = 0; s < block.size(); ++s) {
        const Pose& pose = block.steps[s].pose;
        const auto row = out.subspan(s * n, n);
        if (p_.space == HdSpace::planar) {
            hd::planar_rates(pose.heading, row);
            continue;
        }
        const Vec3 here = pose.position();
        const Vec3 moved = has_previous_ ? Vec3(here - previous_) : Vec3(0, 0, 0);
        hd::spherical_rates(moved.norm() > 1e-9 ? moved : hd::direction(pose.heading, pose.pitch), row);
        previous_ = here;
        has_previous_ = true;
    }
}

std::vector<StateArray> HeadDirectionCells::state() const {
    if (p_.space == HdSpace::planar) return {};
    return {
        {"previous", {4}, std::vector<double>{has_previous_ ? 1.0 : 0.0, previous_.x(), previous_.y(), previous_.z()}}};
}

void HeadDirectionCells::restore(const std::vector<StateArray>& state) {
    if (p_.space == HdSpace::planar) return;
    const auto& v = state_doubles(state, "previous", 4);
    has_previous_ = v[0] != 0.0;
    previous_ = Vec3(v[1], v[2], v[3]);
}

}  // namespace bvc3d
