#include "bvc3d/experiment/replay.hpp"

#include "bvc3d/core/error.hpp"

namespace bvc3d {

ReplaySource recorded_source(std::shared_ptr<const recording::Recording> recording,
                             const RecordedReturnParams& params) {
    if (recording->size() < 2)
        throw InputError("recording '" + recording->name + "' has " + std::to_string(recording->size()) +
                         " scan; a replay needs at least 2");
    ReplaySource s;
    s.path = std::make_shared<TrajectorySpec>(recording_steps(*recording), recording->name);
    s.returns = std::make_shared<RecordedReturnsSpec>(std::move(recording), params);
    return s;
}

ReplaySource simulated_source(const WorldSpec& world, std::shared_ptr<const TrajectorySpec> path,
                              const LidarSpec& sensor, const RecordedReturnParams& params) {
    ReplaySource s;
    s.world = world;
    s.path = std::move(path);
    s.returns = std::make_shared<SimulatedReturnsSpec>(sensor, params);
    return s;
}

TrialConfig replay_trial(const ReplaySource& source, const ModelSpec& model, bool learn,
                         std::shared_ptr<const InitialWeights> weights, std::uint64_t seed) {
    TrialConfig t;
    t.world = source.world;
    t.agent = source.path;
    t.returns = source.returns;
    t.model = model;
    t.weights = std::move(weights);
    t.seed = seed;
    t.protocol.kind = learn ? Protocol::Kind::online : Protocol::Kind::explore_then_sample;
    t.protocol.explore_hours = 0;
    // Every step recorded: the phase ends a second after the last scan.
    t.protocol.sample_hours = (source.path->steps().back().t + 1.0) / 3600.0;
    t.protocol.record_bvc = true;
    t.validate();
    return t;
}

GroupResult run_replay(const std::vector<TrialConfig>& trials, const RunControl& control) {
    return run_trial_group(trials, control);
}

ReplayRates replay_rates(const GroupResult& result, std::size_t model, bool bvc) {
    const ModelRecord& m = result.models.at(model);
    const auto n = static_cast<Eigen::Index>(result.x.size());
    const int cells = bvc ? m.n_bvc : m.n_place;
    const std::vector<float>& data = bvc ? m.bvc : m.rates;
    if (data.size() != static_cast<std::size_t>(n) * static_cast<std::size_t>(cells))
        throw InputError(bvc ? "the replay did not record BVC rates" : "the replay has no place-cell rates");
    ReplayRates r;
    r.rates = Eigen::Map<const analysis::RowMatrixXf>(data.data(), n, cells);
    r.xyz.resize(n, 3);
    for (Eigen::Index i = 0; i < n; ++i) {
        r.xyz(i, 0) = result.x[static_cast<std::size_t>(i)];
        r.xyz(i, 1) = result.y[static_cast<std::size_t>(i)];
        r.xyz(i, 2) = result.z[static_cast<std::size_t>(i)];
    }
    return r;
}

}  // namespace bvc3d
