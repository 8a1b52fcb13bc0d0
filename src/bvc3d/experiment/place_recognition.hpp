#pragma once
// Place recognition over a sequence of scans (docs/place-recognition.md): every descriptor of the
// one list below describes every scan, then the protocol (sequential loop closure or a
// database/query split) finds each query's best match and scores it.
// Takes: a scan sequence (recording or simulated route), descriptors by name, options. Gives: per
// descriptor the rows of every query, the precision-recall curve, the summary and the time spent.
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "bvc3d/analysis/place_recognition.hpp"
#include "bvc3d/bvc/scan_context.hpp"
#include "bvc3d/config/model_spec.hpp"
#include "bvc3d/experiment/scan_sequence.hpp"
#include "bvc3d/sensor/recorded_returns.hpp"

namespace bvc3d {

// How a descriptor sees a scan's azimuths.
enum class HeadingUse {
    none,     // egocentric and rotation-invariant by its search (Scan Context)
    pose,     // the pose's heading: allocentric BVC rates, as the model defines them
    drifted,  // the pose's heading plus a seeded random-walk drift (odometry's heading)
    free,     // no heading: rates in the sensor's level frame, matched over the BVC directions' turns
};

// The kinds of descriptor: the one list (help texts, errors and docs read it).
struct DescriptorKind {
    std::string name;  // what --descriptors names: "bvc", "scan-context", ...
    bool takes_model = false;
    bool learns = false;  // place cells learning online along the sequence
    HeadingUse heading = HeadingUse::none;
    std::string description;
};
const std::vector<DescriptorKind>& descriptor_kinds();

struct DescriptorSpec {
    std::string label;  // "bvc:2d", "scan-context": the kind and the model's name
    const DescriptorKind* kind = nullptr;
    std::optional<ModelSpec> model;
    bool uses_heading() const { return kind->heading == HeadingUse::pose || kind->heading == HeadingUse::drifted; }
};
// "KIND" or "KIND:MODEL" (a preset or a model YAML, labelled by its name); InputError naming the
// unknown kind or model.
DescriptorSpec parse_descriptor(const std::string& text);
// A comma-separated list; InputError when empty or when two descriptors have the same label.
std::vector<DescriptorSpec> parse_descriptors(const std::string& list);

struct PlaceRecognitionOptions {
    analysis::LoopClosureParams loop;
    // Database and query spans: the split protocol; none: sequential loop closure.
    std::optional<analysis::ScanSpan> database, queries;
    RecordedReturnParams preprocess;  // how BVC models read a scan's points, as replays read them
    ScanContextParams scan_context;
    double drift_deg_per_sqrt_min = 1.0;  // the drifting heading's random walk: SD after one minute
    std::uint64_t seed = 0;               // the drift and the place cells' initial weights
    int threads = 0;                      // 0: every core
    std::function<void(std::size_t done, std::size_t total)> progress;  // scans described so far

    void validate() const;  // InputError naming the bad value
};

struct DescriptorOutcome {
    DescriptorSpec spec;
    analysis::PlaceRecognitionResult result;
    double describe_seconds = 0;  // thread time spent describing the scans (reading them apart)
    double search_seconds = 0;    // wall time of the search and the metrics
};

struct PlaceRecognitionOutcome {
    std::string sequence, protocol;
    analysis::Points positions;   // x, y, z of every scan
    std::vector<double> heading;  // the pose's heading of every scan, rad
    std::vector<double> times;    // every scan's time, s (scan_times)
    bool timed = true;            // every scan has a time of its own (else `times` counts one scan a second)
    std::vector<double> drift;    // the drifting descriptors' heading error of every scan, rad
    std::vector<DescriptorOutcome> descriptors;
    double read_seconds = 0;  // thread time spent reading (or simulating) the scans, summed over the threads
    double describe_wall_seconds = 0;
    std::size_t threads = 1;  // the threads that read and described the scans
};

// Each scan's time: the sequence's when every scan has one, else one scan a second (as replays count).
std::vector<double> scan_times(const ScanSequence& sequence);
// Whether every scan of the sequence has a time.
bool has_times(const ScanSequence& sequence);
// Which scans query which (the split when options name one, else the sequential windows, on the
// scans' own times when they all have one): InputError for bad spans and windows, before any scan is read.
analysis::QueryPlan query_plan(const ScanSequence& sequence, const PlaceRecognitionOptions& options);

PlaceRecognitionOutcome run_place_recognition(const ScanSequence& sequence,
                                              const std::vector<DescriptorSpec>& descriptors,
                                              const PlaceRecognitionOptions& options);

// The heading drift: δ_0 = 0, δ_i = δ_{i-1} + N(0, σ²·(t_i − t_{i-1}) / 60 s), σ in rad per √min,
// from the seed's own stream. Times in seconds, increasing.
std::vector<double> heading_drift(const std::vector<double>& times, double sigma_per_sqrt_min, std::uint64_t seed);

// Rates of a BVC population turned by `steps` azimuth steps: the value of cell (l, k, m) moves to
// (l, (k + steps) mod n_dir, m), index (l·n_dir + k)·n_per_axis + m (what the heading-free match
// compares: the scene turned by steps·2π/n_dir).
std::vector<float> turn_bvc_rates(std::span<const float> rates, int n_dir, int n_per_axis, int steps);

}  // namespace bvc3d
