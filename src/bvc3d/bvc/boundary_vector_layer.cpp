#include "bvc3d/bvc/boundary_vector_layer.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "bvc3d/bvc/bvc_kernels.hpp"
#include "bvc3d/core/angles.hpp"
#include "bvc3d/core/error.hpp"
#include "bvc3d/core/format.hpp"
#include "bvc3d/core/vector_exp.hpp"

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
// A memo of at most this many slots (a beam table's columns; more, and the default is kept).
constexpr std::size_t max_slots = 1 << 16;

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
        table().fail("reading",
                     "cannot be nearest_beam with elevation layers (the nearest_beam reading is a 2-D model)");
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
    for (int n = 0; n < padded; ++n) dist_decay_[n] = std::exp(-0.5 * (n * d) * (n * d) / (p_.sigma_r * p_.sigma_r));
    elev_.assign(p_.n_layers(), 0.0);
    dropped_e_.assign(p_.n_layers(), 0.0);
    row_factor_.assign(p_.n_layers(), 0.0);
    kept_layers_.assign(p_.n_layers(), 0);
    kept_elev_.assign(p_.n_layers(), 0.0);
    kept_base_.assign(p_.n_layers(), 0);
    any_layers_.assign(p_.n_layers(), 0);
    // A batch: 256 returns, or as many rows as fill 1024 entries (plus one return's worth).
    jobs_.resize(256);
    exp_args_.resize(2 * jobs_.size());
    kept_weight_.assign(static_cast<std::size_t>(p_.n_layers()) * p_.n_dir, 0.0);
    layer_weight_.assign(p_.n_layers(), 0.0);
    far_weight_.assign(p_.n_layers(), 0.0);
    dropped_weight_.assign(static_cast<std::size_t>(p_.n_layers()) * p_.n_dir, 0.0);
    axis_stride_ = padded;
    padded_.assign(static_cast<std::size_t>(p_.n_layers()) * p_.n_dir * axis_stride_, 0.0);
    row_sums_.assign(static_cast<std::size_t>(p_.n_dir) * axis_stride_, 0.0);
    // k_first..k_last in angular_weights span at most 2·cut/Δθ, plus one for each end's rounding.
    const double span = 2.0 * cut_theta_ / (two_pi / p_.n_dir);
    reach_ = span >= p_.n_dir ? p_.n_dir : std::min(p_.n_dir, static_cast<int>(span) + 2);
    size_memo(default_slots);
    // θ_k, padded with NaN to whole vectors of 8 (kernels::nearest_returns).
    const std::size_t dirs8 = (static_cast<std::size_t>(p_.n_dir) + 7) / 8 * 8;
    dir_angle_.assign(dirs8, NAN);
    for (int k = 0; k < p_.n_dir; ++k) dir_angle_[k] = k * two_pi / p_.n_dir;
    best_return_.assign(dirs8, 0);
    best_gap_.assign(dirs8, 0.0);
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

template <bool planned>
std::size_t BoundaryVectorLayer::pruned_pass(std::span<const LidarReturn> returns, const ScanPlan* plan) const {
    // Sums go to a buffer whose axes are padded to whole blocks of 8 cells, so the vector kernel never
    // needs a scalar tail; they are copied to the result by copy_sums. Each return that feeds a row
    // becomes a job for the kernel: its profile, and its angular record (the directions it reaches
    // and their factors). Planned (a beam table, row by row), each direction's sum of A·D over a
    // scanner row's returns is formed once (row_sums_) and added to every layer the row feeds with
    // its elevation factor E (add_row_sums): a return that two layers read is summed once.
    // Unplanned (any point set, whose elevations need not repeat), a return gets a job per layer it
    // feeds, its profile scaled by that layer's E.
    const int L = p_.n_layers(), M = p_.n_per_axis;
    std::fill(padded_.begin(), padded_.end(), 0.0);
    const double dd = p_.spacing(), inv_dd = dd > 0 ? 1.0 / dd : 0.0;
    // Elevation factors of the current row: summed (elev_) and in [tiny_phi, tiny_row) (dropped_e_);
    // n_kept layers with a summed factor and n_any with any factor.
    const double* dropped_e = dropped_e_.data();
    int n_kept = 0, n_any = 0;
    // Unplanned, for the truncation bound: per (layer, direction) the kept weights Σ E·A and the
    // dropped ones, per layer Σ E over returns that reach it and Σ E over those whose distance window
    // is empty. Planned: the current run's counts.
    if constexpr (!planned) {
        std::fill(kept_weight_.begin(), kept_weight_.end(), 0.0);
        std::fill(dropped_weight_.begin(), dropped_weight_.end(), 0.0);
        std::fill(layer_weight_.begin(), layer_weight_.end(), 0.0);
        std::fill(far_weight_.begin(), far_weight_.end(), 0.0);
    }
    runs_.clear();
    std::size_t run_valid = 0, run_far = 0;
    auto end_run = [&] {
        if (!runs_.empty()) {
            runs_.back().valid = run_valid;
            runs_.back().far = run_far;
        }
        run_valid = run_far = 0;
    };
    if (plan && plan->columns > 0 && 2 * plan->columns != memo_slots_ && 2 * plan->columns <= max_slots)
        size_memo(2 * plan->columns);
    const std::size_t record = static_cast<std::size_t>(reach_) + 1;
    // Far-apart cells (spacing > sigma_r) are few per window: evaluate them directly, which also
    // keeps the power recurrence below far from overflow.
    const bool recurrence = dd > 0 && dd <= p_.sigma_r;
    kernels::ProfileJob* jobs = jobs_.data();
    const std::size_t max_jobs = jobs_.size();
    n_jobs_ = n_direct_ = 0;
    ++batch_;  // no job waits: every slot is free
    auto add_job = [&](const kernels::ProfileJob& job) {
        if (!recurrence) return add_profile_directly<planned>(job);
        jobs[n_jobs_++] = job;
        if (n_jobs_ == max_jobs) flush_jobs<planned>();
    };
    bool row_summed = false;  // planned: row_sums_ holds sums of the current row
    auto end_row = [&] {
        if (!planned || !row_summed) return;
        if (n_jobs_ > 0) flush_jobs<planned>();
        add_row_sums(n_kept);
        row_summed = false;
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
    // Each return's wrapped azimuth, memo slot and distance window, 64 returns at a time by vector
    // code: a superset of |r - d_m| <= cut (an extra cell only adds a true term). The kernel adds
    // whole blocks of 8 cells, aligned: a return's loads then meet the previous return's stores at
    // the same addresses, which the CPU forwards (a load straddling two earlier stores waits for
    // both to reach the cache); the cells this adds get their true terms. Cells evaluated one by one
    // (no recurrence) keep the window as it is: each costs an exp.
    const kernels::ReturnRule rule{
        cut_r_, dd, inv_dd, M, recurrence, slot_scale_, static_cast<std::int32_t>(memo_slots_)};
    static_assert(sizeof(LidarReturn) == 3 * sizeof(double));
    kernels::ReturnReadings in;

    for (std::size_t j = 0; j < returns.size(); ++j) {
        const std::size_t q = j % kernels::ReturnReadings::size;  // its readings in `in`
        if (q == 0) {
            const std::size_t n = std::min(kernels::ReturnReadings::size, returns.size() - j);
            const std::size_t bad = kernels::read_returns(&returns[j].range, n, rule, in);
            if (bad < n) check_return(returns[j + bad], j + bad);
        }
        if (in.absent[q]) continue;
        const LidarReturn& ret = returns[j];
        // Elevation factors, cached across the returns of one scanner row.
        if (!(ret.elevation == last_phi)) {
            end_row();
            last_phi = ret.elevation;
            skipped_row = plan && plan->skips(ret.elevation);
            row_factors(ret.elevation);
            n_kept = n_any = 0;
            for (int l = 0; l < L; ++l) {
                if (elev_[l] > 0.0) {
                    kept_layers_[n_kept] = l;
                    kept_elev_[n_kept] = elev_[l];
                    kept_base_[n_kept++] = static_cast<std::size_t>(l) * p_.n_dir * axis_stride_;
                }
                if (row_factor_[l] > 0.0) any_layers_[n_any++] = l;  // adding 0 to layer_weight changes nothing
            }
            if constexpr (planned) {
                end_run();
                if (!skipped_row) runs_.push_back(Run{ret.elevation, 0, 0});
            }
        }
        if (skipped_row) continue;  // the plan's bound covers the rows it did not cast
        ++valid;
        if constexpr (planned) {
            ++run_valid;
            if (n_kept == 0) continue;  // the bound reads no angular factor
        }
        if (n_any == 0) continue;
        // The directions the azimuth reaches and their angular factors: its memo slot's record, or
        // one of its own after the memo's records. A record stays as it is while a waiting job reads it.
        const double azimuth = in.azimuth[q];
        const std::size_t slot = use_memo ? static_cast<std::size_t>(in.slot[q]) : 0;
        std::size_t at = slot * record;
        if (use_memo && memo_weight_[at] == azimuth) {
            slot_batch_[slot] = batch_;
        } else if (use_memo && !(recurrence && slot_batch_[slot] == batch_)) {  // a miss: the slot takes it
            memo_dir_[at] =
                static_cast<std::uint16_t>(angular_weights(azimuth, &memo_dir_[at + 1], &memo_weight_[at + 1]));
            memo_weight_[at] = azimuth;
            slot_batch_[slot] = batch_;
        } else {  // no memo, or a job waiting for the kernel reads the slot's record: a record of its own
            if (n_direct_ == max_jobs) {  // the room is full: free it (some returns left no job)
                if (n_jobs_ > 0) flush_jobs<planned>();
                n_direct_ = 0;
            }
            at = (memo_slots_ + n_direct_++) * record;
            memo_dir_[at] =
                static_cast<std::uint16_t>(angular_weights(azimuth, &memo_dir_[at + 1], &memo_weight_[at + 1]));
        }
        if constexpr (!planned) {
            for (int i = 0; i < n_any; ++i) layer_weight_[any_layers_[i]] += row_factor_[any_layers_[i]];
            for (int l = 0; l < L && n_any > n_kept; ++l)
                if (dropped_e[l] > 0.0)
                    for (int d = 0; d < memo_dir_[at]; ++d)
                        dropped_weight_[static_cast<std::size_t>(l) * p_.n_dir + memo_dir_[at + 1 + d]] +=
                            dropped_e[l] * memo_weight_[at + 1 + d];
        }
        if (n_kept == 0) continue;
        if (in.width[q] == 0) {  // no cell in reach
            if constexpr (planned) ++run_far;
            else
                for (int i = 0; i < n_kept; ++i) far_weight_[kept_layers_[i]] += kept_elev_[i];
            continue;
        }
        if (memo_dir_[at] == 0) continue;  // an azimuth between directions that reaches none
        const int m_first = in.first[q], width = in.width[q];
        const double x0 = in.x0[q];
        if constexpr (planned) {
            add_job({x0, 1.0, static_cast<std::uint32_t>(m_first), static_cast<std::uint32_t>(at), width, 0});
            row_summed = true;
        } else {
            for (int i = 0; i < n_kept; ++i) {
                for (int d = 0; d < memo_dir_[at]; ++d)
                    kept_weight_[static_cast<std::size_t>(kept_layers_[i]) * p_.n_dir + memo_dir_[at + 1 + d]] +=
                        kept_elev_[i] * memo_weight_[at + 1 + d];
                add_job({x0, kept_elev_[i], static_cast<std::uint32_t>(kept_base_[i] + m_first),
                         static_cast<std::uint32_t>(at), width, 0});
            }
        }
    }
    end_row();
    if (n_jobs_ > 0) flush_jobs<planned>();
    if constexpr (planned) end_run();
    return valid;
}

template <bool planned>
void BoundaryVectorLayer::add_profile_directly(const kernels::ProfileJob& job) const {
    // exp(-h(x0 - nΔ)²) cell by cell (x0 = job.a, the profile's scale job.b), for each direction of
    // the job's record.
    const double dd = p_.spacing(), h_r = 0.5 / (p_.sigma_r * p_.sigma_r);
    const std::size_t stride = static_cast<std::size_t>(axis_stride_);
    double* sums = planned ? row_sums_.data() : padded_.data();
    const int n_dirs = memo_dir_[job.record];
    for (int n = 0; n < job.width; ++n) {
        const double x = job.a - n * dd;
        const double u = c_r_ * std::exp(-h_r * x * x) * job.b;  // b: the scale
        for (int d = 0; d < n_dirs; ++d)
            sums[job.base + memo_dir_[job.record + 1 + d] * stride + n] += memo_weight_[job.record + 1 + d] * u;
    }
}

template <bool planned>
void BoundaryVectorLayer::flush_jobs() const {
    profile_factors(n_jobs_);
    kernels::add_distance_profiles(jobs_.data(), n_jobs_, memo_dir_.data(), memo_weight_.data(),
                                   static_cast<std::size_t>(axis_stride_), dist_decay_.data(),
                                   planned ? row_sums_.data() : padded_.data());
    n_jobs_ = n_direct_ = 0;
    ++batch_;  // the records the flushed jobs read are free again
}

void BoundaryVectorLayer::add_row_sums(int n_kept) const {
    const std::size_t n = row_sums_.size();
    double* row = row_sums_.data();
    for (int i = 0; i < n_kept; ++i) {
        double* layer = padded_.data() + kept_base_[i];
        const double e = kept_elev_[i];
        for (std::size_t c = 0; c < n; ++c) layer[c] += e * row[c];
    }
    std::fill(row_sums_.begin(), row_sums_.end(), 0.0);
}

bool BoundaryVectorLayer::raw_pruned(std::span<const LidarReturn> returns, std::span<double> result) const {
    const std::size_t valid = pruned_pass<false>(returns, nullptr);
    copy_sums(*this, result);
    const double max_raw = kernels::largest(result.data(), result.size());
    return pruned_bound(valid) <= pruned_tolerance * max_raw;
}

void BoundaryVectorLayer::profile_factors(std::size_t n_jobs) const {
    const double h_r = 0.5 / (p_.sigma_r * p_.sigma_r), dd = p_.spacing();
    double* e = exp_args_.data();
    for (std::size_t i = 0; i < n_jobs; ++i) {
        const double x0 = jobs_[i].a;
        e[i] = -h_r * x0 * x0;
        e[n_jobs + i] = 2.0 * h_r * x0 * dd;
    }
    vector_exp(e, e, 2 * n_jobs);
    for (std::size_t i = 0; i < n_jobs; ++i) {
        jobs_[i].a = c_r_ * e[i] * jobs_[i].b;  // b: the profile's scale until now
        jobs_[i].b = e[n_jobs + i];
    }
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

double BoundaryVectorLayer::term_bound(double kept, double dropped, double weight, double far) const {
    return kept * c_r_ * tiny_r + dropped * c_r_ + weight * c_theta_ * c_r_ * tiny_theta +
           far * c_theta_ * c_r_ * tiny_r;
}

double BoundaryVectorLayer::elevation_tail(std::size_t returns) const {
    return p_.elevations.empty() ? 0.0 : static_cast<double>(returns) * c_phi_ * c_theta_ * c_r_ * tiny_phi;
}

double BoundaryVectorLayer::pruned_bound(std::size_t valid) const {
    // Every pruned term of cell (l, k, m) is one of: a distance factor below tiny_r of a kept
    // (return, layer, direction); an angular factor below tiny_theta of a (return, layer) whose
    // elevation factor was evaluated; a (return, layer, direction) whose elevation factor is below
    // tiny_row (its weight E·A is known exactly, D <= c_r); an elevation factor below tiny_phi
    // (worst case, for every return); the distance factor of a return whose whole window was empty.
    const int L = p_.n_layers(), K = p_.n_dir;
    double bound = 0;
    for (int l = 0; l < L; ++l)
        for (int k = 0; k < K; ++k) {
            const std::size_t lk = static_cast<std::size_t>(l) * K + k;
            bound =
                std::max(bound, term_bound(kept_weight_[lk], dropped_weight_[lk], layer_weight_[l], far_weight_[l]));
        }
    return bound + elevation_tail(valid);
}

double BoundaryVectorLayer::planned_bound(const ScanPlan& plan, const std::vector<Run>& runs) const {
    // The same terms as pruned_bound, with each run's Σ_returns A_k (kept or dropped, any direction k)
    // at most the lattice bound of the rows its label can be (and at most c_θ per return), and a row
    // the plan did not cast bounded by the plan. It depends on the scan's rows and this layer's
    // elevations only: a layer reading shared sums gets the verdict of its own pass.
    const int L = p_.n_layers();
    std::fill(kept_weight_.begin(), kept_weight_.begin() + L, 0.0);
    std::fill(dropped_weight_.begin(), dropped_weight_.begin() + L, 0.0);
    std::fill(layer_weight_.begin(), layer_weight_.end(), 0.0);
    std::fill(far_weight_.begin(), far_weight_.end(), 0.0);
    std::size_t valid = 0;
    for (const Run& run : runs) {
        if (plan.skips(run.elevation)) continue;
        row_factors(run.elevation);
        valid += run.valid;
        const double n = static_cast<double>(run.valid);
        const double angles = std::min(plan.angular_sum * plan.rows_per_label, n * c_theta_);
        for (int l = 0; l < L; ++l) {
            kept_weight_[l] += elev_[l] * angles;
            dropped_weight_[l] += dropped_e_[l] * angles;
            layer_weight_[l] += row_factor_[l] * n;
            far_weight_[l] += elev_[l] * static_cast<double>(run.far);
        }
    }
    double bound = 0;
    for (int l = 0; l < L; ++l)
        bound = std::max(bound, term_bound(kept_weight_[l], dropped_weight_[l], layer_weight_[l], far_weight_[l]) +
                                    plan.skipped_bound[l]);
    return bound + elevation_tail(std::max(valid, plan.beams));
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
    const auto at =
        std::find(p_.elevations.begin(), p_.elevations.end(), reader.elevations[static_cast<std::size_t>(l)]);
    if (at == p_.elevations.end())
        throw InputError("BVC layer: shared sums lack the elevation of layer " + std::to_string(l));
    return static_cast<std::size_t>(at - p_.elevations.begin()) * static_cast<std::size_t>(p_.n_dir);
}

void BoundaryVectorLayer::sum_pruned(std::span<const LidarReturn> returns, const ScanPlan& plan) const {
    pruned_pass<true>(returns, &plan);  // the bound is each reader's own (planned_bound of these runs)
}

bool BoundaryVectorLayer::rates_pruned_shared(std::span<const LidarReturn>, const ScanPlan& plan,
                                              const BoundaryVectorLayer& summed, std::span<double> out) const {
    if (out.size() != n_cells()) throw InputError("BVC layer: output has the wrong size");
    if (!can_share_sums(summed.p_))
        throw InputError("BVC layer: cannot read the sums of a layer with other parameters");
    return planned_rates(plan, summed, out);
}

bool BoundaryVectorLayer::planned_rates(const ScanPlan& plan, const BoundaryVectorLayer& summed,
                                        std::span<double> out) const {
    copy_sums(summed, out);
    const double max_raw = kernels::largest(out.data(), out.size());
    if (!(planned_bound(plan, summed.runs_) <= pruned_tolerance * max_raw)) return false;
    normalize(out, max_raw);
    return true;
}

void BoundaryVectorLayer::size_memo(std::size_t slots) const {
    // The slots, then room for a batch of records that are not memoised (irregular point sets).
    const std::size_t record = static_cast<std::size_t>(reach_) + 1;
    memo_slots_ = slots;
    slot_scale_ = static_cast<double>(slots) / two_pi;
    memo_weight_.assign((slots + jobs_.size()) * record, 0.0);
    memo_dir_.assign((slots + jobs_.size()) * record, 0);
    for (std::size_t slot = 0; slot < slots; ++slot) memo_weight_[slot * record] = NAN;  // the keys
    slot_batch_.assign(slots, 0);
}

int BoundaryVectorLayer::angular_weights(double azimuth, std::uint16_t* dir, double* weight) const {
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
        dir[count] = static_cast<std::uint16_t>(ki < 0    ? ki + K
                                                : ki >= K ? ki - K
                                                          : ki);  // |ki| < K: the window is under a turn
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
    near_azimuth_.clear();
    near_index_.clear();
    for (std::size_t j = 0; j < returns.size(); ++j) {
        if (is_no_return(returns[j])) continue;
        check_return(returns[j], j);
        near_azimuth_.push_back(wrap_pi(returns[j].azimuth));
        near_index_.push_back(j);
    }
    kernels::nearest_returns(near_azimuth_.data(), near_azimuth_.size(), dir_angle_.data(), K, best_return_.data(),
                             best_gap_.data());
    for (int k = 0; k < K; ++k) {  // back to the returns' own indices
        const auto i = static_cast<std::size_t>(best_return_[k]);
        best_return_[k] = static_cast<std::int64_t>(i < near_index_.size() ? near_index_[i] : returns.size());
    }
    // Pruned, a direction's profile is evaluated over its distance window only (as raw_pruned does):
    // a cell outside it would get less than tiny_r·c_r. Those Gaussian tails (down to 1e-56 of the
    // peak) were the subnormal float rates, and the weights Oja's rule grew from them, that made
    // the place cells take a microcode assist per product on many CPUs.
    const double dd = p_.spacing(), inv_dd = dd > 0 ? 1.0 / dd : 0.0;
    prune = prune && dd > 0;
    // The exponents of every cell to evaluate, then one batched exp.
    cells_.clear();
    exponents_.clear();
    for (int k = 0; k < K; ++k) {
        if (static_cast<std::size_t>(best_return_[k]) == returns.size()) continue;
        const double r = returns[static_cast<std::size_t>(best_return_[k])].range;
        int m_lo = 0, m_hi = M - 1;
        if (prune) {  // a superset of |r - d_m| <= cut, as in raw_pruned
            const double lo = (r - cut_r_) * inv_dd, hi = (r + cut_r_) * inv_dd;
            m_lo = lo > 0 ? static_cast<int>(std::min(lo, 1e9)) : 0;
            m_hi = std::min(static_cast<int>(std::min(hi, static_cast<double>(M - 2))) + 1, M - 1);
        }
        for (int m = m_lo; m <= m_hi; ++m) {
            const double x = r - m * p_.spacing();
            cells_.push_back(static_cast<std::size_t>(k) * M + m);
            exponents_.push_back(-0.5 * x * x / (p_.sigma_r * p_.sigma_r));
        }
    }
    vector_exp(exponents_.data(), exponents_.data(), exponents_.size());
    double max_raw = 0;
    for (std::size_t i = 0; i < cells_.size(); ++i) {
        const double v = c_r_ * exponents_[i];
        out[cells_[i]] = v;
        max_raw = std::max(max_raw, v);
    }
    return !prune || c_r_ * tiny_r <= pruned_tolerance * max_raw;
}

void BoundaryVectorLayer::raw(std::span<const LidarReturn> returns, std::span<double> out) const {
    if (out.size() != n_cells()) throw InputError("BVC layer: output has the wrong size");
    if (p_.reading == BvcReading::nearest_beam) {
        std::fill(out.begin(), out.end(), 0.0);
        if (!raw_nearest_beam(returns, out, true)) raw_nearest_beam(returns, out, false);
    } else if (!raw_pruned(returns, out)) {
        raw_exact(returns, out);
    }
}

void BoundaryVectorLayer::normalize(std::span<double> out, double mx) const {
    if (p_.normalization == BvcNormalization::per_step_max) {
        if (mx > 0) {
            kernels::divide(out.data(), out.size(), 2.0 * mx);  // exact 0.5 at the maximum
        } else {
            std::fill(out.begin(), out.end(), 0.0);
        }
    } else if (p_.normalization == BvcNormalization::fixed) {
        kernels::divide(out.data(), out.size(), p_.norm_constant);
    }
}

void BoundaryVectorLayer::rates(std::span<const LidarReturn> returns, std::span<double> out) const {
    raw(returns, out);
    normalize(out, kernels::largest(out.data(), out.size()));
}

bool BoundaryVectorLayer::rates_pruned(std::span<const LidarReturn> returns, const ScanPlan& plan,
                                       std::span<double> out) const {
    if (out.size() != n_cells()) throw InputError("BVC layer: output has the wrong size");
    if (p_.reading == BvcReading::nearest_beam) {
        rates(returns, out);
        return true;
    }
    pruned_pass<true>(returns, &plan);
    return planned_rates(plan, *this, out);
}

BoundaryVectorLayer::ScanPlan BoundaryVectorLayer::plan(const LidarSpec& sensor) const {
    ScanPlan plan;
    const int L = p_.n_layers();
    const std::vector<double>& rows = sensor.row_labels();  // the elevations the returns carry
    plan.rows.assign(rows.size(), 1);
    plan.skipped_bound.assign(L, 0.0);
    plan.beams = sensor.beam_count();
    plan.columns = static_cast<std::size_t>(sensor.azimuth_count);
    // A row's beams are evenly spaced in azimuth (δ apart), so for any heading and direction
    // Σ_columns exp(-x²/2σ_θ²) <= 1 + √(2π)·σ_θ/δ (a unimodal function summed over a lattice).
    // linspace labels are δ' = 2π/(n−1) > δ apart with one azimuth twice (0 and 2π): one term more.
    const double delta = two_pi / sensor.azimuth_count;
    const double repeated = sensor.azimuth_labels == AzimuthLabels::linspace ? 1.0 : 0.0;
    const double angular_sum = c_theta_ * (1.0 + std::sqrt(two_pi) * p_.sigma_theta / delta + repeated);
    plan.angular_sum = angular_sum;
    std::vector<double> labels = rows;
    std::sort(labels.begin(), labels.end());
    for (auto at = labels.begin(); at != labels.end();) {
        const auto next = std::upper_bound(at, labels.end(), *at);
        plan.rows_per_label = std::max(plan.rows_per_label, static_cast<int>(next - at));
        at = next;
    }
    if (p_.elevations.empty() || p_.reading == BvcReading::nearest_beam) return plan;  // reads every row
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
