#include "bvc3d/bvc/boundary_vector_layer.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "bvc3d/bvc/bvc_kernels.hpp"
#include "bvc3d/core/angles.hpp"
#include "bvc3d/core/error.hpp"
#include "bvc3d/core/format.hpp"

namespace bvc3d {

namespace {

// A factor exp(-x²/2σ²) below tiny_* (relative to its peak) is treated as zero. raw_pruned bounds
// what that drops with the step's own weight sums and checks that it cannot reach 1e-7 of the
// step's largest sum (the model asks for 1e-6 of the largest rate, docs/model-reference.md#exactness);
// otherwise the full sum is used.
// Elevation has two tiers: a (return, layer) below tiny_row is not summed but its exact weight
// enters the bound; below tiny_phi it is not even evaluated and a worst case enters the bound.
constexpr double tiny_r = 1e-9;
constexpr double tiny_theta = 1e-10;
constexpr double tiny_row = 1e-8;
constexpr double tiny_phi = 1e-13;
constexpr double pruned_tolerance = 1e-7;

double window(double sigma, double tiny) { return sigma * std::sqrt(2.0 * std::log(1.0 / tiny)); }
double gauss_norm(double sigma) { return 1.0 / std::sqrt(two_pi * sigma * sigma); }

}  // namespace

const params::Table<BvcParams>& BvcParams::table() {
    using namespace params;
    static const Table<BvcParams> t(
        "BVC layer",
        {reals("elevations", &BvcParams::elevations, closed(-pi / 2, pi / 2),
               "rad, the layers' preferred elevations; [] is the 2-D model")
             .in_radians()
             .sizes(0, 1024),
         integer("n_dir", &BvcParams::n_dir, closed(1, 4096), "preferred azimuths, 2π/n_dir apart"),
         integer("n_per_axis", &BvcParams::n_per_axis, closed(1, 100000), "preferred distances per direction"),
         real("max_dist", &BvcParams::max_dist, above(0), "m, the largest preferred distance"),
         real("sigma_r", &BvcParams::sigma_r, above(0), "m, distance tuning width"),
         real("sigma_theta", &BvcParams::sigma_theta, above(0), "rad, azimuth tuning width"),
         real("sigma_phi", &BvcParams::sigma_phi, above(0), "rad, elevation tuning width"),
         choice("normalization", &BvcParams::normalization,
                {{BvcNormalization::per_step_max, "per_step_max"},
                 {BvcNormalization::none, "none"},
                 {BvcNormalization::fixed, "fixed"}},
                "per_step_max: raw / (2·max raw); none; fixed: raw / norm_constant"),
         real("norm_constant", &BvcParams::norm_constant, above(0), "the divisor of `fixed` normalization"),
         choice("reading", &BvcParams::reading,
                {{BvcReading::gaussian, "gaussian"}, {BvcReading::nearest_beam, "nearest_beam"}},
                "gaussian (the paper's equations) or nearest_beam (one return per direction, 2-D only)")});
    return t;
}

void BvcParams::validate() const {
    table().check(*this);
    const double cells = static_cast<double>(n_layers()) * n_dir * n_per_axis;
    if (cells > max_cells)
        table().fail("n_per_axis", "makes " + std::to_string(n_layers()) + " layers × " + std::to_string(n_dir) +
                                       " directions × " + std::to_string(n_per_axis) + " distances = " +
                                       format_number(cells) + " cells; the limit is " + format_number(max_cells));
    if (reading == BvcReading::nearest_beam && !elevations.empty())
        table().fail("reading", "cannot be nearest_beam with elevation layers (the nearest_beam reading is a 2-D model)");
}

BoundaryVectorLayer::BoundaryVectorLayer(BvcParams params) : p_(std::move(params)) {
    p_.validate();
    c_r_ = gauss_norm(p_.sigma_r);
    c_theta_ = gauss_norm(p_.sigma_theta);
    c_phi_ = gauss_norm(p_.sigma_phi);
    cut_r_ = window(p_.sigma_r, tiny_r);
    cut_theta_ = window(p_.sigma_theta, tiny_theta);
    cut_phi_ = window(p_.sigma_phi, tiny_phi);
    cut_row_ = window(p_.sigma_phi, tiny_row);
    const double d = p_.spacing();
    // Padded with zeros to a multiple of 8 for the vector kernel.
    const int padded = (p_.n_per_axis + 7) / 8 * 8;
    dist_decay_.assign(padded, 0.0);
    for (int n = 0; n < p_.n_per_axis; ++n) dist_decay_[n] = std::exp(-0.5 * (n * d) * (n * d) / (p_.sigma_r * p_.sigma_r));
    elev_.assign(p_.n_layers(), 0.0);
    dropped_e_.assign(p_.n_layers(), 0.0);
    row_factor_.assign(p_.n_layers(), 0.0);
    kept_layers_.assign(p_.n_layers(), 0);
    any_layers_.assign(p_.n_layers(), 0);
    // A batch: 256 returns, or as many rows as fill 1024 entries (plus one return's worth).
    jobs_.resize(256);
    job_offset_.resize(1024 + static_cast<std::size_t>(p_.n_layers()) * p_.n_dir);
    job_weight_.resize(job_offset_.size());
    kept_weight_.assign(static_cast<std::size_t>(p_.n_layers()) * p_.n_dir, 0.0);
    layer_weight_.assign(p_.n_layers(), 0.0);
    far_weight_.assign(p_.n_layers(), 0.0);
    dropped_weight_.assign(static_cast<std::size_t>(p_.n_layers()) * p_.n_dir, 0.0);
    axis_stride_ = padded + 8;
    padded_.assign(static_cast<std::size_t>(p_.n_layers()) * p_.n_dir * axis_stride_, 0.0);
    memo_weight_.assign(cache_slots * (p_.n_dir + 1), 0.0);
    memo_dir_.assign(cache_slots * (p_.n_dir + 1), 0);
    for (std::size_t slot = 0; slot < cache_slots; ++slot) memo_weight_[slot * (p_.n_dir + 1)] = NAN;  // the keys
    direct_dir_.assign(p_.n_dir, 0);
    direct_weight_.assign(p_.n_dir, 0.0);
}

void BoundaryVectorLayer::check_return(const LidarReturn& r, std::size_t index) {
    auto bad = [&](const std::string& what) {
        throw InputError("LiDAR return " + std::to_string(index) + ": " + what);
    };
    if (r.range < 0) bad("negative range " + std::to_string(r.range));
    if (!std::isfinite(r.azimuth)) bad("azimuth is not finite");
    if (!std::isfinite(r.elevation)) bad("elevation is not finite");
}

namespace {
// NaN or +inf range: the conventional "no return" marker; the return is skipped.
bool is_no_return(const LidarReturn& r) { return std::isnan(r.range) || r.range == INFINITY; }
}  // namespace

void BoundaryVectorLayer::row_factors(double phi) const {
    const double h_p = 0.5 / (p_.sigma_phi * p_.sigma_phi);
    for (int l = 0; l < p_.n_layers(); ++l) {
        elev_[l] = dropped_e_[l] = 0.0;
        if (p_.elevations.empty()) {
            elev_[l] = 1.0;
        } else {
            const double x = phi - p_.elevations[l];
            if (std::abs(x) <= cut_row_) elev_[l] = c_phi_ * std::exp(-x * x * h_p);
            else if (std::abs(x) <= cut_phi_) dropped_e_[l] = c_phi_ * std::exp(-x * x * h_p);
        }
        row_factor_[l] = elev_[l] + dropped_e_[l];
    }
}

bool BoundaryVectorLayer::raw_pruned(std::span<const LidarReturn> returns, const ScanPlan* plan,
                                     std::span<double> result, Pass pass, const BoundaryVectorLayer* summed) const {
    // One instance per pass, so that each pass's loop carries none of the others' work.
    switch (pass) {
        case Pass::own: return pruned_pass<Pass::own>(returns, plan, result, summed);
        case Pass::sums: return pruned_pass<Pass::sums>(returns, plan, result, summed);
        case Pass::bound: break;
    }
    return pruned_pass<Pass::bound>(returns, plan, result, summed);
}

template <BoundaryVectorLayer::Pass pass>
bool BoundaryVectorLayer::pruned_pass(std::span<const LidarReturn> returns, const ScanPlan* plan,
                                      std::span<double> result, const BoundaryVectorLayer* summed) const {
    // Sums go to a buffer whose axes are padded by one 8-lane block, so the vector kernel never
    // needs a scalar tail; they are copied to `result` at the end.
    const int L = p_.n_layers(), K = p_.n_dir, M = p_.n_per_axis, stride = axis_stride_;
    constexpr bool sums = pass != Pass::bound, own_bound = pass != Pass::sums;
    if constexpr (sums) std::fill(padded_.begin(), padded_.end(), 0.0);
    double* out_data = padded_.data();
    const double dd = p_.spacing(), inv_dd = dd > 0 ? 1.0 / dd : 0.0;
    const double h_r = 0.5 / (p_.sigma_r * p_.sigma_r);
    // Far-apart cells (spacing > sigma_r) are few per window: evaluate them directly, which also
    // keeps the power recurrence below far from overflow.
    const bool recurrence = dd > 0 && dd <= p_.sigma_r;
    // Elevation factors of the current row: summed (elev_) and in [tiny_phi, tiny_row) (dropped_e_);
    // the layers with a summed factor (kept_l, n_kept of them) and with any factor (any_l, n_any).
    const double* elev = elev_.data();
    const double* dropped_e = dropped_e_.data();
    int* kept_l = kept_layers_.data();
    int* any_l = any_layers_.data();
    int n_kept = 0, n_any = 0;
    // For the truncation bound: per (layer, direction) the kept weights Σ E·A and the dropped ones,
    // per layer Σ E over returns that reach it and Σ E over those whose distance window is empty.
    clear_bound_sums();
    double* kept_weight = kept_weight_.data();
    double* layer_weight = layer_weight_.data();
    // The `sums` pass keeps, per row, what the bound of any layer reading these sums needs instead.
    constexpr bool keep_rows = pass == Pass::sums;
    row_totals_.clear();
    row_angles_.clear();
    rows_complete_ = keep_rows;
    RowTotal* row_total = nullptr;
    double* near_angles = nullptr;  // this row's Σ A of returns with a distance window, per direction
    double* all_angles = nullptr;   // ... and of every return
    constexpr std::size_t max_row_totals = 1024;
    // The recurrence path lists the returns' profiles (jobs) and the rows each feeds (offsets into
    // the sums, weights), and adds a few hundred at a time in one kernel call, in return order.
    kernels::ProfileJob* jobs = jobs_.data();
    std::uint32_t* job_offset = job_offset_.data();
    double* job_weight = job_weight_.data();
    std::size_t n_jobs = 0, n_rows = 0;
    const std::size_t rows_room = job_offset_.size() - static_cast<std::size_t>(K) * L;
    auto flush = [&] {
        kernels::add_distance_profiles(jobs, n_jobs, job_offset, job_weight, dist_decay_.data(), out_data);
        n_jobs = n_rows = 0;
    };
    std::size_t valid = 0;
    // A beam table comes row by row; returns whose elevation changes nearly every time are an
    // irregular point set, whose azimuths never repeat: the memo is left alone for them.
    std::size_t changes = 0;
    const std::size_t probe = std::min<std::size_t>(returns.size(), 64);
    for (std::size_t j = 1; j < probe; ++j) changes += !(returns[j].elevation == returns[j - 1].elevation);
    const bool use_memo = probe < 64 || changes < 56;
    double last_phi = NAN;
    bool skipped_row = false;

    for (std::size_t j = 0; j < returns.size(); ++j) {
        const LidarReturn& ret = returns[j];
        if (is_no_return(ret)) continue;
        if (!(ret.range >= 0) || !std::isfinite(ret.azimuth) || !std::isfinite(ret.elevation)) check_return(ret, j);
        // Elevation factors, cached across the returns of one scanner row.
        if (!(ret.elevation == last_phi)) {
            last_phi = ret.elevation;
            skipped_row = plan && plan->skips(ret.elevation);
            row_factors(ret.elevation);
            n_kept = n_any = 0;
            for (int l = 0; l < L; ++l) {
                if (elev[l] > 0.0) kept_l[n_kept++] = l;
                if (row_factor_[l] > 0.0) any_l[n_any++] = l;  // adding 0 to layer_weight changes nothing
            }
            row_total = nullptr;
            if (keep_rows && rows_complete_ && !skipped_row) {
                if (row_totals_.size() == max_row_totals) {
                    rows_complete_ = false;  // not a beam table: readers do their own bookkeeping
                } else {
                    row_total = &row_totals_.emplace_back(RowTotal{ret.elevation, 0, 0});
                    row_angles_.resize(row_angles_.size() + 2 * static_cast<std::size_t>(K), 0.0);
                    near_angles = row_angles_.data() + row_angles_.size() - 2 * static_cast<std::size_t>(K);
                    all_angles = near_angles + K;
                }
            }
        }
        if (skipped_row) continue;  // the plan's bound covers the rows it did not cast
        ++valid;
        if (keep_rows && row_total) ++row_total->valid;
        if (n_any == 0) continue;
        const double azimuth = wrap_pi(ret.azimuth);  // any azimuth, however many turns
        const int* dir = direct_dir_.data();
        const double* ang = direct_weight_.data();
        int n_dirs;
        if (use_memo) {
            const std::size_t at = slot_of(azimuth) * (K + 1);
            double* const key = memo_weight_.data() + at;
            int* const count = memo_dir_.data() + at;
            if (!(*key == azimuth)) {
                *count = angular_weights(azimuth, count + 1, key + 1);
                *key = azimuth;
            }
            dir = count + 1;
            ang = key + 1;
            n_dirs = *count;
        } else {
            n_dirs = angular_weights(azimuth, direct_dir_.data(), direct_weight_.data());
        }
        if constexpr (own_bound) {
            for (int i = 0; i < n_any; ++i) layer_weight[any_l[i]] += row_factor_[any_l[i]];
            if (n_any > n_kept)
                for (int l = 0; l < L; ++l)
                    if (dropped_e[l] > 0.0)
                        for (int d = 0; d < n_dirs; ++d)
                            dropped_weight_[static_cast<std::size_t>(l) * K + dir[d]] += dropped_e[l] * ang[d];
        }
        if (keep_rows && row_total)
            for (int d = 0; d < n_dirs; ++d) all_angles[dir[d]] += ang[d];
        if (n_kept == 0) continue;

        // Distance window: a superset of |r - d_m| <= cut (an extra cell only adds a true term), so
        // truncation toward zero serves for floor and ceil (r >= 0; no libm call on baseline x86-64).
        const double r = ret.range;
        int m_lo = 0, m_hi = 0;
        if (dd > 0) {
            const double lo = (r - cut_r_) * inv_dd, hi = (r + cut_r_) * inv_dd;
            m_lo = lo > 0 ? static_cast<int>(std::min(lo, 1e9)) : 0;
            m_hi = static_cast<int>(std::min(hi, static_cast<double>(M - 2))) + 1;
        } else if (r > cut_r_) {
            m_lo = 1;  // no cell in reach
        }
        if (m_lo > m_hi) {
            if constexpr (own_bound)
                for (int i = 0; i < n_kept; ++i) far_weight_[kept_l[i]] += elev[kept_l[i]];
            if (keep_rows && row_total) ++row_total->far;
            continue;
        }
        const int W = m_hi - m_lo + 1;
        if (keep_rows && row_total)
            for (int d = 0; d < n_dirs; ++d) near_angles[dir[d]] += ang[d];

        // The (layer, direction) rows this return feeds, with their elevation × angular weights.
        const std::size_t first = n_rows;
        for (int d = 0; d < n_dirs; ++d)
            for (int i = 0; i < n_kept; ++i) {
                const int l = kept_l[i];
                const double w = elev[l] * ang[d];
                const std::size_t lk = static_cast<std::size_t>(l) * K + dir[d];
                if constexpr (own_bound) kept_weight[lk] += w;
                job_weight[n_rows] = w;
                job_offset[n_rows] = static_cast<std::uint32_t>(lk * stride + m_lo);
                ++n_rows;
            }
        const int count = static_cast<int>(n_rows - first);
        if (count == 0) continue;
        if constexpr (!sums) {  // the sums are read from `summed`
            n_rows = 0;
            continue;
        }

        // Distance profile c_r·exp(-(r - d_m)²/2σ²) over the window, added to every row.
        if (recurrence) {
            // exp(-h(x0 - nΔ)²) = exp(-h x0²) · exp(2h x0 Δ)^n · exp(-h n²Δ²): two exps per return.
            const double x0 = r - m_lo * dd;
            jobs[n_jobs++] = {c_r_ * std::exp(-h_r * x0 * x0), std::exp(2.0 * h_r * x0 * dd), W, count};
            if (n_jobs == jobs_.size() || n_rows > rows_room) flush();
        } else {
            for (int n = 0; n < W; ++n) {
                const double x = r - (m_lo + n) * dd;
                const double u = c_r_ * std::exp(-h_r * x * x);
                for (int i = 0; i < count; ++i) out_data[job_offset[first + i] + n] += job_weight[first + i] * u;
            }
            n_rows = 0;
        }
    }
    if (n_jobs > 0) flush();
    if constexpr (pass == Pass::sums) return true;
    copy_sums(pass == Pass::bound ? *summed : *this, result);
    const double max_raw = result.empty() ? 0.0 : *std::max_element(result.begin(), result.end());
    return pruned_bound(plan, valid) <= pruned_tolerance * max_raw;
}

void BoundaryVectorLayer::copy_sums(const BoundaryVectorLayer& from_layer, std::span<double> result) const {
    const int K = p_.n_dir, M = p_.n_per_axis;
    const std::size_t stride = static_cast<std::size_t>(axis_stride_);
    for (int l = 0; l < p_.n_layers(); ++l) {
        const std::size_t axis = &from_layer == this ? static_cast<std::size_t>(l) * K : from_layer.first_axis(p_, l);
        const double* from = from_layer.padded_.data() + axis * stride;
        for (int k = 0; k < K; ++k)
            std::copy(from + static_cast<std::size_t>(k) * stride, from + static_cast<std::size_t>(k) * stride + M,
                      result.begin() + (static_cast<std::ptrdiff_t>(l) * K + k) * M);
    }
}

void BoundaryVectorLayer::clear_bound_sums() const {
    std::fill(kept_weight_.begin(), kept_weight_.end(), 0.0);
    std::fill(dropped_weight_.begin(), dropped_weight_.end(), 0.0);
    std::fill(layer_weight_.begin(), layer_weight_.end(), 0.0);
    std::fill(far_weight_.begin(), far_weight_.end(), 0.0);
}

double BoundaryVectorLayer::pruned_bound(const ScanPlan* plan, std::size_t valid) const {
    // Every pruned term of cell (l, k, m) is one of: a distance factor below tiny_r of a kept
    // (return, layer, direction); an angular factor below tiny_theta of a (return, layer) whose
    // elevation factor was evaluated; a (return, layer, direction) whose elevation factor is below
    // tiny_row (its weight E·A is known exactly, D <= c_r); an elevation factor below tiny_phi
    // (worst case, for every beam cast or not); the distance factor of a return whose whole window
    // was empty; a row the plan did not cast (bounded by the plan).
    const int L = p_.n_layers(), K = p_.n_dir;
    double bound = 0;
    for (int l = 0; l < L; ++l)
        for (int k = 0; k < K; ++k) {
            const std::size_t lk = static_cast<std::size_t>(l) * K + k;
            bound = std::max(bound, kept_weight_[lk] * c_r_ * tiny_r + dropped_weight_[lk] * c_r_ +
                                        layer_weight_[l] * c_theta_ * c_r_ * tiny_theta +
                                        far_weight_[l] * c_theta_ * c_r_ * tiny_r +
                                        (plan ? plan->skipped_bound[l] : 0.0));
        }
    const std::size_t n_beams = std::max(valid, plan ? plan->beams : std::size_t{0});
    if (!p_.elevations.empty()) bound += static_cast<double>(n_beams) * c_phi_ * c_theta_ * c_r_ * tiny_phi;
    return bound;
}

bool BoundaryVectorLayer::bound_sums_from_rows(const ScanPlan& plan, const BoundaryVectorLayer& summed,
                                               std::size_t& valid) const {
    if (!summed.rows_complete_) return false;
    valid = 0;
    const int L = p_.n_layers(), K = p_.n_dir;
    clear_bound_sums();
    for (std::size_t r = 0; r < summed.row_totals_.size(); ++r) {
        const RowTotal& t = summed.row_totals_[r];
        if (plan.skips(t.elevation)) continue;
        const double* near_angles = summed.row_angles_.data() + 2 * r * static_cast<std::size_t>(K);
        const double* all_angles = near_angles + K;
        row_factors(t.elevation);
        valid += t.valid;
        for (int l = 0; l < L; ++l) {
            layer_weight_[l] += row_factor_[l] * static_cast<double>(t.valid);
            far_weight_[l] += elev_[l] * static_cast<double>(t.far);
            for (int k = 0; k < K; ++k) {
                kept_weight_[static_cast<std::size_t>(l) * K + k] += elev_[l] * near_angles[k];
                dropped_weight_[static_cast<std::size_t>(l) * K + k] += dropped_e_[l] * all_angles[k];
            }
        }
    }
    return true;
}

bool BoundaryVectorLayer::can_share_sums(const BvcParams& o) const {
    // Everything but the elevations, which only select layers (and planar models share only with planar ones).
    return p_.reading == BvcReading::gaussian && o.reading == BvcReading::gaussian &&
           p_.elevations.empty() == o.elevations.empty() && p_.n_dir == o.n_dir && p_.n_per_axis == o.n_per_axis &&
           p_.max_dist == o.max_dist && p_.sigma_r == o.sigma_r && p_.sigma_theta == o.sigma_theta &&
           p_.sigma_phi == o.sigma_phi;
}

std::size_t BoundaryVectorLayer::first_axis(const BvcParams& reader, int l) const {
    if (reader.elevations.empty()) return 0;
    const auto at = std::find(p_.elevations.begin(), p_.elevations.end(), reader.elevations[static_cast<std::size_t>(l)]);
    if (at == p_.elevations.end()) throw InputError("BVC layer: shared sums lack the elevation of layer " + std::to_string(l));
    return static_cast<std::size_t>(at - p_.elevations.begin()) * static_cast<std::size_t>(p_.n_dir);
}

void BoundaryVectorLayer::sum_pruned(std::span<const LidarReturn> returns, const ScanPlan& plan) const {
    raw_pruned(returns, &plan, {}, Pass::sums);  // the bound is each reader's own
}

bool BoundaryVectorLayer::rates_pruned_shared(std::span<const LidarReturn> returns, const ScanPlan& plan,
                                              const BoundaryVectorLayer& summed, std::span<double> out) const {
    if (out.size() != n_cells()) throw InputError("BVC layer: output has the wrong size");
    if (!can_share_sums(summed.p_)) throw InputError("BVC layer: cannot read the sums of a layer with other parameters");
    // The bound's sums from the summing layer's row totals: the same terms as this layer's own pass
    // adds return by return, in another order. Sums of n positive terms in two orders differ by at
    // most 2n·2^-53 of their value, so the verdict is the own pass's whenever the bound is further
    // than 1e-9 from the threshold (n < 10^6 here: a beam table); closer, the own pass decides.
    bool ok;
    copy_sums(summed, out);
    std::size_t valid = 0;
    const double max_raw = out.empty() ? 0.0 : *std::max_element(out.begin(), out.end());
    const double threshold = pruned_tolerance * max_raw;
    const double bound = bound_sums_from_rows(plan, summed, valid) && valid < 1000000 ? pruned_bound(&plan, valid) : NAN;
    if (bound < threshold * (1 - 1e-9)) ok = true;
    else if (bound > threshold * (1 + 1e-9)) ok = false;
    else ok = raw_pruned(returns, &plan, out, Pass::bound, &summed);
    if (!ok) return false;
    normalize(out);
    return true;
}

int BoundaryVectorLayer::angular_weights(double azimuth, int* dir, double* weight) const {
    const int K = p_.n_dir;
    const double dtheta = two_pi / K, h_t = 0.5 / (p_.sigma_theta * p_.sigma_theta);
    const bool all_dirs = 2.0 * cut_theta_ >= two_pi;
    // ceil and floor of quotients within a few turns, from truncation (no libm call on baseline x86-64).
    auto ceil_int = [](double t) {
        const int i = static_cast<int>(t);
        return i + (static_cast<double>(i) < t);
    };
    auto floor_int = [](double t) {
        const int i = static_cast<int>(t);
        return i - (static_cast<double>(i) > t);
    };
    const int k_first = all_dirs ? 0 : ceil_int((azimuth - cut_theta_) / dtheta);
    const int k_last = all_dirs ? K - 1 : floor_int((azimuth + cut_theta_) / dtheta);
    int count = 0;
    for (int ki = k_first; ki <= k_last; ++ki) {
        const double x = all_dirs ? wrap_pi(azimuth - ki * dtheta) : azimuth - ki * dtheta;
        if (std::abs(x) > cut_theta_) continue;
        dir[count] = ki < 0 ? ki + K : ki >= K ? ki - K : ki;  // |ki| < K: the window is under a turn
        weight[count] = c_theta_ * std::exp(-x * x * h_t);
        ++count;
    }
    return count;
}

void BoundaryVectorLayer::raw_exact(std::span<const LidarReturn> returns, std::span<double> out) const {
    if (out.size() != n_cells()) throw InputError("BVC layer: output has the wrong size");
    std::fill(out.begin(), out.end(), 0.0);
    if (p_.reading == BvcReading::nearest_beam) {
        raw_nearest_beam(returns, out, false);
        return;
    }
    const int L = p_.n_layers(), K = p_.n_dir, M = p_.n_per_axis;
    std::vector<double> E(L), A(K), D(M);
    for (std::size_t j = 0; j < returns.size(); ++j) {
        const auto& ret = returns[j];
        if (is_no_return(ret)) continue;
        check_return(ret, j);
        for (int l = 0; l < L; ++l) {
            const double x = p_.elevations.empty() ? 0.0 : ret.elevation - p_.elevations[l];
            E[l] = p_.elevations.empty() ? 1.0 : c_phi_ * std::exp(-0.5 * x * x / (p_.sigma_phi * p_.sigma_phi));
        }
        for (int k = 0; k < K; ++k) {
            const double x = wrap_pi(ret.azimuth - k * two_pi / K);
            A[k] = c_theta_ * std::exp(-0.5 * x * x / (p_.sigma_theta * p_.sigma_theta));
        }
        for (int m = 0; m < M; ++m) {
            const double x = ret.range - m * p_.spacing();
            D[m] = c_r_ * std::exp(-0.5 * x * x / (p_.sigma_r * p_.sigma_r));
        }
        for (int l = 0; l < L; ++l)
            for (int k = 0; k < K; ++k)
                for (int m = 0; m < M; ++m) out[(static_cast<std::size_t>(l) * K + k) * M + m] += E[l] * A[k] * D[m];
    }
}

bool BoundaryVectorLayer::raw_nearest_beam(std::span<const LidarReturn> returns, std::span<double> out,
                                           bool prune) const {
    // For each direction, the first return with the smallest |wrap(azimuth - θ_k)|.
    const int K = p_.n_dir, M = p_.n_per_axis;
    best_return_.assign(K, returns.size());
    best_gap_.assign(K, INFINITY);
    for (std::size_t j = 0; j < returns.size(); ++j) {
        if (is_no_return(returns[j])) continue;
        check_return(returns[j], j);
        const double az = wrap_pi(returns[j].azimuth);
        for (int k = 0; k < K; ++k) {
            double gap = az - k * two_pi / K;  // in (-3π, π]: one correction wraps it
            if (gap <= -pi) gap += two_pi;
            gap = std::abs(gap);
            if (gap < best_gap_[k]) {
                best_gap_[k] = gap;
                best_return_[k] = j;
            }
        }
    }
    // Pruned, a direction's profile is evaluated over its distance window only (as raw_pruned does):
    // a cell outside it would get less than tiny_r·c_r. Those Gaussian tails (down to 1e-56 of the
    // peak) were the subnormal float rates, and the weights Oja's rule grew from them, that made
    // the place cells take a microcode assist per product on many CPUs.
    const double dd = p_.spacing(), inv_dd = dd > 0 ? 1.0 / dd : 0.0;
    prune = prune && dd > 0;
    double max_raw = 0;
    for (int k = 0; k < K; ++k) {
        if (best_return_[k] == returns.size()) continue;
        const double r = returns[best_return_[k]].range;
        int m_lo = 0, m_hi = M - 1;
        if (prune) {  // a superset of |r - d_m| <= cut, as in raw_pruned
            const double lo = (r - cut_r_) * inv_dd, hi = (r + cut_r_) * inv_dd;
            m_lo = lo > 0 ? static_cast<int>(std::min(lo, 1e9)) : 0;
            m_hi = std::min(static_cast<int>(std::min(hi, static_cast<double>(M - 2))) + 1, M - 1);
        }
        for (int m = m_lo; m <= m_hi; ++m) {
            const double x = r - m * p_.spacing();
            const double v = c_r_ * std::exp(-0.5 * x * x / (p_.sigma_r * p_.sigma_r));
            out[static_cast<std::size_t>(k) * M + m] = v;
            max_raw = std::max(max_raw, v);
        }
    }
    return !prune || c_r_ * tiny_r <= pruned_tolerance * max_raw;
}

void BoundaryVectorLayer::raw(std::span<const LidarReturn> returns, std::span<double> out) const {
    if (out.size() != n_cells()) throw InputError("BVC layer: output has the wrong size");
    if (p_.reading == BvcReading::nearest_beam) {
        std::fill(out.begin(), out.end(), 0.0);
        if (!raw_nearest_beam(returns, out, true)) raw_nearest_beam(returns, out, false);
    } else if (!raw_pruned(returns, nullptr, out)) {
        raw_exact(returns, out);
    }
}

void BoundaryVectorLayer::normalize(std::span<double> out) const {
    if (p_.normalization == BvcNormalization::per_step_max) {
        const double mx = out.empty() ? 0.0 : *std::max_element(out.begin(), out.end());
        if (mx > 0) {
            const double denom = 2.0 * mx;
            for (double& v : out) v = v / denom;  // exact 0.5 at the maximum
        } else {
            std::fill(out.begin(), out.end(), 0.0);
        }
    } else if (p_.normalization == BvcNormalization::fixed) {
        for (double& v : out) v = v / p_.norm_constant;
    }
}

void BoundaryVectorLayer::rates(std::span<const LidarReturn> returns, std::span<double> out) const {
    raw(returns, out);
    normalize(out);
}

bool BoundaryVectorLayer::rates_pruned(std::span<const LidarReturn> returns, const ScanPlan& plan,
                                       std::span<double> out) const {
    if (out.size() != n_cells()) throw InputError("BVC layer: output has the wrong size");
    if (p_.reading == BvcReading::nearest_beam) {
        rates(returns, out);
        return true;
    }
    if (!raw_pruned(returns, &plan, out)) return false;
    normalize(out);
    return true;
}

BoundaryVectorLayer::ScanPlan BoundaryVectorLayer::plan(const LidarSpec& sensor) const {
    ScanPlan plan;
    const int L = p_.n_layers();
    const std::vector<double>& rows = sensor.row_labels();  // the elevations the returns carry
    plan.rows.assign(rows.size(), 1);
    plan.skipped_bound.assign(L, 0.0);
    plan.beams = sensor.beam_count();
    if (p_.elevations.empty() || p_.reading == BvcReading::nearest_beam) return plan;  // reads every row
    // A row's beams are evenly spaced in azimuth (δ apart), so for any heading and direction
    // Σ_columns exp(-x²/2σ_θ²) <= 1 + √(2π)·σ_θ/δ (a unimodal function summed over a lattice).
    // linspace labels are δ' = 2π/(n−1) > δ apart with one azimuth twice (0 and 2π): one term more.
    const double delta = two_pi / sensor.azimuth_count;
    const double repeated = sensor.azimuth_labels == AzimuthLabels::linspace ? 1.0 : 0.0;
    const double angular_sum = c_theta_ * (1.0 + std::sqrt(two_pi) * p_.sigma_theta / delta + repeated);
    const double h_p = 0.5 / (p_.sigma_phi * p_.sigma_phi);
    for (std::size_t i = 0; i < rows.size(); ++i) {
        bool needed = false;
        for (double psi : p_.elevations) needed = needed || std::abs(rows[i] - psi) <= cut_row_;
        if (needed) continue;
        plan.rows[i] = 0;
        plan.skipped_rows.push_back(rows[i]);
        for (int l = 0; l < L; ++l) {
            const double x = rows[i] - p_.elevations[l];
            plan.skipped_bound[l] += c_phi_ * std::exp(-x * x * h_p) * angular_sum * c_r_;
        }
    }
    return plan;
}

}  // namespace bvc3d
