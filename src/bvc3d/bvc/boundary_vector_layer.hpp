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
#include "bvc3d/core/aligned.hpp"
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
    double max_dist = 12.0;    // m
    double sigma_r = 0.75;     // m
    double sigma_theta = 0.1;  // rad
    double sigma_phi = 0.01;   // rad
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
        std::vector<char> rows;             // one flag per row of the sensor
        std::vector<double> skipped_rows;   // elevations of the rows not needed
        std::vector<double> skipped_bound;  // per layer: bound on their contribution to any cell
        std::size_t beams = 0;              // beams in the full table
        // Σ_columns c_θ·exp(-x²/2σ_θ²) over one row's columns, for any heading and direction, is at
        // most angular_sum (a unimodal function summed over a lattice); rows_per_label rows at most
        // carry the same elevation label.
        double angular_sum = 0;
        int rows_per_label = 1;
        std::size_t columns = 0;  // the sensor's columns per row
        bool skips(double elevation) const {
            return std::find(skipped_rows.begin(), skipped_rows.end(), elevation) != skipped_rows.end();
        }
    };
    ScanPlan plan(const LidarSpec& sensor) const;
    // Rates from a scan of the plan's sensor at a level pose, cast with plan.rows (returns of other
    // rows, e.g. cast for another model, are ignored): its truncation bound takes each row's angular
    // factors from the plan's lattice bound, so it needs no bookkeeping per return. Returns false,
    // leaving `out` unspecified, if the bound is not met: the caller then casts every row and calls
    // rates().
    bool rates_pruned(std::span<const LidarReturn> returns, const ScanPlan& plan, std::span<double> out) const;

    // Several models on one scan (an experiment's models sharing a walk): the layers' sums of one
    // (return, layer) pair do not depend on the other layers, so a layer whose parameters equal
    // this one's but for its elevations can read the sums of those it has from a layer that summed
    // their union once. sum_pruned sums (the union's side); rates_pruned_shared gives what
    // rates_pruned gives, the same bits and the same verdict of the truncation bound (which depends
    // on the scan's rows, not on the sums), reading the sums from `summed` (which must hold every
    // elevation of this layer and have summed the same scan).
    bool can_share_sums(const BvcParams& other) const;
    void sum_pruned(std::span<const LidarReturn> returns, const ScanPlan& plan) const;
    bool rates_pruned_shared(std::span<const LidarReturn> returns, const ScanPlan& plan,
                             const BoundaryVectorLayer& summed, std::span<double> out) const;

    // The full triple-Gaussian sum with no pruning: the definition itself, for checking.
    void raw_exact(std::span<const LidarReturn> returns, std::span<double> out) const;

private:
    // The pruned sums of `returns` into padded_, and the bookkeeping of the truncation bound: with a
    // plan (a beam table's scan), per run of returns of one row: its elevation, the returns counted
    // and those whose distance window is empty (runs_); without one (any point set), the exact
    // weights of every pruned term, return by return (kept_weight_ ...). Returns the returns counted.
    template <bool planned>
    std::size_t pruned_pass(std::span<const LidarReturn> returns, const ScanPlan* plan) const;
    // The pruned sums of any point set into out; false if the bound is not met.
    bool raw_pruned(std::span<const LidarReturn> returns, std::span<double> out) const;
    // This layer's elevation factors of a row at elevation phi: summed (elev_) and dropped (dropped_e_).
    void row_factors(double phi) const;
    // The bound on every pruned term of a cell: from the exact weights (no plan), or from `runs`
    // and the plan's lattice bound; `valid` returns counted.
    double pruned_bound(std::size_t valid) const;
    // The terms of one (layer, direction): kept and dropped weights Σ E·A, Σ E of returns that reach
    // the layer, Σ E of those whose window is empty; and the elevation factors below tiny_phi of
    // `returns` returns.
    double term_bound(double kept, double dropped, double weight, double far) const;
    double elevation_tail(std::size_t returns) const;
    struct Run {
        double elevation;
        std::size_t valid, far;
    };
    double planned_bound(const ScanPlan& plan, const std::vector<Run>& runs) const;
    // The rates from `summed`'s sums of a planned pass (this layer's own, or a union's), if this
    // layer's bound for that pass's runs is met.
    bool planned_rates(const ScanPlan& plan, const BoundaryVectorLayer& summed, std::span<double> out) const;
    // The runs of the last planned pass (sum_pruned's, for the layers reading its sums).
    mutable std::vector<Run> runs_;
    // The nearest_beam reading into `out` (zeroed by the caller). Pruned: only each direction's
    // distance window; returns false if what that drops is not below the pruning tolerance.
    bool raw_nearest_beam(std::span<const LidarReturn> returns, std::span<double> out, bool prune) const;
    void normalize(std::span<double> out, double largest) const;  // largest: the largest of out
    static void check_return(const LidarReturn& r, std::size_t index);

    BvcParams p_;
    double c_r_, c_theta_, c_phi_;                  // Gaussian normalization constants 1/sqrt(2π σ²)
    double cut_r_, cut_theta_, cut_phi_, cut_row_;  // factor windows: exp(-x²/2σ²) >= tiny inside
    std::vector<double> dist_decay_;                // exp(-n²Δ²/2σ_r²), n = 0..n_per_axis-1, zero-padded
    // The directions an azimuth reaches and their angular factors c_θ·exp(-x²/2σ_θ²): a pure
    // function of the azimuth, memoised in a direct-mapped table keyed by the azimuth's bits
    // (scanners repeat the same azimuths row after row, and step after step while the agent does not
    // turn). An azimuth reaches at most reach_ directions (3 with the defaults), so the record at
    // memo_weight_[s·(reach_ + 1) ...] = key, factors and memo_dir_[same] = count, directions, is
    // small. A NaN key never matches. Irregular point sets (real LiDAR) repeat no azimuth: the memo
    // would only evict useful cache lines, so their records go to the room after the slots, one per
    // return of a batch. The numbers are the same either way.
    //
    // The slot of an azimuth in (-π, π] is its position on the circle, in memo_slots_ equal parts:
    // a beam table's evenly spaced columns, fewer than the slots, never share one (as many, and
    // rounding could put two in one). A planned pass makes the slots twice the sensor's columns, so
    // that a row's records lie close together (a few cache lines, which stay in the L1 cache across
    // the rows of a scan).
    static constexpr std::size_t default_slots = 1024;
    mutable std::size_t memo_slots_ = 0;
    mutable double slot_scale_ = 0;  // memo_slots_ / 2π (kernels::read_returns gives each return its slot)
    void size_memo(std::size_t slots) const;
    int reach_ = 0;
    // The directions `azimuth` reaches and their angular factors; returns how many (at most reach_).
    int angular_weights(double azimuth, std::uint16_t* dir, double* weight) const;
    mutable std::vector<double> memo_weight_;
    mutable std::vector<std::uint16_t> memo_dir_;
    mutable std::vector<std::uint32_t> slot_batch_;  // the batch of jobs that last read each slot
    mutable std::uint32_t batch_ = 0;

    // The kernel's jobs, not yet added (n_jobs_), and the records of their own after the memo's slots
    // (n_direct_); flush_jobs adds them to row_sums_ (planned) or padded_.
    mutable std::size_t n_jobs_ = 0, n_direct_ = 0;
    template <bool planned>
    void flush_jobs() const;
    // A job evaluated cell by cell, for cells further apart than σ_r.
    template <bool planned>
    void add_profile_directly(const kernels::ProfileJob& job) const;
    // A scanner row's sums per direction, Σ A·D over its returns, padded like padded_'s axes; added
    // to each layer it feeds with that layer's elevation factor, then cleared.
    mutable std::vector<double, CacheAligned<double>> row_sums_;
    // The current row's kept layers: their elevation factors and first offsets in padded_.
    mutable std::vector<double> kept_elev_;
    mutable std::vector<std::size_t> kept_base_;
    void add_row_sums(int n_kept) const;

    // Scratch for one step (a layer is not shared between threads): the elevation factors of the
    // current row (summed, dropped, their sum) and which layers have them; a batch of returns'
    // distance profiles (jobs_) and the (layer, direction) rows each feeds, as offsets into padded_
    // and weights.
    mutable std::vector<double> elev_, dropped_e_, row_factor_;
    mutable std::vector<int> kept_layers_, any_layers_;
    mutable std::vector<kernels::ProfileJob> jobs_;
    mutable std::vector<double> exp_args_;
    // The first n_jobs jobs' a and b from their x0 and scale (two batched exps per return).
    void profile_factors(std::size_t n_jobs) const;
    mutable std::vector<double> kept_weight_, layer_weight_, far_weight_, dropped_weight_;  // truncation bound
    int axis_stride_ = 0;                                       // n_per_axis rounded up to 8
    mutable std::vector<double, CacheAligned<double>> padded_;  // sums with padded axes, blocks of 8 cache-aligned
    // This layer's sums (its layers as `from_layer` holds them, padded) into result.
    void copy_sums(const BoundaryVectorLayer& from_layer, std::span<double> result) const;
    // The first padded axis of the layer with `reader`'s layer l's elevation (shared sums).
    std::size_t first_axis(const BvcParams& reader, int l) const;
    std::vector<double> dir_angle_;                  // θ_k = k·2π/n_dir, NaN-padded to a multiple of 8
    mutable std::vector<std::int64_t> best_return_;  // nearest_beam reading: per direction
    mutable std::vector<double> best_gap_;
    mutable std::vector<double> near_azimuth_;  // ... the valid returns' azimuths and indices
    mutable std::vector<std::size_t> near_index_;
    mutable std::vector<std::size_t> cells_;  // ... its cells to evaluate and their exponents
    mutable std::vector<double> exponents_;
};

}  // namespace bvc3d
