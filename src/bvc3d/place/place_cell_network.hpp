#pragma once
// Place-cell stage (docs/model-reference.md#place-cell-network): a rate network driven by BVCs and, optionally, grid
// cells (docs/model-reference.md#place-cells-fed-by-grid-cells), learning with Oja's rule.
// Takes: BVC rates b (and grid rates c), one vector per model step. Gives: place-cell rates v.
//
// One Euler step, k = Δt/τ_p, g the grid influence (grid_influence), gain γ (gain):
//   s ← s + k·[−s + (1−g)·W_b·b + g·W_g·c − (1−g)·Γ_pb·Σb − g·Γ_pg·Σc − Γ_pp·Σv_prev],   v = tanh(γ·[s]+)
//   learning: W_b,i ← W_b,i + (1−g)·η·v_i·(b − v_i·W_b,i/α_pb)            (Oja, row i; W_g never learns)
// W_b starts Bernoulli(p_connect) from the trial's `weights` stream; W_g is a fixed binary mask,
// Bernoulli(grid_p_connect) from its `grid_mask` stream. Without grid cells (n_grid = 0, then g must be 0) this is
// the paper's network (SPEC §6); with g = 0 the grid terms add exact zeros and (1−g) multiplies by exactly 1, so a
// network with grid cells and g = 0 gives the paper's bits too.
//
// Single precision (weights, membrane, rates): the recorded rates are float32 anyway, and sums run
// in a fixed order of 8 interleaved partial sums, so results are bit-identical whatever the
// vector width the compiler picks. BVC rates and weights smaller in magnitude than the smallest
// normal float (1.2e-38) are taken as 0: no subnormal number ever enters the arithmetic (each costs
// a microcode assist per instruction on many CPUs).
#include <cstdint>
#include <span>
#include <vector>

#include "bvc3d/core/aligned.hpp"
#include "bvc3d/core/params.hpp"

namespace bvc3d {

struct PlaceParams {
    int n_place = 250;
    double p_connect = 0.25;                // initial weights are Bernoulli(p_connect)
    double dt_over_tau = 0.5;               // Δt/τ_p
    double gamma_pb = 0.3;                  // feedforward inhibition
    double gamma_pp = 0.5;                  // recurrent inhibition
    double gain = 1.0;                      // g in v = tanh(g·[s]+)
    double eta = 0.096;                     // learning rate Δt/τ_W
    double alpha_pb = 0.70710678118654752;  // √0.5
    // Grid cells (SPEC §16; quiet at their defaults, so the paper's models keep their canonical text).
    double grid_influence = 0.0;  // g
    double gamma_pg = 0.35;       // Γ_pg, inhibition by the grid cells' total
    double grid_p_connect = 0.3;  // W_g is Bernoulli(grid_p_connect)
    static const params::Table<PlaceParams>& table();
    void validate() const { table().check(*this); }
};

class PlaceCellNetwork {
public:
    // Initial weights drawn from the trial's `weights` stream (bvc3d::Stream::weights) of `seed`; with n_grid > 0
    // grid inputs, the mask W_g from its `grid_mask` stream. InputError for grid_influence > 0 without grid cells.
    PlaceCellNetwork(int n_bvc, const PlaceParams& params, std::uint64_t seed, int n_grid = 0);

    int n_bvc() const { return n_bvc_; }
    int n_grid() const { return n_grid_; }
    int n_place() const { return p_.n_place; }
    const PlaceParams& params() const { return p_; }

    // One Euler step of the membrane, new rates, and (if learn) one Oja update. Returns the rates.
    std::span<const float> step(std::span<const double> bvc_rates, bool learn) { return step(bvc_rates, {}, learn); }
    // The same with the grid cells' rates (n_grid values; none when n_grid = 0).
    std::span<const float> step(std::span<const double> bvc_rates, std::span<const double> grid_rates, bool learn);
    // learn.size() steps at once, step t reading bvc_rates[t·n_bvc ...] and learning if learn[t]: the
    // same bits as that many calls of step(). Returns every step's rates (steps × n_place, row-major).
    // One pass over the weights serves every 8 steps; the rows Oja's rule changes within the block
    // (the few active cells) are multiplied again for the steps after.
    std::span<const float> step_block(std::span<const double> bvc_rates, std::span<const char> learn) {
        return step_block(bvc_rates, {}, learn);
    }
    // The same with the grid cells' rates (steps × n_grid, row-major).
    std::span<const float> step_block(std::span<const double> bvc_rates, std::span<const double> grid_rates,
                                      std::span<const char> learn);

    std::span<const float> rates() const { return v_; }
    std::span<const float> membrane() const { return s_; }
    // Row-major n_place × n_bvc weights.
    std::vector<float> weights() const;
    void set_weights(std::span<const float> w);
    // Row-major n_place × n_grid mask W_g (0 or 1).
    std::vector<float> grid_mask() const;
    // Membrane and rates back to zero; weights kept.
    void reset();
    // Restore the dynamic state (checkpoints).
    void set_state(std::span<const float> membrane, std::span<const float> rates);
    // Row i's weights (n_bvc) and membrane set, its rate kept (a growing network recruits cell i this way).
    void set_cell(int i, std::span<const float> w, float membrane);

private:
    // Weights in the kernels' paired layout (place_kernels.hpp): rows 2p and 2p+1 interleaved by
    // blocks of 8 columns; row(i) is row i's first block, column j at row(i)[paired_column(j)].
    std::size_t pair_stride() const { return 2 * stride_; }
    float* row(int i) { return w_.data() + static_cast<std::size_t>(i / 2) * pair_stride() + 8 * (i % 2); }
    const float* row(int i) const { return w_.data() + static_cast<std::size_t>(i / 2) * pair_stride() + 8 * (i % 2); }
    int pairs() const { return (p_.n_place + 1) / 2; }
    // BVC rates as the network's float inputs (vb: stride_ entries, padding 0); throws on a non-finite rate.
    void inputs(std::span<const double> bvc_rates, float* vb) const;
    // Grid rates likewise (vg: grid_stride_ entries).
    void grid_inputs(std::span<const double> grid_rates, float* vg) const;
    // The membrane and rates from this step's drive (W_b·vb), grid drive (W_g·vg; null without grid cells) and
    // inputs, then Oja's update if learn; `learned` (if not null) collects the rows the update changed.
    void advance(const float* drive, const float* grid_drive, const float* vb, const float* vg, bool learn,
                 std::vector<int>* learned);

    int n_bvc_, n_grid_;
    std::size_t stride_,
        grid_stride_;  // n_bvc rounded up to a multiple of 8; padding (and an odd count's last row) stays 0
    PlaceParams p_;
    std::vector<float, CacheAligned<float>> w_;  // W_b (paired layout)
    // W_g by columns, one bit per row (kernels::mask_products): column j's rows at grid_bits_[j·grid_words_ ...].
    std::vector<std::uint16_t> grid_bits_;
    std::size_t grid_words_ = 0;
    std::vector<float> grid_lanes_;  // mask_products' lanes
    std::vector<float> s_, v_, vb_, drive_;
    std::vector<float> vg_, grid_drive_, combined_;  // with grid cells only
    std::vector<int> active_;         // the cells whose rate may be other than ±0 (s > 0 at the last step)
    std::vector<float> block_rates_;  // step_block's results
    std::vector<int> learned_;        // rows Oja's rule changed within a block
    std::vector<char> is_learned_;
};

}  // namespace bvc3d
