#pragma once
// BVC stage: the fast path's workspace (private to the layer; public for the layer's own header). Takes: returns,
// and a scan plan when they are a beam table's scan. Gives: the sums raw_i of the equation in tuning.hpp with the
// terms that are all but zero left out, and what truncation_bound.hpp needs to bound them.
//
// Two passes:
// - planned (a beam table, row by row): each direction's sum of A·D over a scanner row's returns is formed once and
//   added to every layer the row feeds with that layer's E, so a return two layers read is summed once; the bound
//   takes each row's angular factors from the plan's lattice bound (no bookkeeping per return);
// - unplanned (any point set, whose elevations need not repeat): a return gets a job per layer it feeds, its
//   profile scaled by that layer's E, and the exact weights of every term it drops are summed for the bound.
// Each return's distance profile D(r − d_m) over its window of cells is a job for the vector kernel
// (bvc_kernels.hpp): a·b^n·decay[n], the Gaussian written as a recurrence over the evenly spaced d_m; its
// directions and angular factors A come from a memo keyed by the azimuth (scanners repeat the same azimuths row after
// row, and step after step while the agent does not turn).
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "bvc3d/bvc/bvc_kernels.hpp"
#include "bvc3d/bvc/profile_job.hpp"
#include "bvc3d/bvc/scan_plan.hpp"
#include "bvc3d/bvc/truncation_bound.hpp"
#include "bvc3d/bvc/tuning.hpp"
#include "bvc3d/core/aligned.hpp"
#include "bvc3d/sensor/lidar.hpp"

namespace bvc3d {

class PrunedSums {
public:
    explicit PrunedSums(const LayerTuning& tuning);

    // Any point set: returns the valid returns counted; weights() then holds what was dropped.
    std::size_t sum_unplanned(std::span<const LidarReturn> returns);
    // A scan of plan's sensor cast with plan.rows (returns of other rows are ignored); runs() then holds its rows.
    void sum_planned(std::span<const LidarReturn> returns, const ScanPlan& plan);

    const pruning::PrunedWeights& weights() const { return weights_; }
    std::span<const pruning::Run> runs() const { return runs_; }
    // The sums of the last pass, for the layers of `reader` (each of whose elevations the summed layer has, at the
    // same position when `same_layer`) in reader's cell order.
    void copy_sums(const BvcParams& reader, bool same_layer, std::span<double> out) const;

private:
    LayerTuning t_;
    const pruning::Windows win_;
    int axis_stride_ = 0;  // n_per_axis rounded up to 8
    bool recurrence_ = false;
    std::vector<double> dist_decay_;  // exp(-n²Δ²/2σ_r²), n = 0..n_per_axis-1, zero-padded to the stride
    // Sums with axes padded to whole blocks of 8 cells, 64-byte aligned: the kernel needs no scalar tail, and each
    // block is one cache line.
    std::vector<double, CacheAligned<double>> padded_;
    // Planned: the current scanner row's Σ A·D per direction, padded like padded_'s axes.
    std::vector<double, CacheAligned<double>> row_sums_;

    // The current row's elevation factors per layer (summed, dropped, both) and the layers that have them.
    struct Row {
        std::vector<double> kept, dropped;
        std::vector<int> kept_layers, any_layers;
        std::vector<std::size_t> kept_base;  // first offset in padded_ of each kept layer
        std::vector<double> kept_elev;       // ... and its E
        int n_kept = 0, n_any = 0;
    } row_;
    void enter_row(double phi);

    // The azimuth memo: a direct-mapped table of records keyed by the azimuth's bits, slot = the azimuth's position
    // on the circle in memo_slots_ equal parts. A record at memo_weight_[s·(reach_ + 1) ...] is the key and the
    // factors, at memo_dir_[same] the count and the directions: an azimuth reaches at most reach_ directions (3 with
    // the defaults). A NaN key never matches. Irregular point sets (real LiDAR) repeat no azimuth: their records go to
    // the room after the slots, one per return of a batch. A planned pass makes the slots twice the sensor's columns,
    // so that a row's records lie close together (they stay in the L1 cache across a scan's rows); evenly spaced
    // columns, fewer than the slots, never share one. The numbers are the same either way.
    static constexpr std::size_t default_slots = 1024;
    std::size_t memo_slots_ = 0;
    double slot_scale_ = 0;  // memo_slots_ / 2π
    int reach_ = 0;
    std::vector<double> memo_weight_;
    std::vector<std::uint16_t> memo_dir_;
    std::vector<std::uint32_t> slot_batch_;  // the batch of jobs that last read each slot
    std::uint32_t batch_ = 0;
    void size_memo(std::size_t slots);
    // The directions `azimuth` reaches and their factors A into dir/weight; returns how many.
    int angular_weights(double azimuth, std::uint16_t* dir, double* weight) const;
    // The record of the q-th reading's azimuth: its memo slot's, or one of its own after the slots (a record stays
    // as it is while a waiting job reads it). May flush the jobs into `sums` to free the room.
    std::size_t record_of(std::size_t q, bool use_memo, double* sums);

    // The kernel's jobs not yet added (n_jobs_) and the records of their own after the slots (n_direct_).
    std::vector<kernels::ProfileJob> jobs_;
    std::vector<double> exp_args_;
    std::size_t n_jobs_ = 0, n_direct_ = 0;
    void add_job(const kernels::ProfileJob& job, double* sums);
    void flush_jobs(double* sums);
    void profile_factors(std::size_t n_jobs);  // a and b of the first n_jobs jobs from their x0 and scale
    void add_profile_directly(const kernels::ProfileJob& job, double* sums) const;
    void add_row_sums();  // row_sums_ into each kept layer of the row, times its E; then cleared

    // Each return's readings (kernels::read_returns), 64 at a time.
    kernels::ReturnReadings in_;
    kernels::ReturnRule rule_{};
    // Zeroes the sums and readies the memo; returns whether the memo is used (not for irregular point sets).
    bool begin_pass(std::span<const LidarReturn> returns, const ScanPlan* plan);
    // visit(return, q) for each return that is not absent, q its readings' index in in_.
    template <class Visit>
    void for_each_return(std::span<const LidarReturn> returns, Visit&& visit);

    pruning::PrunedWeights weights_;
    std::vector<pruning::Run> runs_;
};

}  // namespace bvc3d
