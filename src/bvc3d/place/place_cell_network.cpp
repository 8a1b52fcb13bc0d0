#include "bvc3d/place/place_cell_network.hpp"

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <string>

#include "bvc3d/core/error.hpp"
#include "bvc3d/core/random.hpp"
#include "bvc3d/place/place_kernels.hpp"

namespace bvc3d {

namespace {
// BVC rates and weights smaller in magnitude than the smallest normal float (2^-126, 1.2e-38) enter
// the network as 0, and Oja's rule stores such results as 0: the arithmetic never reads or writes a
// subnormal number, which costs a microcode assist per instruction on many CPUs. (No process-wide
// flush-to-zero mode is set: it would change the arithmetic of every other library in the process.)
constexpr float tiny_operand = FLT_MIN;
float flush_tiny(float x) { return std::abs(x) < tiny_operand ? 0.0f : x; }
}  // namespace

const params::Table<PlaceParams>& PlaceParams::table() {
    using namespace params;
    static const Table<PlaceParams> t(
        "place cells",
        {integer("n_place", &PlaceParams::n_place, closed(1, 1000000), "place cells"),
         real("p_connect", &PlaceParams::p_connect, closed(0, 1), "initial weights are Bernoulli(p_connect)"),
         real("dt_over_tau", &PlaceParams::dt_over_tau, open_closed(0, 1), "Δt/τ_p, the membrane's Euler step"),
         real("gamma_pb", &PlaceParams::gamma_pb, finite(), "feedforward inhibition Γ_pb"),
         real("gamma_pp", &PlaceParams::gamma_pp, finite(), "recurrent inhibition Γ_pp"),
         real("gain", &PlaceParams::gain, open_closed(0, 1e6), "g in v = tanh(g·[s]+)"),
         real("eta", &PlaceParams::eta, closed(0, 1e6), "learning rate η = Δt/τ_W"),
         real("alpha_pb", &PlaceParams::alpha_pb, above(0), "α_pb of Oja's rule"),
         real("grid_influence", &PlaceParams::grid_influence, closed(0, 1),
              "g: the grid cells' share of the drive (0: BVCs only, the paper's network)")
             .quiet_at_default(),
         real("gamma_pg", &PlaceParams::gamma_pg, finite(), "inhibition Γ_pg by the grid cells' total")
             .quiet_at_default(),
         real("grid_p_connect", &PlaceParams::grid_p_connect, closed(0, 1),
              "the grid mask W_g is Bernoulli(grid_p_connect)")
             .quiet_at_default()});
    return t;
}

PlaceCellNetwork::PlaceCellNetwork(int n_bvc, const PlaceParams& params, std::uint64_t seed, int n_grid)
    : n_bvc_(n_bvc), n_grid_(n_grid), p_(params) {
    p_.validate();
    if (n_bvc < 1) throw InputError("place cells: need at least one BVC input");
    if (n_grid < 0) throw InputError("place cells: a negative number of grid cells");
    if (n_grid == 0 && p_.grid_influence > 0)
        throw InputError("place cells: grid_influence = " + std::to_string(p_.grid_influence) +
                         " needs grid cells as input (none given)");
    stride_ = (static_cast<std::size_t>(n_bvc) + 7) / 8 * 8;
    w_.assign(static_cast<std::size_t>(pairs()) * pair_stride(), 0.0f);
    Rng rng(seed, Stream::weights);
    for (int i = 0; i < p_.n_place; ++i)
        for (int j = 0; j < n_bvc; ++j) row(i)[kernels::paired_column(j)] = rng.bernoulli(p_.p_connect) ? 1.0f : 0.0f;
    s_.assign(p_.n_place, 0.0f);
    v_.assign(p_.n_place, 0.0f);
    drive_.assign(2 * static_cast<std::size_t>(pairs()), 0.0f);
    vb_.assign(stride_, 0.0f);
    grid_stride_ = (static_cast<std::size_t>(n_grid) + 7) / 8 * 8;
    if (n_grid > 0) {
        grid_words_ = (static_cast<std::size_t>(p_.n_place) + 15) / 16;
        grid_bits_.assign(static_cast<std::size_t>(n_grid) * grid_words_, 0);
        Rng mask(seed, Stream::grid_mask);
        for (int i = 0; i < p_.n_place; ++i)
            for (int j = 0; j < n_grid; ++j)
                if (mask.bernoulli(p_.grid_p_connect))
                    grid_bits_[static_cast<std::size_t>(j) * grid_words_ + i / 16] |=
                        static_cast<std::uint16_t>(1u << (i % 16));
        grid_lanes_.assign(8 * 16 * grid_words_, 0.0f);
        vg_.assign(grid_stride_, 0.0f);
    }
}

void PlaceCellNetwork::inputs(std::span<const double> bvc_rates, float* vb) const {
    if (bvc_rates.size() != static_cast<std::size_t>(n_bvc_))
        throw InputError("place cells: expected " + std::to_string(n_bvc_) + " BVC rates, got " +
                         std::to_string(bvc_rates.size()));
    const std::size_t bad = kernels::to_floats(bvc_rates.data(), vb, bvc_rates.size(), tiny_operand);
    if (bad < bvc_rates.size()) throw InputError("place cells: BVC rate " + std::to_string(bad) + " is not finite");
}

void PlaceCellNetwork::grid_inputs(std::span<const double> grid_rates, float* vg) const {
    if (grid_rates.size() != static_cast<std::size_t>(n_grid_))
        throw InputError("place cells: expected " + std::to_string(n_grid_) + " grid rates, got " +
                         std::to_string(grid_rates.size()));
    const std::size_t bad = kernels::to_floats(grid_rates.data(), vg, grid_rates.size(), tiny_operand);
    if (bad < grid_rates.size()) throw InputError("place cells: grid rate " + std::to_string(bad) + " is not finite");
}

void PlaceCellNetwork::advance(const float* drive, const float* grid_drive, const float* vb, const float* vg,
                               bool learn, std::vector<int>* learned) {
    const float k = static_cast<float>(p_.dt_over_tau);
    // Inhibition uses the BVC total and the place cells' previous rates, summed in index order. Only
    // the cells that were active can have a rate other than ±0, and adding ±0 to a sum that is not −0
    // leaves it as it is (a sum of floats from +0 is never −0): summing the active ones is the sum.
    float previous = 0;
    for (int i : active_) previous += v_[i];
    const double g = p_.grid_influence;
    float feedforward = static_cast<float>((1.0 - g) * p_.gamma_pb) * kernels::sum8(vb, stride_);
    if (grid_drive) {
        // (1−g)·W_b·b + g·W_g·c; with g = 0, 1·x + 0 = x (x ≥ +0): the paper's drive, bit for bit.
        const float kb = static_cast<float>(1.0 - g), kg = static_cast<float>(g);
        combined_.resize(s_.size());
        for (std::size_t i = 0; i < s_.size(); ++i) combined_[i] = kb * drive[i] + kg * grid_drive[i];
        drive = combined_.data();
        feedforward += static_cast<float>(g * p_.gamma_pg) * kernels::sum8(vg, grid_stride_);
    }
    const float inhibition = feedforward + static_cast<float>(p_.gamma_pp) * previous;
    // tanh(g·[s]+); for a silent cell (the argument ±0, or NaN) the argument is its own tanh.
    bool finite = false;
    active_.resize(s_.size());
    active_.resize(kernels::membrane_step(s_.data(), drive, s_.size(), k, inhibition, static_cast<float>(p_.gain),
                                          v_.data(), active_.data(), &finite));
    for (int i : active_) v_[i] = std::tanh(v_[i]);
    // Weights that ran away (a learning rate far too large) show up here first: stop early.
    const auto diverged = [&] {
        return InputError(
            "place cells diverged (non-finite membrane potentials or weights): the weights ran away; is the "
            "learning rate eta = " +
            std::to_string(p_.eta) + " too large?");
    };
    if (!std::isfinite(inhibition) || !finite) throw diverged();
    if (!learn || !(p_.eta > 0)) return;
    // Oja: W_i += (1−g)·eta·v_i·(v_b - v_i·W_i/alpha). Silent cells (v_i = 0) do not change. A weight that is not
    // finite stops the network at once: the products skip inputs that are 0, which a weight of ±inf or NaN would
    // turn into NaN.
    const float eta = static_cast<float>((1.0 - g) * p_.eta), inv_alpha = static_cast<float>(1.0 / p_.alpha_pb);
    for (int i : active_) {
        const float vi = v_[i];
        if (vi == 0.0f) continue;
        if (!kernels::oja_row(row(i), vb, eta * vi, vi * inv_alpha, tiny_operand, stride_)) throw diverged();
        if (learned && !is_learned_[i]) {
            is_learned_[i] = 1;
            learned->push_back(i);
        }
    }
}

std::span<const float> PlaceCellNetwork::step(std::span<const double> bvc_rates, std::span<const double> grid_rates,
                                              bool learn) {
    inputs(bvc_rates, vb_.data());
    if (n_grid_ > 0 || !grid_rates.empty()) grid_inputs(grid_rates, vg_.data());
    kernels::paired_products(w_.data(), pair_stride(), vb_.data(), stride_, stride_, pairs(), 1, drive_.data(), 0);
    if (n_grid_ > 0) {
        grid_drive_.resize(drive_.size());
        kernels::mask_products(grid_bits_.data(), grid_words_, vg_.data(), static_cast<std::size_t>(n_grid_), s_.size(),
                               grid_lanes_.data(), grid_drive_.data());
    }
    advance(drive_.data(), n_grid_ > 0 ? grid_drive_.data() : nullptr, vb_.data(), vg_.data(), learn, nullptr);
    return v_;
}

std::span<const float> PlaceCellNetwork::step_block(std::span<const double> bvc_rates,
                                                    std::span<const double> grid_rates, std::span<const char> learn) {
    const std::size_t steps = learn.size(), n = static_cast<std::size_t>(n_bvc_),
                      ng = static_cast<std::size_t>(n_grid_);
    if (bvc_rates.size() != steps * n)
        throw InputError("place cells: expected " + std::to_string(steps) + " × " + std::to_string(n_bvc_) +
                         " BVC rates, got " + std::to_string(bvc_rates.size()));
    if (grid_rates.size() != steps * ng)
        throw InputError("place cells: expected " + std::to_string(steps) + " × " + std::to_string(n_grid_) +
                         " grid rates, got " + std::to_string(grid_rates.size()));
    // Every input is checked before the state changes.
    vb_.resize(std::max<std::size_t>(steps, 1) * stride_, 0.0f);
    for (std::size_t t = 0; t < steps; ++t) inputs(bvc_rates.subspan(t * n, n), vb_.data() + t * stride_);
    const std::size_t drive_stride = 2 * static_cast<std::size_t>(pairs());
    drive_.resize(std::max<std::size_t>(steps, 1) * drive_stride);
    kernels::paired_products(w_.data(), pair_stride(), vb_.data(), stride_, stride_, pairs(), static_cast<int>(steps),
                             drive_.data(), drive_stride);
    if (n_grid_ > 0) {  // by W_g's columns, only where a grid cell fires
        vg_.resize(std::max<std::size_t>(steps, 1) * grid_stride_, 0.0f);
        for (std::size_t t = 0; t < steps; ++t)
            grid_inputs(grid_rates.subspan(t * ng, ng), vg_.data() + t * grid_stride_);
        grid_drive_.resize(std::max<std::size_t>(steps, 1) * drive_stride);
        for (std::size_t t = 0; t < steps; ++t)
            kernels::mask_products(grid_bits_.data(), grid_words_, vg_.data() + t * grid_stride_, ng, s_.size(),
                                   grid_lanes_.data(), grid_drive_.data() + t * drive_stride);
    }
    block_rates_.resize(steps * static_cast<std::size_t>(p_.n_place));
    learned_.clear();
    is_learned_.assign(p_.n_place, 0);
    for (std::size_t t = 0; t < steps; ++t) {
        float* drive = drive_.data() + t * drive_stride;
        const float* vb = vb_.data() + t * stride_;
        // The products of rows changed since the block began, with their weights as they are now.
        for (int i : learned_) drive[i] = kernels::paired_row_product(row(i), vb, stride_);
        const float* grid_drive = n_grid_ > 0 ? grid_drive_.data() + t * drive_stride : nullptr;
        advance(drive, grid_drive, vb, n_grid_ > 0 ? vg_.data() + t * grid_stride_ : nullptr, learn[t] != 0, &learned_);
        std::copy(v_.begin(), v_.end(), block_rates_.begin() + static_cast<std::ptrdiff_t>(t * p_.n_place));
    }
    return block_rates_;
}

std::vector<float> PlaceCellNetwork::weights() const {
    std::vector<float> out(static_cast<std::size_t>(p_.n_place) * n_bvc_);
    for (int i = 0; i < p_.n_place; ++i)
        for (int j = 0; j < n_bvc_; ++j)
            out[static_cast<std::size_t>(i) * n_bvc_ + j] = row(i)[kernels::paired_column(j)];
    return out;
}

std::vector<float> PlaceCellNetwork::grid_mask() const {
    std::vector<float> out(static_cast<std::size_t>(p_.n_place) * n_grid_);
    for (int i = 0; i < p_.n_place; ++i)
        for (int j = 0; j < n_grid_; ++j)
            out[static_cast<std::size_t>(i) * n_grid_ + j] =
                grid_bits_[static_cast<std::size_t>(j) * grid_words_ + i / 16] >> (i % 16) & 1u ? 1.0f : 0.0f;
    return out;
}

void PlaceCellNetwork::set_weights(std::span<const float> w) {
    if (w.size() != static_cast<std::size_t>(p_.n_place) * n_bvc_)
        throw InputError("place cells: weights must be " + std::to_string(p_.n_place) + " x " + std::to_string(n_bvc_));
    for (float x : w)
        if (!std::isfinite(x)) throw InputError("place cells: weights must be finite");
    for (int i = 0; i < p_.n_place; ++i)
        for (int j = 0; j < n_bvc_; ++j)
            row(i)[kernels::paired_column(j)] = flush_tiny(w[static_cast<std::size_t>(i) * n_bvc_ + j]);
}

void PlaceCellNetwork::reset() {
    std::fill(s_.begin(), s_.end(), 0.0f);
    std::fill(v_.begin(), v_.end(), 0.0f);
    active_.clear();
}

void PlaceCellNetwork::set_state(std::span<const float> membrane, std::span<const float> rates) {
    if (membrane.size() != s_.size() || rates.size() != v_.size())
        throw InputError("place cells: state has the wrong size");
    std::copy(membrane.begin(), membrane.end(), s_.begin());
    std::copy(rates.begin(), rates.end(), v_.begin());
    active_.clear();  // any cell may be active: every rate other than ±0
    for (std::size_t i = 0; i < v_.size(); ++i)
        if (v_[i] != 0.0f) active_.push_back(static_cast<int>(i));
}

void PlaceCellNetwork::set_cell(int i, std::span<const float> w, float membrane) {
    if (i < 0 || i >= p_.n_place) throw InputError("place cells: no cell " + std::to_string(i));
    if (w.size() != static_cast<std::size_t>(n_bvc_))
        throw InputError("place cells: a row of weights must have " + std::to_string(n_bvc_) + " values");
    for (float x : w)
        if (!std::isfinite(x)) throw InputError("place cells: weights must be finite");
    if (!std::isfinite(membrane)) throw InputError("place cells: the membrane potential must be finite");
    for (int j = 0; j < n_bvc_; ++j) row(i)[kernels::paired_column(j)] = flush_tiny(w[j]);
    s_[i] = membrane;
}

}  // namespace bvc3d
