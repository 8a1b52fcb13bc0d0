// The population seam (docs/architecture.md#populations): a kind of cell the library does not know, written here and
// nowhere else, runs in a trial, is checkpointed, recorded, analysed and written to the trial file by the library's
// own runner, recorder and analysis, and changes nothing of the model it joins.
//
// Two test populations: `heading` echoes the agent's heading (cos, sin), reading nothing; `mean-place` reads the
// place cells and the heading and gives the mean place-cell rate, the heading's cosine again, and a count of the
// steps it has seen (a state that a checkpoint must carry).
#include <gtest/gtest.h>
#include <hdf5.h>

#include <cmath>
#include <filesystem>
#include <numeric>

#include "bvc3d/core/error.hpp"
#include "bvc3d/experiment/experiment.hpp"
#include "bvc3d/experiment/pipeline.hpp"
#include "bvc3d/experiment/trial_runner.hpp"

using namespace bvc3d;
namespace fs = std::filesystem;

namespace {

class EchoHeading : public Population {
public:
    std::size_t size() const override { return 2; }
    void step(const StepBlock& block, std::span<const std::span<const double>>, std::span<double> out) override {
        for (std::size_t s = 0; s < block.size(); ++s) {
            out[2 * s] = std::cos(block.steps[s].pose.heading);
            out[2 * s + 1] = std::sin(block.steps[s].pose.heading);
        }
    }
};

class MeanPlace : public Population {
public:
    explicit MeanPlace(std::size_t n_place) : n_place_(n_place) {}
    std::size_t size() const override { return 3; }
    void step(const StepBlock& block, std::span<const std::span<const double>> inputs, std::span<double> out) override {
        const auto place = inputs[0];
        const auto heading = inputs[1];
        for (std::size_t s = 0; s < block.size(); ++s) {
            const auto row = place.subspan(s * n_place_, n_place_);
            out[3 * s] = std::accumulate(row.begin(), row.end(), 0.0) / static_cast<double>(n_place_);
            out[3 * s + 1] = heading[2 * s];
            out[3 * s + 2] = static_cast<double>(++seen_);
        }
    }
    std::vector<StateArray> state() const override { return {{"seen", {1}, std::vector<double>{double(seen_)}}}; }
    void restore(const std::vector<StateArray>& arrays) override {
        seen_ = static_cast<std::int64_t>(state_doubles(arrays, "seen", 1)[0]);
    }
    std::vector<StateArray> kept() const override { return state(); }
    std::vector<std::pair<std::string, std::int64_t>> counters() const override { return {{"mean_place_seen", seen_}}; }

private:
    std::size_t n_place_;
    std::int64_t seen_ = 0;
};

PopulationSpec heading_spec() {
    PopulationSpec s;
    s.name = "heading";
    s.kind = "echo-heading";
    s.key = "kind: echo-heading";
    s.make = [](const PopulationContext&) { return std::make_unique<EchoHeading>(); };
    return s;
}

PopulationSpec mean_place_spec() {
    PopulationSpec s;
    s.name = "mean-place";
    s.kind = "mean-place";
    s.inputs = {"place", "heading"};
    s.key = "kind: mean-place";
    s.make = [](const PopulationContext& c) { return std::make_unique<MeanPlace>(c.input_sizes.at(0)); };
    return s;
}

TrialConfig trial(bool with_populations, double hours = 0.05) {
    TrialConfig t;
    t.world = WorldSpec{"cross", 45, "+x+y"};
    t.model = model_preset("3d-0.2");
    if (with_populations) t.model.populations = {heading_spec(), mean_place_spec()};
    t.seed = 3;
    t.protocol.explore_hours = t.protocol.sample_hours = hours;
    return t;
}

const PopulationRecord& population(const ModelRecord& m, const std::string& name) {
    for (const auto& p : m.populations)
        if (p.name == name) return p;
    throw std::runtime_error("no population " + name);
}

std::vector<float> read_floats(const fs::path& file, const std::string& dataset, std::vector<hsize_t>& dims) {
    const hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
    const hid_t d = H5Dopen2(f, dataset.c_str(), H5P_DEFAULT);
    const hid_t space = H5Dget_space(d);
    dims.assign(static_cast<std::size_t>(H5Sget_simple_extent_ndims(space)), 0);
    H5Sget_simple_extent_dims(space, dims.data(), nullptr);
    std::vector<float> v(static_cast<std::size_t>(H5Sget_simple_extent_npoints(space)));
    H5Dread(d, H5T_NATIVE_FLOAT, H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data());
    H5Sclose(space);
    H5Dclose(d);
    H5Fclose(f);
    return v;
}

bool exists(const fs::path& file, const std::string& object) {
    const hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
    const bool found = H5Lexists(f, object.c_str(), H5P_DEFAULT) > 0;
    H5Fclose(f);
    return found;
}

}  // namespace

TEST(PopulationSeam, ANewPopulationRunsBesideTheModelAndChangesNothingOfIt) {
    const GroupResult plain = run_trial_group({trial(false)});
    const GroupResult with = run_trial_group({trial(true)});
    ASSERT_EQ(with.t, plain.t);
    EXPECT_EQ(with.models[0].rates, plain.models[0].rates);
    EXPECT_EQ(with.models[0].weights, plain.models[0].weights);
    EXPECT_TRUE(plain.models[0].populations.empty());

    const std::size_t n = with.t.size();
    const ModelRecord& m = with.models[0];
    const auto& heading = population(m, "heading");
    const auto& mean = population(m, "mean-place");
    ASSERT_EQ(heading.rates.size(), 2 * n);
    ASSERT_EQ(mean.rates.size(), 3 * n);
    const auto n_place = static_cast<std::size_t>(m.n_place);
    for (std::size_t j = 0; j < n; ++j) {
        // Its inputs are the recorded heading and place-cell rates of the same step.
        EXPECT_FLOAT_EQ(heading.rates[2 * j], static_cast<float>(std::cos(with.heading[j]))) << j;
        EXPECT_FLOAT_EQ(heading.rates[2 * j + 1], static_cast<float>(std::sin(with.heading[j]))) << j;
        double sum = 0;
        for (std::size_t c = 0; c < n_place; ++c) sum += m.rates[j * n_place + c];
        EXPECT_NEAR(mean.rates[3 * j], sum / static_cast<double>(n_place), 1e-6) << j;
        EXPECT_EQ(mean.rates[3 * j + 1], heading.rates[2 * j]) << j;
        if (j > 0) {
            EXPECT_GT(mean.rates[3 * j + 2], mean.rates[3 * (j - 1) + 2]) << j;  // stepped every step
        }
    }
    // What it keeps at the end: its count of every step of the trial, exploration included.
    const auto seen = state_doubles(mean.kept, "seen", 1)[0];
    EXPECT_GE(seen, static_cast<double>(mean.rates[3 * (n - 1) + 2]));
    EXPECT_GT(seen, static_cast<double>(n));
}

TEST(PopulationSeam, CheckpointsCarryAPopulationsState) {
    const auto dir = fs::temp_directory_path() / ("bvc3d-seam-" + std::to_string(::getpid()));
    fs::remove_all(dir);
    fs::create_directories(dir);
    const std::vector<TrialConfig> group{trial(true, 0.1)};
    const GroupResult straight = run_trial_group(group);

    std::atomic<bool> stop{false};
    RunControl control;
    control.stop = &stop;
    control.checkpoint = dir / "group.h5";
    control.checkpoint_minutes = 3;
    control.progress = [&](double t, std::int64_t) {
        if (t > 0.13 * 3600) stop = true;  // during the sampling phase
    };
    EXPECT_THROW(run_trial_group(group, control), Interrupted);
    ASSERT_TRUE(fs::exists(control.checkpoint));
    stop = false;
    control.progress = nullptr;
    const GroupResult resumed = run_trial_group(group, control);
    for (const char* name : {"heading", "mean-place"}) {
        EXPECT_EQ(population(resumed.models[0], name).rates, population(straight.models[0], name).rates) << name;
        EXPECT_EQ(population(resumed.models[0], name).kept.size(), population(straight.models[0], name).kept.size());
    }
    EXPECT_EQ(state_doubles(population(resumed.models[0], "mean-place").kept, "seen", 1),
              state_doubles(population(straight.models[0], "mean-place").kept, "seen", 1));
    fs::remove_all(dir);
}

TEST(PopulationSeam, TheTrialFileHoldsItsRatesKeptArraysAndMetrics) {
    const auto dir = fs::temp_directory_path() / ("bvc3d-seam-file-" + std::to_string(::getpid()));
    fs::remove_all(dir);
    fs::create_directories(dir);
    const auto path = dir / "trial.h5";
    const GroupOutcome out = run_analyze_write({trial(true)}, {path});
    const std::size_t n = out.result.t.size();

    std::vector<hsize_t> dims;
    const auto rates = read_floats(path, "populations/heading/rates", dims);
    EXPECT_EQ(dims, (std::vector<hsize_t>{n, 2}));
    EXPECT_EQ(rates, population(out.result.models[0], "heading").rates);
    read_floats(path, "populations/mean-place/seen", dims);
    EXPECT_EQ(dims, (std::vector<hsize_t>{1}));
    // Analysed as the place cells are: a spatial map per cell. The heading's cells fire everywhere the agent faces
    // their way, so their maps are not place fields; the analysis says what it finds, it does not judge.
    EXPECT_TRUE(exists(path, "populations/heading/metrics"));
    ASSERT_EQ(out.trials[0].populations.size(), 2u);
    EXPECT_EQ(out.trials[0].populations[0].first, "heading");
    // The place cells' own metrics are those of the trial without the populations.
    const GroupOutcome plain = run_and_analyze({trial(false)});
    const auto a = metrics_record(out.trials[0].metrics, out.trials[0].params).scalars;
    const auto b = metrics_record(plain.trials[0].metrics, plain.trials[0].params).scalars;
    ASSERT_EQ(a.size(), b.size());
    for (std::size_t k = 0; k < a.size(); ++k) {
        EXPECT_EQ(a[k].first, b[k].first);
        EXPECT_TRUE(a[k].second == b[k].second || (std::isnan(a[k].second) && std::isnan(b[k].second))) << a[k].first;
    }
    fs::remove_all(dir);
}

TEST(PopulationSeam, InputsThatNameNoPopulationAreRefused) {
    TrialConfig t = trial(true);
    t.model.populations[1].inputs = {"place", "compass"};
    try {
        run_trial_group({t});
        FAIL() << "no error";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("'compass'"), std::string::npos) << e.what();
    }
    t = trial(true);
    std::swap(t.model.populations[0], t.model.populations[1]);  // mean-place before the heading it reads
    EXPECT_THROW(run_trial_group({t}), InputError);
    t = trial(true);
    t.model.populations[0].name = "place";
    EXPECT_THROW(run_trial_group({t}), InputError);
}
