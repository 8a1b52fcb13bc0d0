#pragma once
// BVC stage (SPEC §5): boundary vector cells tuned to distance, allocentric azimuth and elevation.
// Takes: LiDAR returns (range, azimuth, elevation). Gives: one rate per cell, cell i = (l, k, m) at
// index (l·n_dir + k)·n_per_axis + m, for preferred elevation psi_l, azimuth theta_k = 2πk/n_dir and
// distance d_m = m·max_dist/(n_per_axis - 1).
#include <span>
#include <string>
#include <vector>

#include "bvc3d/sensor/lidar.hpp"

namespace bvc3d {

enum class BvcNormalization { per_step_max, none, fixed };

// How a direction reads the scan: the paper's Gaussian over all returns (eq. 1-2), or the single
// return nearest to theta_k with no angular or elevation factor (the authors' code; `2d-8beam`).
enum class BvcReading { gaussian, nearest_beam };

struct BvcParams {
    std::vector<double> elevations;  // psi_l in radians; empty: the 2-D model (no elevation factor)
    int n_dir = 8;
    int n_per_axis = 60;
    double max_dist = 12.0;     // m
    double sigma_r = 0.75;      // m
    double sigma_theta = 0.1;   // rad
    double sigma_phi = 0.01;    // rad
    BvcNormalization normalization = BvcNormalization::per_step_max;
    double norm_constant = 1.0;  // `fixed`: rate = raw / norm_constant
    BvcReading reading = BvcReading::gaussian;

    int n_layers() const { return elevations.empty() ? 1 : static_cast<int>(elevations.size()); }
    int n_cells() const { return n_layers() * n_dir * n_per_axis; }
    double spacing() const { return n_per_axis > 1 ? max_dist / (n_per_axis - 1) : 0.0; }
    void validate() const;  // throws InputError naming the bad parameter
};

BvcNormalization parse_bvc_normalization(const std::string& name);  // throws InputError
std::string to_string(BvcNormalization n);
BvcReading parse_bvc_reading(const std::string& name);
std::string to_string(BvcReading r);

class BoundaryVectorLayer {
public:
    explicit BoundaryVectorLayer(BvcParams params);

    const BvcParams& params() const { return p_; }
    std::size_t n_cells() const { return static_cast<std::size_t>(p_.n_cells()); }

    // Input hygiene: a return whose range is NaN or +inf means "no return" and is skipped; a
    // negative range, -inf, or a non-finite angle throws InputError naming the return.
    //
    // Unnormalised sums raw_i (SPEC §5), to within 1e-7 of the largest raw_i: terms whose factors
    // are all but zero are pruned, and a per-step bound on what was pruned is checked; when it is
    // not small enough the full sum is computed instead.
    void raw(std::span<const LidarReturn> returns, std::span<double> out) const;
    // Normalised rates (per_step_max: raw / (2·max raw), so the largest is exactly 0.5).
    void rates(std::span<const LidarReturn> returns, std::span<double> out) const;

    // Rows of a beam table whose every beam contributes below the tolerance to every cell, so a
    // scanner need not cast them: rows[i] = 0. When scans are pruned this way, pass the full
    // beam count to rates()/raw() through `beams_in_full_scan`, so that the error bound counts the
    // beams that were not cast; if it fails, `needs_full_scan()` is set and the caller re-casts.
    std::vector<char> rows_needed(const LidarSpec& sensor) const;
    bool rates_pruned(std::span<const LidarReturn> returns, std::size_t beams_in_full_scan, std::span<double> out) const;

    // The full triple-Gaussian sum with no pruning: the definition itself, for checking.
    void raw_exact(std::span<const LidarReturn> returns, std::span<double> out) const;

private:
    // Returns false if the pruning bound is not met (out then holds the pruned sums).
    bool raw_pruned(std::span<const LidarReturn> returns, std::size_t n_bound, std::span<double> out) const;
    void raw_nearest_beam(std::span<const LidarReturn> returns, std::span<double> out) const;
    void normalise(std::span<double> out) const;
    static void check_return(const LidarReturn& r, std::size_t index);

    BvcParams p_;
    double c_r_, c_theta_, c_phi_;      // Gaussian normalisation constants 1/sqrt(2π σ²)
    double cut_r_, cut_theta_, cut_phi_;  // factor windows: exp(-x²/2σ²) >= tiny inside
    std::vector<double> dist_decay_;    // exp(-n²Δ²/2σ_r²), n = 0..n_per_axis-1, zero-padded
    // Scratch for one return (a layer is not shared between threads): its distance profile and
    // the (layer, direction) rows it feeds with their weights.
    mutable std::vector<double> profile_, weights_;
    mutable std::vector<double*> rows_;
};

}  // namespace bvc3d
