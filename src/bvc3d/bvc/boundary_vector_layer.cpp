#include "bvc3d/bvc/boundary_vector_layer.hpp"

#include <algorithm>
#include <cmath>

#include "bvc3d/bvc/bvc_kernels.hpp"
#include "bvc3d/core/angles.hpp"
#include "bvc3d/core/error.hpp"

namespace bvc3d {

namespace {

// A factor exp(-x²/2σ²) below this (relative to its peak) is treated as zero. Each pruned term is
// then below tiny × (product of the peaks), and raw_pruned checks that their sum cannot reach
// 1e-7 of the step's largest sum (SPEC §5 asks for 1e-6 of the largest rate).
constexpr double tiny = 1e-13;
constexpr double pruned_tolerance = 1e-7;

double window(double sigma) { return sigma * std::sqrt(2.0 * std::log(1.0 / tiny)); }
double gauss_norm(double sigma) { return 1.0 / std::sqrt(two_pi * sigma * sigma); }

}  // namespace

void BvcParams::validate() const {
    auto fail = [](const std::string& what) { throw InputError("BVC layer: " + what); };
    for (double e : elevations)
        if (!std::isfinite(e) || std::abs(e) > pi / 2) fail("every elevation must be finite and within ±π/2 rad");
    if (n_dir < 1) fail("n_dir must be >= 1");
    if (n_per_axis < 1) fail("n_per_axis must be >= 1");
    if (!std::isfinite(max_dist) || max_dist < 0 || (n_per_axis > 1 && max_dist == 0))
        fail("max_dist must be > 0");
    if (!std::isfinite(sigma_r) || sigma_r <= 0) fail("sigma_r must be > 0");
    if (!std::isfinite(sigma_theta) || sigma_theta <= 0) fail("sigma_theta must be > 0");
    if (!std::isfinite(sigma_phi) || sigma_phi <= 0) fail("sigma_phi must be > 0");
    if (normalization == BvcNormalization::fixed && !(std::isfinite(norm_constant) && norm_constant > 0))
        fail("norm_constant must be > 0 for fixed normalisation");
    if (reading == BvcReading::nearest_beam && !elevations.empty())
        fail("the nearest_beam reading is a 2-D model: it takes no elevations");
}

BvcNormalization parse_bvc_normalization(const std::string& name) {
    if (name == "per_step_max") return BvcNormalization::per_step_max;
    if (name == "none") return BvcNormalization::none;
    if (name == "fixed") return BvcNormalization::fixed;
    throw InputError("normalization '" + name + "' is not one of per_step_max, none, fixed");
}

std::string to_string(BvcNormalization n) {
    switch (n) {
        case BvcNormalization::per_step_max: return "per_step_max";
        case BvcNormalization::none: return "none";
        case BvcNormalization::fixed: return "fixed";
    }
    return "?";
}

BvcReading parse_bvc_reading(const std::string& name) {
    if (name == "gaussian") return BvcReading::gaussian;
    if (name == "nearest_beam") return BvcReading::nearest_beam;
    throw InputError("reading '" + name + "' is not one of gaussian, nearest_beam");
}

std::string to_string(BvcReading r) { return r == BvcReading::gaussian ? "gaussian" : "nearest_beam"; }

BoundaryVectorLayer::BoundaryVectorLayer(BvcParams params) : p_(std::move(params)) {
    p_.validate();
    c_r_ = gauss_norm(p_.sigma_r);
    c_theta_ = gauss_norm(p_.sigma_theta);
    c_phi_ = gauss_norm(p_.sigma_phi);
    cut_r_ = window(p_.sigma_r);
    cut_theta_ = window(p_.sigma_theta);
    cut_phi_ = window(p_.sigma_phi);
    const double d = p_.spacing();
    // Padded with zeros to a multiple of 8 for the vector kernel.
    const int padded = (p_.n_per_axis + 7) / 8 * 8;
    dist_decay_.assign(padded, 0.0);
    for (int n = 0; n < p_.n_per_axis; ++n) dist_decay_[n] = std::exp(-0.5 * (n * d) * (n * d) / (p_.sigma_r * p_.sigma_r));
    profile_.assign(padded, 0.0);
    weights_.assign(static_cast<std::size_t>(p_.n_layers()) * p_.n_dir, 0.0);
    rows_.assign(weights_.size(), nullptr);
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

bool BoundaryVectorLayer::raw_pruned(std::span<const LidarReturn> returns, std::size_t n_bound,
                                     std::span<double> out) const {
    std::fill(out.begin(), out.end(), 0.0);
    const int L = p_.n_layers(), K = p_.n_dir, M = p_.n_per_axis;
    const bool planar = p_.elevations.empty();
    const double dd = p_.spacing(), dtheta = two_pi / K;
    const double h_r = 0.5 / (p_.sigma_r * p_.sigma_r), h_t = 0.5 / (p_.sigma_theta * p_.sigma_theta),
                 h_p = 0.5 / (p_.sigma_phi * p_.sigma_phi);
    // Far-apart cells (spacing > sigma_r) are few per window: evaluate them directly, which also
    // keeps the power recurrence below far from overflow.
    const bool recurrence = dd > 0 && dd <= p_.sigma_r;
    double elev_w[64];
    std::vector<double> elev_heap;
    double* elev = L <= 64 ? elev_w : (elev_heap.resize(L), elev_heap.data());
    std::size_t valid = 0;
    double last_phi = NAN;
    bool any_layer = true;

    for (std::size_t j = 0; j < returns.size(); ++j) {
        const LidarReturn& ret = returns[j];
        if (is_no_return(ret)) continue;
        check_return(ret, j);
        ++valid;
        // Elevation factors, cached across the returns of one scanner row.
        if (!(ret.elevation == last_phi)) {
            last_phi = ret.elevation;
            any_layer = false;
            for (int l = 0; l < L; ++l) {
                if (planar) {
                    elev[l] = 1.0;
                } else {
                    const double x = ret.elevation - p_.elevations[l];
                    elev[l] = std::abs(x) <= cut_phi_ ? c_phi_ * std::exp(-x * x * h_p) : 0.0;
                }
                any_layer = any_layer || elev[l] > 0.0;
            }
        }
        if (!any_layer) continue;

        // Distance window [m_lo, m_hi] and the profile c_r·exp(-(r - d_m)²/2σ²) across it.
        const double r = ret.range;
        int m_lo = 0, m_hi = 0;
        if (dd > 0) {
            m_lo = std::max(0, static_cast<int>(std::ceil((r - cut_r_) / dd)));
            m_hi = std::min(M - 1, static_cast<int>(std::floor((r + cut_r_) / dd)));
        } else if (r > cut_r_) {
            continue;
        }
        if (m_lo > m_hi) continue;
        const int W = m_hi - m_lo + 1;

        // The (layer, direction) rows this return feeds, with their elevation × angular weights.
        int count = 0;
        int k_first = 0, k_last = K - 1;
        const bool all_dirs = 2.0 * cut_theta_ >= two_pi;
        if (!all_dirs) {
            k_first = static_cast<int>(std::ceil((ret.azimuth - cut_theta_) / dtheta));
            k_last = static_cast<int>(std::floor((ret.azimuth + cut_theta_) / dtheta));
        }
        for (int ki = k_first; ki <= k_last; ++ki) {
            const double x = all_dirs ? wrap_pi(ret.azimuth - ki * dtheta) : ret.azimuth - ki * dtheta;
            if (std::abs(x) > cut_theta_) continue;
            const double ang = c_theta_ * std::exp(-x * x * h_t);
            const int k = ((ki % K) + K) % K;
            for (int l = 0; l < L; ++l) {
                if (elev[l] == 0.0) continue;
                weights_[count] = elev[l] * ang;
                rows_[count] = out.data() + (static_cast<std::size_t>(l) * K + k) * M + m_lo;
                ++count;
            }
        }
        if (count == 0) continue;

        // Distance profile c_r·exp(-(r - d_m)²/2σ²) over the window, added to every row.
        if (recurrence) {
            // exp(-h(x0 - nΔ)²) = exp(-h x0²) · exp(2h x0 Δ)^n · exp(-h n²Δ²): two exps per return.
            const double x0 = r - m_lo * dd;
            kernels::add_distance_profile(c_r_ * std::exp(-h_r * x0 * x0), std::exp(2.0 * h_r * x0 * dd),
                                          dist_decay_.data(), W, weights_.data(), rows_.data(), count,
                                          profile_.data());
        } else {
            for (int n = 0; n < W; ++n) {
                const double x = r - (m_lo + n) * dd;
                const double u = c_r_ * std::exp(-h_r * x * x);
                for (int i = 0; i < count; ++i) rows_[i][n] += weights_[i] * u;
            }
        }
    }
    const double peak_term = c_r_ * c_theta_ * (planar ? 1.0 : c_phi_);
    const double max_raw = out.empty() ? 0.0 : *std::max_element(out.begin(), out.end());
    const double bound = static_cast<double>(std::max(valid, n_bound)) * peak_term * tiny;
    return bound <= pruned_tolerance * max_raw;
}

void BoundaryVectorLayer::raw_exact(std::span<const LidarReturn> returns, std::span<double> out) const {
    if (out.size() != n_cells()) throw InputError("BVC layer: output has the wrong size");
    std::fill(out.begin(), out.end(), 0.0);
    if (p_.reading == BvcReading::nearest_beam) {
        raw_nearest_beam(returns, out);
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

void BoundaryVectorLayer::raw_nearest_beam(std::span<const LidarReturn> returns, std::span<double> out) const {
    const int K = p_.n_dir, M = p_.n_per_axis;
    for (int k = 0; k < K; ++k) {
        const double theta_k = k * two_pi / K;
        std::size_t best = returns.size();
        double best_gap = INFINITY;
        for (std::size_t j = 0; j < returns.size(); ++j) {
            if (is_no_return(returns[j])) continue;
            check_return(returns[j], j);
            const double gap = std::abs(wrap_pi(returns[j].azimuth - theta_k));
            if (gap < best_gap) {
                best_gap = gap;
                best = j;
            }
        }
        if (best == returns.size()) continue;
        for (int m = 0; m < M; ++m) {
            const double x = returns[best].range - m * p_.spacing();
            out[static_cast<std::size_t>(k) * M + m] = c_r_ * std::exp(-0.5 * x * x / (p_.sigma_r * p_.sigma_r));
        }
    }
}

void BoundaryVectorLayer::raw(std::span<const LidarReturn> returns, std::span<double> out) const {
    if (out.size() != n_cells()) throw InputError("BVC layer: output has the wrong size");
    if (p_.reading == BvcReading::nearest_beam) {
        std::fill(out.begin(), out.end(), 0.0);
        raw_nearest_beam(returns, out);
    } else if (!raw_pruned(returns, 0, out)) {
        raw_exact(returns, out);
    }
}

void BoundaryVectorLayer::normalise(std::span<double> out) const {
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
    normalise(out);
}

bool BoundaryVectorLayer::rates_pruned(std::span<const LidarReturn> returns, std::size_t beams_in_full_scan,
                                       std::span<double> out) const {
    if (out.size() != n_cells()) throw InputError("BVC layer: output has the wrong size");
    if (p_.reading == BvcReading::nearest_beam) {
        rates(returns, out);
        return true;
    }
    if (!raw_pruned(returns, beams_in_full_scan, out)) return false;
    normalise(out);
    return true;
}

std::vector<char> BoundaryVectorLayer::rows_needed(const LidarSpec& sensor) const {
    std::vector<char> rows(sensor.elevations.size(), 1);
    if (p_.elevations.empty()) return rows;  // the 2-D model reads every row
    for (std::size_t i = 0; i < rows.size(); ++i) {
        bool near = false;
        for (double psi : p_.elevations) near = near || std::abs(sensor.elevations[i] - psi) <= cut_phi_;
        rows[i] = near;
    }
    return rows;
}

}  // namespace bvc3d
