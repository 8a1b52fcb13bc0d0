#pragma once
// BVC stage (docs/model-reference.md#boundary-vector-cells): boundary vector cells tuned to
// distance, allocentric azimuth and elevation.
// Takes: LiDAR returns (range, azimuth, elevation), from a beam table or any point set. Gives: one
// rate per cell, cell i = (l, k, m) at index (l·n_dir + k)·n_per_axis + m, for preferred elevation
// psi_l, azimuth theta_k = 2πk/n_dir and distance d_m = m·max_dist/(n_per_axis - 1).
#include <algorithm>
#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "bvc3d/bvc/profile_job.hpp"
#include "bvc3d/core/params.hpp"
#include "bvc3d/sensor/lidar.hpp"

namespace bvc3d {

enum class BvcNormalization { per_step_max, none, fixed };

// How a direction reads the scan: the paper's Gaussian over all returns (eq. 1-2), or the single
// return nearest to theta_k with no angular or elevation factor (the authors' code; `2d-8beam`).
enum class BvcReading { gaussian, nearest_beam };

// Defaults: the paper's σs and spacing; the layers of its `3d-0.2` model (the default model).
struct BvcParams {
    std::vector<double> elevations{0.0, 0.2};  // psi_l in radians; empty: the 2-D model (no elevation factor)
    int n_dir = 8;
    int n_per_axis = 60;
    double max_dist = 12.0;     // m
    double sigma_r = 0.75;      // m
    double sigma_theta = 0.1;   // rad
    double sigma_phi = 0.01;    // rad
    BvcNormalization normalization = BvcNormalization::per_step_max;
    double norm_constant = 1.0;  // `fixed`: rate = raw / norm_constant
    BvcReading reading = BvcReading::gaussian;

    // At most this many cells (layers × n_dir × n_per_axis): beyond it a layer is a mistake, and its
    // weights and rates would not fit in memory.
    static constexpr double max_cells = 1e6;

    int n_layers() const { return elevations.empty() ? 1 : static_cast<int>(elevations.size()); }
    int n_cells() const { return n_layers() * n_dir * n_per_axis; }
    double spacing() const { return n_per_axis > 1 ? max_dist / (n_per_axis - 1) : 0.0; }
    static const params::Table<BvcParams>& table();
    void validate() const;  // throws params::ParamError naming the bad parameter
};

class BoundaryVectorLayer {
public:
    explicit BoundaryVectorLayer(BvcParams params);

    const BvcParams& params() const { return p_; }
    std::size_t n_cells() const { return static_cast<std::size_t>(p_.n_cells()); }

    // Input hygiene: a return whose range is NaN or +inf means "no return" and is skipped; a
    // negative range, -inf, or a non-finite angle throws InputError naming the return.
    //
    // Unnormalized sums raw_i (docs/model-reference.md#rates), to within 1e-7 of the largest raw_i:
    // terms whose factors are all but zero are pruned, and a per-step bound on what was pruned is
    // checked; when it is not small enough the full sum is computed instead.
    void raw(std::span<const LidarReturn> returns, std::span<double> out) const;
    // Normalized rates (per_step_max: raw / (2·max raw), so the largest is exactly 0.5).
    void rates(std::span<const LidarReturn> returns, std::span<double> out) const;

    // Which rows of a scanner's beam table this layer needs: rows[i] = 0 for a row whose weight is
    // negligible for every layer, so the scanner need not cast it. What the skipped rows could have
    // added is bounded in advance from the beam table (its columns are evenly spaced in azimuth).
    struct ScanPlan {
        std::vector<char> rows;              // one flag per row of the sensor
        std::vector<double> skipped_rows;    // elevations of the rows not needed
        std::vector<double> skipped_bound;   // per layer: bound on their contribution to any cell
        std::size_t beams = 0;               // beams in the full table
        bool skips(double elevation) const {
            return std::find(skipped_rows.begin(), skipped_rows.end(), elevation) != skipped_rows.end();
        }
    };
    ScanPlan plan(const LidarSpec& sensor) const;
    // Rates from a scan cast with plan.rows (returns of other rows, e.g. cast for another model,
    // are ignored). Returns false, leaving `out` unspecified, if the truncation bound is not met:
    // the caller then casts every row and calls rates().
    bool rates_pruned(std::span<const LidarReturn> returns, const ScanPlan& plan, std::span<double> out) const;

    // Several models on one scan (an experiment's models sharing a walk): the layers' sums of one
    // (return, layer) pair do not depend on the other layers, so a layer whose parameters equal
    // this one's but for its elevations can read the sums of those it has from a layer that summed
    // their union once. sum_pruned sums (the union's side); rates_pruned_shared gives what
    // rates_pruned gives, the same bits and its own truncation bound, reading the sums from
    // `summed` (which must hold every elevation of this layer and have summed the same scan).
    bool can_share_sums(const BvcParams& other) const;
    void sum_pruned(std::span<const LidarReturn> returns, const ScanPlan& plan) const;
    bool rates_pruned_shared(std::span<const LidarReturn> returns, const ScanPlan& plan,
                             const BoundaryVectorLayer& summed, std::span<double> out) const;

    // The full triple-Gaussian sum with no pruning: the definition itself, for checking.
    void raw_exact(std::span<const LidarReturn> returns, std::span<double> out) const;

private:
    // What raw_pruned does: `own` sums and checks its bound (returns false if the bound is not met;
    // out then holds the pruned sums); `sums` only sums, into padded_, and keeps row totals
    // (sum_pruned); `bound` only does the bound's bookkeeping, reading the sums from `summed`.
    enum class Pass { own, sums, bound };
    bool raw_pruned(std::span<const LidarReturn> returns, const ScanPlan* plan, std::span<double> out,
                    Pass pass = Pass::own, const BoundaryVectorLayer* summed = nullptr) const;
    template <Pass pass>
    bool pruned_pass(std::span<const LidarReturn> returns, const ScanPlan* plan, std::span<double> out,
                     const BoundaryVectorLayer* summed) const;
    // The truncation bound's sums (per layer and direction: kept and dropped weights; per layer:
    // weights and empty-window weights) from `summed`'s row totals, as this layer's own pass would
    // add them return by return, and the returns counted; false if summed kept none.
    bool bound_sums_from_rows(const ScanPlan& plan, const BoundaryVectorLayer& summed, std::size_t& valid) const;
    // This layer's elevation factors of a row at elevation phi: summed (elev_) and dropped (dropped_e_).
    void row_factors(double phi) const;
    // The bound sums back to zero, and every pruned term's bound from them (`valid` returns counted).
    void clear_bound_sums() const;
    double pruned_bound(const ScanPlan* plan, std::size_t valid) const;
    // Row totals of the last `sums` pass, per scanner row: its elevation, returns counted, returns with an empty
    // distance window, and in row_angles_ per direction Σ angular factors of the returns with a window, then of all.
    struct RowTotal {
        double elevation;
        std::size_t valid, far;
    };
    mutable std::vector<RowTotal> row_totals_;
    mutable std::vector<double> row_angles_;
    mutable bool rows_complete_ = false;  // false: too many rows (an irregular point set) to keep
    // The nearest_beam reading into `out` (zeroed by the caller). Pruned: only each direction's
    // distance window; returns false if what that drops is not below the pruning tolerance.
    bool raw_nearest_beam(std::span<const LidarReturn> returns, std::span<double> out, bool prune) const;
    void normalize(std::span<double> out) const;
    static void check_return(const LidarReturn& r, std::size_t index);

    BvcParams p_;
    double c_r_, c_theta_, c_phi_;      // Gaussian normalization constants 1/sqrt(2π σ²)
    double cut_r_, cut_theta_, cut_phi_, cut_row_;  // factor windows: exp(-x²/2σ²) >= tiny inside
    std::vector<double> dist_decay_;    // exp(-n²Δ²/2σ_r²), n = 0..n_per_axis-1, zero-padded
    // The directions an azimuth reaches and their angular factors c_θ·exp(-x²/2σ_θ²): a pure
    // function of the azimuth, memoised in a direct-mapped table keyed by the azimuth's bits
    // (scanners repeat the same azimuths row after row, and step after step while the agent does not
    // turn). Slot s is memo_weight_[s·(n_dir + 1) ...] = key, factors and memo_dir_[same] = count,
    // directions: two cache lines a lookup. A NaN key never matches.
    static constexpr std::size_t cache_slots = 1024;
    // The slot for `azimuth` in (-π, π]: its position on the circle, so a beam table's evenly spaced
    // columns (up to cache_slots of them) never share a slot. A hit is an add, a multiply and a
    // compare; a miss fills the slot.
    static std::size_t slot_of(double azimuth) {
        const auto s = static_cast<std::size_t>((azimuth + 3.14159265358979323846) * (cache_slots / 6.283185307179586477));
        return s < cache_slots ? s : cache_slots - 1;
    }
    // The directions `azimuth` reaches and their angular factors; returns how many.
    int angular_weights(double azimuth, int* dir, double* weight) const;
    mutable std::vector<double> memo_weight_;
    mutable std::vector<int> memo_dir_;
    // Irregular point sets (real LiDAR) repeat no azimuth: the memo would only evict useful cache
    // lines, so their factors are computed directly (into direct_*). The numbers are the same.
    mutable std::vector<int> direct_dir_;
    mutable std::vector<double> direct_weight_;

    // Scratch for one step (a layer is not shared between threads): the elevation factors of the
    // current row (summed, dropped, their sum) and which layers have them; a batch of returns'
    // distance profiles (jobs_) and the (layer, direction) rows each feeds, as offsets into padded_
    // and weights.
    mutable std::vector<double> elev_, dropped_e_, row_factor_;
    mutable std::vector<int> kept_layers_, any_layers_;
    mutable std::vector<kernels::ProfileJob> jobs_;
    mutable std::vector<std::uint32_t> job_offset_;
    mutable std::vector<double> job_weight_;
    mutable std::vector<double> kept_weight_, layer_weight_, far_weight_, dropped_weight_;  // truncation bound
    int axis_stride_ = 0;                 // n_per_axis rounded up to 8, plus 8
    mutable std::vector<double> padded_;  // sums with padded axes
    // This layer's sums (its layers as `from_layer` holds them, padded) into result.
    void copy_sums(const BoundaryVectorLayer& from_layer, std::span<double> result) const;
    // The first padded axis of the layer with `reader`'s layer l's elevation (shared sums).
    std::size_t first_axis(const BvcParams& reader, int l) const;
    mutable std::vector<std::size_t> best_return_;  // nearest_beam reading
    mutable std::vector<double> best_gap_;
};

}  // namespace bvc3d
