#include "bvc3d/population/grid_cells.hpp"

#include <algorithm>
#include <cmath>

#include "bvc3d/core/angles.hpp"
#include "bvc3d/core/error.hpp"
#include "bvc3d/core/random.hpp"

namespace bvc3d {

namespace {
constexpr std::uint64_t phase_tag = 0x6772696470686173;  // the phases' shift: hash(seed, tag, 0)
constexpr std::uint64_t noise_tag = 0x677269646e6f6973;  // path noise: hash(seed ^ tag, step, axis·2 + draw)
}  // namespace

const params::Table<GridParams>& GridParams::table() {
    using namespace params;
    using P = GridParams;
    static const Table<P> t(
        "grid cells",
        {real("spacing", &P::spacing, above(0), "λ, m: the plane waves' wavelength (fields 2λ/√3 apart)"),
         real("orientation", &P::orientation, finite(), "α, rad: the first orientation").in_radians(),
         integer("n_orientations", &P::n_orientations, closed(1, 360), "orientations α + k·2π/n_orientations"),
         integer("n", &P::n, closed(1, 1000000), "cells"),
         choice("input", &P::input, {{GridInput::pose, "pose"}, {GridInput::path, "path"}},
                "pose: the true position; path: integrated from the steps with noise"),
         real("path_noise", &P::path_noise, closed(0, 100), "m, sd per axis per model step of path integration")});
    return t;
}

namespace grid {

namespace {
// The three plane waves' phases at (x, y).
struct Phases {
    double a, b, c;
};
Phases phases(const Cell& cell, double spacing, double x, double y) {
    const double dx = x - cell.tx, dy = y - cell.ty;
    const double ca = cell.cos_a, sa = cell.sin_a;
    const double rx = ca * dx + sa * dy, ry = -sa * dx + ca * dy;  // R(−α)(p − t)
    const double f = 2.0 * pi / spacing, h = std::sqrt(3.0) / 2.0;
    return {f * rx, f * (rx / 2 + h * ry), f * (rx / 2 - h * ry)};
}
}  // namespace

double interference(const Cell& c, double spacing, double x, double y) {
    const Phases p = phases(c, spacing, x, y);
    return (std::cos(p.a) + std::cos(p.b) + std::cos(p.c)) / 3.0;
}

double rate_at(const Cell& c, double spacing, double x, double y) {
    const Phases p = phases(c, spacing, x, y);
    const double two = std::cos(p.a) + std::cos(p.b);
    // With the first two waves' sum below 0, z < 1/3 + rounding, short of the threshold z ≈ 0.379 (z' = 0.7^1.5)
    // by far: the rate is 0 (half the places), and the third cosine is not taken.
    if (two < 0.0) return 0.0;
    return rate((two + std::cos(p.c)) / 3.0);
}

double rate(double z) {
    const double zn = std::clamp((z + 0.5) / 1.5, 0.0, 1.0);
    // Below 0.342 < 0.7³ the cube root is under 0.7 by far more than its rounding error: the rate is 0 (most cells
    // at most places), and the cube root is not taken.
    if (zn * zn < 0.342) return 0.0;
    return std::clamp((std::cbrt(zn * zn) - 0.7) / 0.3, 0.0, 1.0);
}

void sobol_point(std::uint32_t k, std::uint64_t shift, double& u, double& v) {
    std::uint32_t a = 0, b = 0, m = 1;  // m_i of the polynomial x + 1: m_1 = 1, m_i = 2·m_(i−1) XOR m_(i−1)
    for (int i = 0; i < 32; ++i) {
        if (i > 0) m = (m << 1) ^ m;
        if (k >> i & 1u) {
            a ^= 1u << (31 - i);  // van der Corput
            b ^= m << (31 - i);   // V_i = m_i / 2^i
        }
    }
    a ^= static_cast<std::uint32_t>(shift);
    b ^= static_cast<std::uint32_t>(shift >> 32);
    u = a * 0x1p-32;
    v = b * 0x1p-32;
}

std::vector<Cell> module(const GridParams& p, std::uint64_t seed) {
    const std::uint64_t shift = hash_u64(seed, phase_tag, 0);
    std::vector<Cell> cells(static_cast<std::size_t>(p.n));
    for (int c = 0; c < p.n; ++c) {
        const double a = p.orientation + 2.0 * pi * (c % p.n_orientations) / p.n_orientations;
        double u, v;
        sobol_point(static_cast<std::uint32_t>(c / p.n_orientations), shift, u, v);
        const double lx = p.spacing * (u + v), ly = p.spacing * (u - v) / std::sqrt(3.0);  // in the cell's frame
        cells[c] = {a, std::cos(a) * lx - std::sin(a) * ly, std::sin(a) * lx + std::cos(a) * ly, std::cos(a),
                    std::sin(a)};
    }
    return cells;
}

}  // namespace grid

GridCells::GridCells(const GridParams& p, std::uint64_t seed) : p_(p), seed_(seed) {
    p_.validate();
    cells_ = grid::module(p_, seed_);
}

void GridCells::rates(double x, double y, std::span<double> out) const {
    for (std::size_t c = 0; c < cells_.size(); ++c) out[c] = grid::rate_at(cells_[c], p_.spacing, x, y);
}

void GridCells::step(const StepBlock& block, std::span<const std::span<const double>>, std::span<double> out) {
    const std::size_t n = size();
    for (std::size_t s = 0; s < block.size(); ++s) {
        const Pose& pose = block.steps[s].pose;
        double x = pose.x, y = pose.y;
        if (p_.input == GridInput::path) {
            if (!started_) {
                est_x_ = x;
                est_y_ = y;
            } else {
                const auto index = static_cast<std::uint64_t>(block.first_index + static_cast<std::int64_t>(s));
                const auto normal = [&](std::uint64_t axis) {  // Box-Muller on two counter-based uniforms
                    const double u1 = 1.0 - hash_uniform(seed_ ^ noise_tag, index, 2 * axis);
                    const double u2 = hash_uniform(seed_ ^ noise_tag, index, 2 * axis + 1);
                    return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * pi * u2);
                };
                est_x_ += (x - last_x_) + p_.path_noise * normal(0);
                est_y_ += (y - last_y_) + p_.path_noise * normal(1);
            }
            started_ = true;
            last_x_ = x;
            last_y_ = y;
            x = est_x_;
            y = est_y_;
        }
        rates(x, y, out.subspan(s * n, n));
    }
}

std::vector<StateArray> GridCells::state() const {
    if (p_.input == GridInput::pose) return {};
    return {{"path", {5}, std::vector<double>{started_ ? 1.0 : 0.0, est_x_, est_y_, last_x_, last_y_}}};
}

void GridCells::restore(const std::vector<StateArray>& state) {
    if (p_.input == GridInput::pose) return;
    const auto& v = state_doubles(state, "path", 5);
    for (double d : v)
        if (!std::isfinite(d)) throw InputError("grid cells: its path integration state is not finite");
    started_ = v[0] != 0.0;
    est_x_ = v[1];
    est_y_ = v[2];
    last_x_ = v[3];
    last_y_ = v[4];
}

}  // namespace bvc3d
