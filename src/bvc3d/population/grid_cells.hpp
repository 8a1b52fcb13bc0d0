#pragma once
// Population stage: grid cells, idealised (docs/model-reference.md#grid-cells; the authors' follow-up to the paper,
// Dukenbaev et al. 2026). Takes: the agent's position on the floor — the true one, or one integrated from its steps
// with seeded noise. Gives: one rate in [0, 1] per cell, reading no other population.
//
// A cell of spacing λ, orientation α and phase t, at position p (x, y):
//   r = R(−α)(p − t),  f = 2π/λ
//   z = [cos(f r_x) + cos(f(r_x/2 + √3 r_y/2)) + cos(f(r_x/2 − √3 r_y/2))] / 3          ∈ [−0.5, 1]
//   rate = clip((z'^(2/3) − 0.7)/0.3, 0, 1),  z' = (z + 0.5)/1.5                          ∈ [0, 1]
// λ is the wavelength of the three plane waves: neighbouring field centres lie 2λ/√3 apart, along axes at 30° from
// the waves (α + 30° + k·60°). z' maps z's analytic range onto [0, 1] (the authors normalise each cell's z to [0, 1]
// over time instead: the same map once a cell has visited its field's peak and a trough).
//
// A module: n cells, cell c with orientation α + (c mod n_orientations)·2π/n_orientations (the authors: 8, i.e.
// 0°, 45°, …, 315°) and phase t = R(α_c)·λ·(u·(1, 1/√3) + v·(1, −1/√3)), the lattice's unit cell, with (u, v) the
// 2-D Sobol point number ⌊c / n_orientations⌋ scrambled by a digital shift drawn from the seed: each orientation's
// phases spread evenly over its unit cell.
//
// Path integration (input: path): the position estimate starts at the first step's true position, then adds each
// step's true displacement plus Gaussian noise of sd path_noise (m, per axis, per model step) drawn from the seed
// and the step's index (counter-based: the same at every block size, and across a checkpoint). Its error is a
// random walk: sd path_noise·√steps.
#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "bvc3d/core/params.hpp"
#include "bvc3d/population/population.hpp"

namespace bvc3d {

enum class GridInput { pose, path };

struct GridParams {
    double spacing = 4.0;      // λ, m (the authors' scales: 4 / 5.5 / 7)
    double orientation = 0.0;  // α of the first orientation, rad
    int n_orientations = 8;    // orientations α + k·2π/n_orientations
    int n = 800;               // cells (the authors: 800 / 400 / 400)
    GridInput input = GridInput::pose;
    double path_noise = 0.01;  // m per axis per model step, with input: path
    static const params::Table<GridParams>& table();
    void validate() const { table().check(*this); }
};

// The equations above, written once.
namespace grid {
struct Cell {
    double orientation;   // α_c, rad
    double tx, ty;        // phase t, m
    double cos_a, sin_a;  // cos α_c, sin α_c: computed once, not at every step
};
// z of a cell at (x, y).
double interference(const Cell& c, double spacing, double x, double y);
// The rate for z.
double rate(double z);
// rate(interference(c, spacing, x, y)), bit for bit, with less work where the rate is 0.
double rate_at(const Cell& c, double spacing, double x, double y);
// The module's cells for a seed.
std::vector<Cell> module(const GridParams& p, std::uint64_t seed);
// Point k of the 2-D Sobol sequence (direction numbers of x and x + 1), each coordinate's bits XORed with `shift`'s
// 32-bit halves: in [0, 1)².
void sobol_point(std::uint32_t k, std::uint64_t shift, double& u, double& v);
}  // namespace grid

class GridCells : public Population {
public:
    GridCells(const GridParams& p, std::uint64_t seed);
    const GridParams& params() const { return p_; }
    const std::vector<grid::Cell>& cells() const { return cells_; }
    // Rates at (x, y) into out (n values).
    void rates(double x, double y, std::span<double> out) const;
    // The position the cells read at model step `index` (0, 1, ... of a trial) with the agent at (x, y): that
    // position (input: pose), or the estimate integrated to it (input: path; each call is one step along the path).
    std::array<double, 2> read_position(double x, double y, std::uint64_t index);

    std::size_t size() const override { return cells_.size(); }
    void step(const StepBlock& block, std::span<const std::span<const double>> inputs, std::span<double> out) override;
    std::vector<StateArray> state() const override;
    void restore(const std::vector<StateArray>& state) override;

private:
    GridParams p_;
    std::uint64_t seed_;
    std::vector<grid::Cell> cells_;
    // Path integration: the estimate and the true position it last integrated to, once there are.
    bool started_ = false;
    double est_x_ = 0, est_y_ = 0, last_x_ = 0, last_y_ = 0;
};

}  // namespace bvc3d
