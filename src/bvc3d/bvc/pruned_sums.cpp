#include "bvc3d/bvc/pruned_sums.hpp"

#include <algorithm>
#include <cmath>

#include "bvc3d/bvc/return_check.hpp"
#include "bvc3d/core/angles.hpp"
#include "bvc3d/core/vector_math.hpp"

namespace bvc3d {

namespace {
// A memo of at most this many slots (a beam table's columns; more, and the default is kept).
constexpr std::size_t max_slots = 1 << 16;
// A batch of the kernel's jobs: 256 returns, or as many rows as fill 1024 entries (plus one return's worth).
constexpr std::size_t batch_jobs = 256;
}  // namespace

PrunedSums::PrunedSums(const LayerTuning& tuning) : t_(tuning), win_(tuning) {
    const int L = t_.n_layers(), K = t_.n_dir;
    const double d = t_.spacing, sigma = t_.distance.sigma;
    axis_stride_ = (t_.n_per_axis + 7) / 8 * 8;
    // Far-apart cells (spacing > σ_r) are few per window: evaluate them directly, which also keeps the power
    // recurrence below far from overflow.
    recurrence_ = d > 0 && d <= sigma;
    dist_decay_.assign(axis_stride_, 0.0);
    for (int n = 0; n < axis_stride_; ++n) dist_decay_[n] = std::exp(-0.5 * (n * d) * (n * d) / (sigma * sigma));
    padded_.assign(static_cast<std::size_t>(L) * K * axis_stride_, 0.0);
    row_sums_.assign(static_cast<std::size_t>(K) * axis_stride_, 0.0);
    row_.kept.assign(L, 0.0);
    row_.dropped.assign(L, 0.0);
    row_.kept_layers.assign(L, 0);
    row_.any_layers.assign(L, 0);
    row_.kept_base.assign(L, 0);
    row_.kept_elev.assign(L, 0.0);
    jobs_.resize(batch_jobs);
    exp_args_.resize(2 * jobs_.size());
    weights_.reset(L, K);
    // The directions of one azimuth span at most 2·window/Δθ, plus one for each end's rounding.
    const double span = 2.0 * win_.theta / (two_pi / K);
    reach_ = span >= K ? K : std::min(K, static_cast<int>(span) + 2);
    size_memo(default_slots);
}

void PrunedSums::size_memo(std::size_t slots) {
    // The slots, then room for a batch of records that are not memoised (irregular point sets).
    const std::size_t record = static_cast<std::size_t>(reach_) + 1;
    memo_slots_ = slots;
    slot_scale_ = static_cast<double>(slots) / two_pi;
    memo_weight_.assign((slots + jobs_.size()) * record, 0.0);
    memo_dir_.assign((slots + jobs_.size()) * record, 0);
    for (std::size_t slot = 0; slot < slots; ++slot) memo_weight_[slot * record] = NAN;  // the keys
    slot_batch_.assign(slots, 0);
}

int PrunedSums::angular_weights(double azimuth, std::uint16_t* dir, double* weight) const {
    const int K = t_.n_dir;
    const double dtheta = two_pi / K, cut = win_.theta;
    const bool all_dirs = 2.0 * cut >= two_pi;
    // ceil and floor of quotients within a few turns, from truncation (no libm call on baseline x86-64).
    auto ceil_int = [](double t) {
        const int i = static_cast<int>(t);
        return i + (static_cast<double>(i) < t);
    };
    auto floor_int = [](double t) {
        const int i = static_cast<int>(t);
        return i - (static_cast<double>(i) > t);
    };
    const int k_first = all_dirs ? 0 : ceil_int((azimuth - cut) / dtheta);
    const int k_last = all_dirs ? K - 1 : floor_int((azimuth + cut) / dtheta);
    int count = 0;
    for (int ki = k_first; ki <= k_last; ++ki) {
        const double x = all_dirs ? wrap_pi(azimuth - ki * dtheta) : azimuth - ki * dtheta;
        if (std::abs(x) > cut) continue;
        // |ki| < K: the window is under a turn.
        dir[count] = static_cast<std::uint16_t>(ki < 0 ? ki + K : ki >= K ? ki - K : ki);
        weight[count] = t_.azimuth(x);
        ++count;
    }
    return count;
}

void PrunedSums::enter_row(double phi) {
    Row& r = row_;
    r.n_kept = r.n_any = 0;
    for (int l = 0; l < t_.n_layers(); ++l) {
        const pruning::ElevationSplit e = pruning::split_elevation(t_, win_, l, phi);
        r.kept[l] = e.kept;
        r.dropped[l] = e.dropped;
        if (e.kept > 0.0) {
            r.kept_layers[r.n_kept] = l;
            r.kept_elev[r.n_kept] = e.kept;
            r.kept_base[r.n_kept++] = static_cast<std::size_t>(l) * t_.n_dir * axis_stride_;
        }
        if (e.kept + e.dropped > 0.0) r.any_layers[r.n_any++] = l;  // adding 0 to a weight changes nothing
    }
}

bool PrunedSums::begin_pass(std::span<const LidarReturn> returns, const ScanPlan* plan) {
    std::fill(padded_.begin(), padded_.end(), 0.0);
    if (plan && plan->columns > 0 && 2 * plan->columns != memo_slots_ && 2 * plan->columns <= max_slots)
        size_memo(2 * plan->columns);
    n_jobs_ = n_direct_ = 0;
    ++batch_;  // no job waits: every slot is free
    const double dd = t_.spacing, inv_dd = dd > 0 ? 1.0 / dd : 0.0;
    // Each return's wrapped azimuth, memo slot and distance window, by vector code: a superset of |r - d_m| <= cut
    // (an extra cell only adds a true term). With the recurrence the kernel adds whole blocks of 8 cells, aligned: a
    // return's loads then meet the previous return's stores at the same addresses, which the CPU forwards (a load
    // straddling two earlier stores waits for both to reach the cache). Cells evaluated one by one keep the window as
    // it is: each costs an exp.
    rule_ = kernels::ReturnRule{
        win_.r, dd, inv_dd, t_.n_per_axis, recurrence_, slot_scale_, static_cast<std::int32_t>(memo_slots_)};
    // A beam table comes row by row; returns whose elevation changes nearly every time are an irregular point set,
    // whose azimuths never repeat: the memo is left alone for them.
    std::size_t changes = 0;
    const std::size_t probe = std::min<std::size_t>(returns.size(), 64);
    for (std::size_t j = 1; j < probe; ++j) changes += !(returns[j].elevation == returns[j - 1].elevation);
    return probe < 64 || changes < 56;
}

template <class Visit>
void PrunedSums::for_each_return(std::span<const LidarReturn> returns, Visit&& visit) {
    static_assert(sizeof(LidarReturn) == 3 * sizeof(double));
    for (std::size_t j = 0; j < returns.size(); ++j) {
        const std::size_t q = j % kernels::ReturnReadings::size;
        if (q == 0) {
            const std::size_t n = std::min(kernels::ReturnReadings::size, returns.size() - j);
            const std::size_t bad = kernels::read_returns(&returns[j].range, n, rule_, in_);
            if (bad < n) check_return(returns[j + bad], j + bad);
        }
        if (!in_.absent[q]) visit(returns[j], q);
    }
}

// record_of and add_job run once per return (and layer): inlined into the two passes, as the lambdas they were.
[[gnu::always_inline]] inline std::size_t PrunedSums::record_of(std::size_t q, bool use_memo, double* sums) {
    const std::size_t record = static_cast<std::size_t>(reach_) + 1;
    const double azimuth = in_.azimuth[q];
    const std::size_t slot = use_memo ? static_cast<std::size_t>(in_.slot[q]) : 0;
    std::size_t at = slot * record;
    if (use_memo && memo_weight_[at] == azimuth) {
        slot_batch_[slot] = batch_;
        return at;
    }
    if (use_memo && !(recurrence_ && slot_batch_[slot] == batch_)) {  // a miss: the slot takes it
        memo_dir_[at] = static_cast<std::uint16_t>(angular_weights(azimuth, &memo_dir_[at + 1], &memo_weight_[at + 1]));
        memo_weight_[at] = azimuth;
        slot_batch_[slot] = batch_;
        return at;
    }
    // No memo, or a job waiting for the kernel reads the slot's record: a record of its own.
    if (n_direct_ == jobs_.size()) {  // the room is full: free it (some returns left no job)
        if (n_jobs_ > 0) flush_jobs(sums);
        n_direct_ = 0;
    }
    at = (memo_slots_ + n_direct_++) * record;
    memo_dir_[at] = static_cast<std::uint16_t>(angular_weights(azimuth, &memo_dir_[at + 1], &memo_weight_[at + 1]));
    return at;
}

[[gnu::always_inline]] inline void PrunedSums::add_job(const kernels::ProfileJob& job, double* sums) {
    if (!recurrence_) return add_profile_directly(job, sums);
    jobs_[n_jobs_++] = job;
    if (n_jobs_ == jobs_.size()) flush_jobs(sums);
}

std::size_t PrunedSums::sum_unplanned(std::span<const LidarReturn> returns) {
    const bool use_memo = begin_pass(returns, nullptr);
    const std::size_t K = static_cast<std::size_t>(t_.n_dir);
    weights_.reset(t_.n_layers(), t_.n_dir);
    double* sums = padded_.data();
    const Row& r = row_;
    std::size_t valid = 0;
    double last_phi = NAN;
    for_each_return(returns, [&](const LidarReturn& ret, std::size_t q) {
        if (!(ret.elevation == last_phi)) {  // elevation factors, cached across the returns of one scanner row
            last_phi = ret.elevation;
            enter_row(ret.elevation);
        }
        ++valid;
        if (r.n_any == 0) return;
        const std::size_t at = record_of(q, use_memo, sums);
        const int n_dirs = memo_dir_[at];
        for (int i = 0; i < r.n_any; ++i) {
            const int l = r.any_layers[i];
            weights_.evaluated[l] += r.kept[l] + r.dropped[l];
        }
        for (int l = 0; l < t_.n_layers() && r.n_any > r.n_kept; ++l)
            if (r.dropped[l] > 0.0)
                for (int d = 0; d < n_dirs; ++d)
                    weights_.dropped[l * K + memo_dir_[at + 1 + d]] += r.dropped[l] * memo_weight_[at + 1 + d];
        if (r.n_kept == 0) return;
        if (in_.width[q] == 0) {  // no cell in reach
            for (int i = 0; i < r.n_kept; ++i) weights_.far[r.kept_layers[i]] += r.kept_elev[i];
            return;
        }
        if (n_dirs == 0) return;  // an azimuth between directions that reaches none
        for (int i = 0; i < r.n_kept; ++i) {
            for (int d = 0; d < n_dirs; ++d)
                weights_.kept[r.kept_layers[i] * K + memo_dir_[at + 1 + d]] +=
                    r.kept_elev[i] * memo_weight_[at + 1 + d];
            add_job({in_.x0[q], r.kept_elev[i], static_cast<std::uint32_t>(r.kept_base[i] + in_.first[q]),
                     static_cast<std::uint32_t>(at), in_.width[q], 0},
                    sums);
        }
    });
    if (n_jobs_ > 0) flush_jobs(sums);
    return valid;
}

void PrunedSums::sum_planned(std::span<const LidarReturn> returns, const ScanPlan& plan) {
    const bool use_memo = begin_pass(returns, &plan);
    double* sums = row_sums_.data();
    runs_.clear();
    std::size_t run_valid = 0, run_far = 0;
    auto end_run = [&] {
        if (!runs_.empty()) {
            runs_.back().valid = run_valid;
            runs_.back().far = run_far;
        }
        run_valid = run_far = 0;
    };
    bool row_summed = false;  // row_sums_ holds sums of the current row
    auto end_row = [&] {
        if (!row_summed) return;
        if (n_jobs_ > 0) flush_jobs(sums);
        add_row_sums();
        row_summed = false;
    };
    double last_phi = NAN;
    bool skipped_row = false;
    for_each_return(returns, [&](const LidarReturn& ret, std::size_t q) {
        if (!(ret.elevation == last_phi)) {  // a new scanner row
            end_row();
            last_phi = ret.elevation;
            skipped_row = plan.skips(ret.elevation);
            enter_row(ret.elevation);
            end_run();
            if (!skipped_row) runs_.push_back(pruning::Run{ret.elevation, 0, 0});
        }
        if (skipped_row) return;  // the plan's bound covers the rows it did not cast
        ++run_valid;
        if (row_.n_kept == 0) return;  // the bound reads no angular factor
        const std::size_t at = record_of(q, use_memo, sums);
        if (in_.width[q] == 0) {  // no cell in reach
            ++run_far;
            return;
        }
        if (memo_dir_[at] == 0) return;  // an azimuth between directions that reaches none
        add_job(
            {in_.x0[q], 1.0, static_cast<std::uint32_t>(in_.first[q]), static_cast<std::uint32_t>(at), in_.width[q], 0},
            sums);
        row_summed = true;
    });
    end_row();
    if (n_jobs_ > 0) flush_jobs(sums);
    end_run();
}

void PrunedSums::add_profile_directly(const kernels::ProfileJob& job, double* sums) const {
    // D(x0 − nΔ)·scale cell by cell (x0 = job.a, the scale job.b), for each direction of the job's record.
    const double dd = t_.spacing, h_r = t_.distance.h, c_r = t_.distance.peak;
    const std::size_t stride = static_cast<std::size_t>(axis_stride_);
    const int n_dirs = memo_dir_[job.record];
    for (int n = 0; n < job.width; ++n) {
        const double x = job.a - n * dd;
        const double u = c_r * std::exp(-h_r * x * x) * job.b;
        for (int d = 0; d < n_dirs; ++d)
            sums[job.base + memo_dir_[job.record + 1 + d] * stride + n] += memo_weight_[job.record + 1 + d] * u;
    }
}

void PrunedSums::flush_jobs(double* sums) {
    profile_factors(n_jobs_);
    kernels::add_distance_profiles(jobs_.data(), n_jobs_, memo_dir_.data(), memo_weight_.data(),
                                   static_cast<std::size_t>(axis_stride_), dist_decay_.data(), sums);
    n_jobs_ = n_direct_ = 0;
    ++batch_;  // the records the flushed jobs read are free again
}

void PrunedSums::profile_factors(std::size_t n_jobs) {
    // D(x0 − nΔ) = c_r·exp(−h x0²) · exp(2h x0 Δ)^n · exp(−h n²Δ²): a = scale·c_r·exp(−h x0²), b = exp(2h x0 Δ).
    const double h_r = t_.distance.h, dd = t_.spacing;
    double* e = exp_args_.data();
    for (std::size_t i = 0; i < n_jobs; ++i) {
        const double x0 = jobs_[i].a;
        e[i] = -h_r * x0 * x0;
        e[n_jobs + i] = 2.0 * h_r * x0 * dd;
    }
    vector_exp(e, e, 2 * n_jobs);
    for (std::size_t i = 0; i < n_jobs; ++i) {
        jobs_[i].a = t_.distance.peak * e[i] * jobs_[i].b;  // b: the profile's scale until now
        jobs_[i].b = e[n_jobs + i];
    }
}

void PrunedSums::add_row_sums() {
    const std::size_t n = row_sums_.size();
    const double* row = row_sums_.data();
    for (int i = 0; i < row_.n_kept; ++i) {
        double* layer = padded_.data() + row_.kept_base[i];
        const double e = row_.kept_elev[i];
        for (std::size_t c = 0; c < n; ++c) layer[c] += e * row[c];
    }
    std::fill(row_sums_.begin(), row_sums_.end(), 0.0);
}

void PrunedSums::copy_sums(const BvcParams& reader, bool same_layer, std::span<double> out) const {
    const int K = reader.n_dir, M = reader.n_per_axis;
    const std::size_t stride = static_cast<std::size_t>(axis_stride_);
    for (int l = 0; l < reader.n_layers(); ++l) {
        std::size_t layer = static_cast<std::size_t>(l);
        if (!same_layer && !reader.elevations.empty()) {
            const double psi = reader.elevations[static_cast<std::size_t>(l)];
            const auto at = std::find(t_.elevations.begin(), t_.elevations.end(), psi);
            if (at == t_.elevations.end())
                throw InputError("BVC layer: shared sums lack the elevation of layer " + std::to_string(l));
            layer = static_cast<std::size_t>(at - t_.elevations.begin());
        }
        const double* from = padded_.data() + layer * static_cast<std::size_t>(t_.n_dir) * stride;
        for (int k = 0; k < K; ++k)
            std::copy(from + static_cast<std::size_t>(k) * stride, from + static_cast<std::size_t>(k) * stride + M,
                      out.begin() + (static_cast<std::ptrdiff_t>(l) * K + k) * M);
    }
}

}  // namespace bvc3d
