#pragma once
// Trial files: one HDF5 file per trial with the trial's identity and configuration as attributes,
// the recorded samples, the trained weights and the metrics (layout: docs/trial-files.md).
// Takes: a GroupResult, the trial's identity and its metrics as named values and arrays (the
// recorder does not interpret them). Gives: files, and what they hold read back.
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "bvc3d/core/params.hpp"
#include "bvc3d/recorder/trial_record.hpp"

namespace bvc3d {

// Version 1: ground trials (x, y; z only when some sample has z != 0). Version 2: trials of flying
// agents (3-D positions: samples/z always, /metrics/volume). A file keeps the lowest version that
// holds its trial, so ground trials' files are as they always were. Readers refuse other versions.
inline constexpr int trial_file_format_version = 2;
inline constexpr int trial_file_format_version_2d = 1;
// The version a trial of positions with `dims` coordinates is written with.
inline int trial_file_version_for(int dims) {
    return dims == 3 ? trial_file_format_version : trial_file_format_version_2d;
}

// Which trial a file holds and how it was configured (the root attributes).
struct TrialIdentity {
    std::string name, condition, world, world_source, model, sensor, protocol, config, fingerprint;
    // The model's canonical text (config/model_yaml.hpp), recorded with the weights it trained, so
    // that loading them into another model is refused (an empty text records nothing).
    std::string model_config;
    // What the place cells' weights are (attribute `place_weights`; "" in older files): "learned" (Oja's
    // rule ran in the trial), "trained" (frozen, from `place_weights_source`, a trial file or an array)
    // or "untrained" (frozen at the seed's random draw: the place-cell metrics would mean nothing and
    // are not written).
    std::string place_weights, place_weights_source;
    std::vector<std::pair<std::string, std::string>> swept;  // the condition's defining values
    std::uint64_t seed = 0;
    double tilt_deg = NAN;  // cross arenas only
    double explore_hours = NAN, sample_hours = NAN;
    int dims = 2;  // coordinates of the analyzed positions: 2, or 3 for flying agents
    // Where the returns came from when not from the world (a replayed recording: its name and
    // files), written as text attributes of these names when present.
    std::vector<std::pair<std::string, std::string>> data_source;
};

// A named array of a trial file, row-major with the given shape.
struct NamedArray {
    std::string name;
    std::vector<std::size_t> shape;
    std::variant<std::vector<double>, std::vector<float>, std::vector<std::int64_t>> data;
    bool compress = true;
};

// The /metrics group: scalar metrics and the parameters they were computed with (attributes, in
// this order), and per-bin or per-cell arrays.
struct MetricsRecord {
    std::vector<std::pair<std::string, double>> scalars;
    std::vector<std::pair<std::string, params::Value>> parameters;
    std::vector<NamedArray> arrays;
};

// Writes the file atomically: it appears only when complete. z is written for 3-D trials (id.dims 3)
// and when any sample has z != 0. The model's other populations go to /populations/NAME/ with their metrics
// (population_metrics: by population name).
void write_trial_file(const std::filesystem::path& path, const TrialIdentity& id, const GroupResult& group,
                      std::size_t model_index, const MetricsRecord& metrics,
                      const std::vector<std::pair<std::string, MetricsRecord>>& population_metrics = {});

// A complete trial file's fingerprint and the names of the attributes under /metrics (the metrics
// it holds, with their parameters); nullopt if the file is missing, broken or not a trial file.
// InputError for a trial file of a format version this build does not know (a newer bvc3d's).
struct TrialStamp {
    std::string fingerprint;
    std::vector<std::string> metric_attributes;
    bool navigation = false;  // it holds /navigation (a navigation trial's episodes)
};
std::optional<TrialStamp> read_trial_stamp(const std::filesystem::path& path);
// Whether `path` is a trial file (an HDF5 file whose root says format bvc3d-trial), whole or not.
bool is_trial_file(const std::filesystem::path& path);

// What `bvc3d analyze` reads back. Reading checks what it reads: errors (InputError) name the file
// and the dataset or attribute — missing, of the wrong type or shape, non-finite positions or rates,
// a format_version this code does not read.
struct TrialFileData : TrialIdentity {
    std::vector<std::pair<std::string, params::Value>> metric_attributes;  // everything under /metrics
    std::optional<std::vector<double>> extent;                             // /metrics/extent, if fixed
    std::optional<std::vector<double>> volume;                             // /metrics/volume (3-D trials)
    std::vector<double> x, y, z;                                           // z empty for ground trials
    std::vector<float> rates;                                              // samples × n_place
    std::size_t n_place = 0;
};
TrialFileData read_trial_samples(const std::filesystem::path& path);  // throws InputError

// The recorded samples' positions and one kind of rates: place-cell rates (`rates`) or BVC rates
// (`bvc_rates`, present when the trial recorded them; InputError naming the file otherwise).
struct TrialRates {
    std::vector<double> t, x, y, z, heading;  // z all 0 for ground trials
    std::vector<float> rates;                 // samples × cells
    std::size_t n_cells = 0;
};
TrialRates read_trial_rates(const std::filesystem::path& path, bool bvc);

// The trained weights (n_place × n_bvc, row-major) of a trial file, and the model that trained them
// (its name and canonical text, attributes `model` and `model_config` of /weights; empty in files
// written before bvc3d recorded them).
struct TrialWeights {
    std::vector<float> values;
    std::size_t n_place = 0, n_bvc = 0;
    std::string model, model_config;
};
TrialWeights read_trial_weights(const std::filesystem::path& path);
// Any dataset of a trial file by its path inside the file ("samples/heading", "metrics/sai",
// "weights"), as stored: float64, float32, or int64 for integers. nullopt when the file lacks it;
// InputError when the file is missing, broken or not a trial file, or the dataset holds neither
// numbers nor integers. For readers that show a file (`bvc3d view`), not for the analysis.
std::optional<NamedArray> read_trial_array(const std::filesystem::path& path, const std::string& dataset);

// A navigation trial's /navigation group, checked as it is read (InputError naming the file and the dataset: missing,
// of the wrong shape, non-finite numbers, indices out of range); with the trial's identity.
struct TrialNavigation : TrialIdentity {
    NavigationRecord record;
};
TrialNavigation read_trial_navigation(const std::filesystem::path& path);

// The named scalar metrics of a file, for summaries; a metric the file lacks (written before it
// existed) reads as NaN. `parameters`: the named /metrics attributes (the analysis parameters) as
// text, "(not recorded)" where missing, and last `extent` ("data" or the fixed bounds).
struct TrialSummaryRow : TrialIdentity {
    std::vector<std::pair<std::string, double>> metrics;
    std::vector<std::pair<std::string, std::string>> parameters;
};
TrialSummaryRow read_trial_summary(const std::filesystem::path& path, const std::vector<std::string>& metric_names,
                                   const std::vector<std::string>& parameter_names = {});

}  // namespace bvc3d
