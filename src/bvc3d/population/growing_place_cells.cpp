#include "bvc3d/population/growing_place_cells.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "bvc3d/core/error.hpp"

namespace bvc3d {

namespace {
constexpr int first_capacity = 64;                  // rows held at the start (at least n_initial)
constexpr double max_weights = 2.0 * (1ull << 30);  // floats (8 GiB): a budget × n_bvc beyond is refused
}  // namespace

const params::Table<GrowingParams>& GrowingParams::table() {
    using namespace params;
    using P = GrowingParams;
    static const Table<P> t(
        "growing place cells",
        {integer("budget", &P::budget, closed(1, 1000000), "most place cells the network recruits"),
         integer("n_initial", &P::n_initial, closed(0, 1000000), "cells at the start, the paper's random ones"),
         real("threshold", &P::threshold, closed(0, 1), "recruit where the largest rate is below this (0: never)"),
         integer("sample_every", &P::sample_every, closed(1, 1000000000), "learning steps between sampled places")});
    return t;
}

void GrowingParams::validate() const {
    table().check(*this);
    if (n_initial > budget)
        table().fail("n_initial",
                     "must be <= budget (" + std::to_string(budget) + "), got " + std::to_string(n_initial));
}

void GrowingPlaceCells::check(const PlaceParams& place, const GrowingParams& growing) {
    growing.validate();
    place.validate();
    // A cell not recruited must stay silent: its membrane is driven by −inhibition only.
    if (place.gamma_pb < 0) PlaceParams::table().fail("gamma_pb", "must be >= 0 in a growing network");
    if (place.gamma_pp < 0) PlaceParams::table().fail("gamma_pp", "must be >= 0 in a growing network");
}

GrowingPlaceCells::GrowingPlaceCells(int n_bvc, const PlaceParams& place, const GrowingParams& growing,
                                     std::uint64_t seed)
    : n_bvc_(n_bvc), g_(growing), seed_(seed) {
    check(place, g_);
    if (n_bvc < 1) throw InputError("growing place cells: need at least one BVC input");
    if (static_cast<double>(g_.budget) * n_bvc > max_weights)
        GrowingParams::table().fail("budget", "× " + std::to_string(n_bvc) + " BVCs is more weights than 8 GiB hold");
    PlaceParams p = place;
    p.n_place = std::max(1, std::min(g_.budget, std::max(g_.n_initial, first_capacity)));
    net_ = std::make_unique<PlaceCellNetwork>(n_bvc, p, seed);
    const std::vector<float> zero(n_bvc, 0.0f);
    for (int i = g_.n_initial; i < p.n_place; ++i) net_->set_cell(i, zero, 0.0f);
    n_ = g_.n_initial;
    recruited_at_.assign(n_, 0);
    rates_.assign(g_.budget, 0.0f);
}

void GrowingPlaceCells::set_capacity(int capacity) {
    PlaceParams p = net_->params();
    if (capacity == p.n_place) return;
    const int old = p.n_place, keep = std::min(old, capacity);
    std::vector<float> w = net_->weights();
    w.resize(static_cast<std::size_t>(capacity) * n_bvc_, 0.0f);
    std::vector<float> s(net_->membrane().begin(), net_->membrane().begin() + keep),
        v(net_->rates().begin(), net_->rates().begin() + keep);
    s.resize(capacity, 0.0f);
    v.resize(capacity, 0.0f);
    p.n_place = capacity;
    auto next = std::make_unique<PlaceCellNetwork>(n_bvc_, p, seed_);
    next->set_weights(w);
    next->set_state(s, v);
    net_ = std::move(next);
}

bool GrowingPlaceCells::sampled(bool learn) const { return learn && learning_steps_ % g_.sample_every == 0; }

void GrowingPlaceCells::recruit_if_silent(std::span<const double> bvc_rates) {
    if (n_ >= g_.budget) return;
    float largest = -std::numeric_limits<float>::infinity();
    for (int i = 0; i < n_; ++i) largest = std::max(largest, rates_[i]);
    if (!(largest < static_cast<float>(g_.threshold))) return;
    double total = 0;
    for (double b : bvc_rates) total += b;
    if (!(total > 0)) return;  // nothing seen: nothing to tune a cell to
    const double scale = net_->params().p_connect * n_bvc_ / total;
    std::vector<float> w(bvc_rates.size());
    for (std::size_t j = 0; j < w.size(); ++j) w[j] = static_cast<float>(scale * bvc_rates[j]);
    if (n_ >= net_->n_place()) set_capacity(std::min(g_.budget, 2 * net_->n_place()));
    net_->set_cell(n_, w, 0.0f);
    recruited_at_.push_back(learning_steps_);
    ++n_;
}

std::span<const float> GrowingPlaceCells::step(std::span<const double> bvc_rates, bool learn) {
    const auto v = net_->step(bvc_rates, learn);
    std::copy(v.begin(), v.end(), rates_.begin());
    if (learn) ++learning_steps_;
    if (sampled(learn)) recruit_if_silent(bvc_rates);
    return rates_;
}

void GrowingPlaceCells::step(const StepBlock& block, std::span<const std::span<const double>> inputs,
                             std::span<double> out) {
    if (inputs.size() != 1) throw InputError("a growing place-cell network reads one BVC population");
    const std::size_t steps = block.size(), n = static_cast<std::size_t>(n_bvc_), budget = size();
    if (inputs[0].size() != steps * n)
        throw InputError("growing place cells: expected " + std::to_string(steps) + " × " + std::to_string(n) +
                         " BVC rates, got " + std::to_string(inputs[0].size()));
    // Runs of steps up to the next sampled one go through the network at once (the same bits as step by step).
    std::size_t from = 0;
    while (from < steps) {
        std::size_t to = from;
        std::int64_t c = learning_steps_;
        for (; to < steps; ++to) {
            if (!block.learn[to]) continue;
            if (++c % g_.sample_every == 0) break;
        }
        const std::size_t end = std::min(to + 1, steps), count = end - from;
        const auto v = net_->step_block(inputs[0].subspan(from * n, count * n), block.learn.subspan(from, count));
        const std::size_t held = static_cast<std::size_t>(net_->n_place());
        for (std::size_t t = 0; t < count; ++t) {
            double* row = out.data() + (from + t) * budget;
            std::copy(v.begin() + static_cast<std::ptrdiff_t>(t * held),
                      v.begin() + static_cast<std::ptrdiff_t>((t + 1) * held), row);
            std::fill(row + held, row + budget, 0.0);
        }
        std::copy(v.end() - static_cast<std::ptrdiff_t>(held), v.end(), rates_.begin());
        learning_steps_ = c;
        if (to < steps) recruit_if_silent(inputs[0].subspan(to * n, n));
        from = end;
    }
}

std::vector<float> GrowingPlaceCells::weights() const {
    std::vector<float> w = net_->weights();
    w.resize(static_cast<std::size_t>(n_) * n_bvc_);
    return w;
}

void GrowingPlaceCells::reset() {
    net_->reset();
    std::fill(rates_.begin(), rates_.end(), 0.0f);
}

std::vector<StateArray> GrowingPlaceCells::kept() const {
    const std::size_t budget = size(), b = static_cast<std::size_t>(n_bvc_);
    std::vector<float> w = weights();
    w.resize(budget * b, 0.0f);
    std::vector<double> at(budget, -1.0);
    for (int i = 0; i < n_; ++i) at[i] = static_cast<double>(recruited_at_[i]);
    return {{"weights", {budget, b}, std::move(w)}, {"recruited_at", {budget}, std::move(at)}};
}

std::vector<StateArray> GrowingPlaceCells::state() const {
    const std::size_t budget = size();
    auto arrays = kept();
    std::vector<float> s(net_->membrane().begin(), net_->membrane().end());
    s.resize(budget, 0.0f);
    arrays.push_back({"membrane", {budget}, std::move(s)});
    arrays.push_back({"rates", {budget}, rates_});
    arrays.push_back(
        {"counts", {2}, std::vector<double>{static_cast<double>(n_), static_cast<double>(learning_steps_)}});
    return arrays;
}

void GrowingPlaceCells::restore(const std::vector<StateArray>& state) {
    // Everything is checked before anything changes.
    const std::size_t budget = size(), b = static_cast<std::size_t>(n_bvc_);
    const auto& w = state_floats(state, "weights", budget * b);
    const auto& at = state_doubles(state, "recruited_at", budget);
    const auto& s = state_floats(state, "membrane", budget);
    const auto& v = state_floats(state, "rates", budget);
    const auto& counts = state_doubles(state, "counts", 2);
    const double cells = counts[0], learned = counts[1];
    if (!(cells >= g_.n_initial && cells <= static_cast<double>(budget) && cells == std::floor(cells)))
        throw InputError("its count of cells is not between n_initial and the budget");
    if (!(learned >= 0 && learned < 9e15 && learned == std::floor(learned)))
        throw InputError("its count of learning steps is not a whole number >= 0");
    const int n = static_cast<int>(cells);
    for (std::size_t i = 0; i < budget; ++i)
        if ((static_cast<int>(i) < n) != (at[i] >= 0) || at[i] > learned)
            throw InputError("its recruited_at does not fit its count of cells and learning steps");
    for (std::size_t i = static_cast<std::size_t>(n) * b; i < budget * b; ++i)
        if (w[i] != 0.0f) throw InputError("it has weights for cells it has not recruited");
    for (float x : w)
        if (!std::isfinite(x)) throw InputError("its weights are not finite");
    for (std::size_t i = static_cast<std::size_t>(n); i < budget; ++i)
        if (v[i] != 0.0f || s[i] > 0.0f) throw InputError("a cell it has not recruited is not silent");
    int capacity = std::max(1, std::min(g_.budget, std::max(g_.n_initial, first_capacity)));
    while (capacity < n) capacity = std::min(g_.budget, 2 * capacity);
    set_capacity(capacity);
    const auto held = static_cast<std::size_t>(capacity);
    net_->set_weights(std::span<const float>(w).first(held * b));
    net_->set_state(std::span<const float>(s).first(held), std::span<const float>(v).first(held));
    n_ = n;
    learning_steps_ = static_cast<std::int64_t>(learned);
    recruited_at_.assign(at.begin(), at.begin() + n);
    std::copy(v.begin(), v.end(), rates_.begin());
}

std::vector<std::pair<std::string, std::int64_t>> GrowingPlaceCells::counters() const {
    return {{"place cells recruited", n_ - g_.n_initial}};
}

}  // namespace bvc3d
