#include "bvc3d/experiment/elevation_chooser.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <mutex>
#include <numbers>
#include <optional>
#include <thread>

#include "bvc3d/agent/trajectory.hpp"
#include "bvc3d/analysis/trial_metrics.hpp"
#include "bvc3d/core/cancel.hpp"
#include "bvc3d/core/error.hpp"
#include "bvc3d/core/format.hpp"
#include "bvc3d/core/parallel.hpp"
#include "bvc3d/core/random.hpp"
#include "bvc3d/experiment/pipeline.hpp"

namespace bvc3d {

namespace {

// A source read twice over: step n of the second pass reads walk step n again, so both passes see
// the same scans (and the same sensor noise).
class TwoPassSource : public ReturnSource {
public:
    TwoPassSource(std::shared_ptr<ReturnSource> inner, std::uint64_t walk_steps)
        : inner_(std::move(inner)), walk_steps_(walk_steps) {}
    const LidarSpec* beam_table() const override { return inner_->beam_table(); }
    void returns(std::uint64_t step, const Pose& pose, const std::vector<char>& rows, Scan& out) override {
        inner_->returns(step % walk_steps_, pose, rows, out);
    }

private:
    std::shared_ptr<ReturnSource> inner_;
    std::uint64_t walk_steps_;
};

// One factory per worker thread: each distinct inner source is wrapped once, so models that share
// it still share one scan per step.
SourceFactory replay_factory(const SourceFactory& inner, std::uint64_t walk_steps, std::uint64_t noise_seed) {
    auto wrapped =
        std::make_shared<std::vector<std::pair<std::shared_ptr<ReturnSource>, std::shared_ptr<ReturnSource>>>>();
    return [=](const ModelSpec& model, const World* world) -> std::shared_ptr<ReturnSource> {
        std::shared_ptr<ReturnSource> made = inner ? inner(model, world) : nullptr;
        for (const auto& [from, replay] : *wrapped) {
            const LidarSpec* table = from->beam_table();
            if (made ? from == made : table && table->same_beams(model.sensor)) return replay;
        }
        if (!made) {
            if (!world) throw InputError("choosing elevations needs a world to cast rays in");
            made = std::make_shared<RayCastSource>(*world, model.sensor, noise_seed);
        }
        auto replay = std::make_shared<TwoPassSource>(made, walk_steps);
        wrapped->emplace_back(made, replay);
        return replay;
    };
}

// The walk, then the walk again: the agent the candidates' trials run on.
std::shared_ptr<const AgentSpec> two_passes(const std::vector<ModelStep>& walk, int dims) {
    std::vector<ModelStep> steps;
    steps.reserve(2 * walk.size());
    const double t0 = walk.front().t;
    const double period = walk.back().t - t0 + (walk.back().t - walk[walk.size() - 2].t);
    for (int pass = 0; pass < 2; ++pass)
        for (ModelStep s : walk) {
            s.t = s.t - t0 + pass * period;
            steps.push_back(s);
        }
    return std::make_shared<TrajectorySpec>(std::move(steps), "exploratory walk, two passes", dims);
}

// Learning through the first pass exactly: the runner hands out a step while the last one ended
// before the phase's end, so the phase ends between the first pass's last two steps.
Protocol two_pass_protocol(const std::vector<ModelStep>& walk) {
    const double last = walk.back().t - walk.front().t;
    const double before = walk[walk.size() - 2].t - walk.front().t;
    Protocol p;
    p.explore_hours = 0.5 * (last + before) / 3600.0;
    p.sample_hours = 2.0 * (last + 1.0) / 3600.0;  // past the second pass's end: the path runs out first
    return p;
}

// MSAI of the BVC population: its rate maps on the place cells' bins, thresholded and normalized as
// theirs are, then the same aliasing index.
double bvc_aliasing(const GroupResult& r, std::size_t model, int dims, const analysis::TrialMetrics& m,
                    const analysis::AnalysisParams& p) {
    const auto& rec = r.models.at(model);
    const Eigen::Map<const analysis::RowMatrixXf> bvc(rec.bvc.data(), static_cast<Eigen::Index>(r.x.size()), rec.n_bvc);
    const auto maps = analysis::rate_maps<float>(m.maps.grid, sample_positions(r, dims), bvc, p.quantile);
    return analysis::spatial_aliasing(maps.bins.centers, maps.map, p.d_th, static_cast<std::size_t>(p.msai_bins)).msai;
}

// A candidate's trial analyzed as any trial is (2-D bins or, for a flying agent, the flight volume's voxels).
CandidateScore score(const World* world, const GroupResult& r, std::size_t model, const TrialConfig& trial) {
    static const WorldDescription none;
    const auto analyzed = analyze(trial, world ? world->description() : none, r, model);
    const auto& m = analyzed.metrics;
    CandidateScore s;
    s.elevations = trial.model.bvc.elevations;
    s.n_per_axis = trial.model.bvc.n_per_axis;
    s.msai = m.aliasing.msai;
    s.frac_multimodal = m.modality_summary.frac_multimodal;
    s.bvc_msai = bvc_aliasing(r, model, trial.agent->dims(), m, analyzed.params);
    return s;
}

// The lowest criterion; NaN (no bins) never wins, ties go to the first.
std::size_t best_of(const std::vector<CandidateScore>& scores) {
    std::size_t best = 0;
    for (std::size_t i = 0; i < scores.size(); ++i)
        if (std::isnan(scores[best].msai) || scores[i].msai < scores[best].msai) best = i;
    return best;
}

}  // namespace

const params::Table<ChooserParams>& ChooserParams::table() {
    using namespace params;
    static const Table<ChooserParams> t(
        "elevation chooser",
        {integer("budget", &ChooserParams::budget, at_least(1), "BVCs shared by the layers"),
         integer("min_layers", &ChooserParams::min_layers, at_least(1), "fewest layers the search returns"),
         integer("max_layers", &ChooserParams::max_layers, at_least(1), "most layers the search returns"),
         real("elevation_min", &ChooserParams::elevation_min, closed(-std::numbers::pi / 2, std::numbers::pi / 2),
              "rad, lowest candidate elevation"),
         real("elevation_max", &ChooserParams::elevation_max, closed(-std::numbers::pi / 2, std::numbers::pi / 2),
              "rad, highest candidate elevation"),
         real("elevation_step", &ChooserParams::elevation_step, above(0), "rad, spacing of the candidate elevations"),
         real("explore_minutes", &ChooserParams::explore_minutes, open_closed(0, max_agent_hours * 60),
              "simulated minutes of the exploratory walk")});
    return t;
}

std::vector<double> ChooserParams::candidate_elevations() const {
    std::vector<double> out;
    if (!(elevation_step > 0)) return out;
    // Multiples of the step from the minimum, with a little slack so that 0.4 is reached from 0 by 0.05.
    for (int i = 0;; ++i) {
        // Rounded to 12 decimals, so that 0.05 · 3 is the 0.15 a user would type.
        const double e = std::round((elevation_min + i * elevation_step) * 1e12) / 1e12;
        if (e > elevation_max + 1e-9 * std::max(1.0, std::abs(elevation_max))) break;
        out.push_back(std::min(e, elevation_max));
    }
    return out;
}

void ChooserParams::validate(int n_dir) const {
    table().check(*this);
    if (min_layers > max_layers)
        throw InputError("elevation chooser: min_layers (" + std::to_string(min_layers) + ") exceeds max_layers (" +
                         std::to_string(max_layers) + ")");
    if (elevation_min > elevation_max)
        throw InputError("elevation chooser: empty candidate range: elevation_min " + format_number(elevation_min) +
                         " > elevation_max " + format_number(elevation_max));
    // Each candidate is a short trial in every round of the search: count them before listing them.
    const double span = (elevation_max - elevation_min) / elevation_step;
    if (span >= max_candidate_elevations)
        throw InputError("elevation chooser: elevation_step " + format_number(elevation_step) + " gives " +
                         format_number(std::floor(span) + 1) + " candidate elevations from " +
                         format_number(elevation_min) + " to " + format_number(elevation_max) + "; the limit is " +
                         format_number(max_candidate_elevations));
    const auto n = static_cast<int>(candidate_elevations().size());
    if (n < min_layers)
        throw InputError("elevation chooser: the candidate range holds " + std::to_string(n) +
                         " elevation(s), fewer than min_layers = " + std::to_string(min_layers));
    const int layers = std::min(max_layers, n);
    if (budget / (n_dir * layers) < 2)
        throw InputError("elevation chooser: a budget of " + std::to_string(budget) + " BVCs is too small for " +
                         std::to_string(layers) + " layers of " + std::to_string(n_dir) +
                         " directions (each direction needs at least 2 distances: budget >= " +
                         std::to_string(2 * n_dir * layers) + ")");
}

ChooserDefaults chooser_defaults(const AgentSpec& agent) {
    if (agent.locomotion() == Locomotion::flying) return {"fly-5l", "spherical-full", true};
    return {"3d-0.2", "spherical", false};
}

std::string elevations_text(const std::vector<double>& elevations) {
    std::string s;
    for (double e : elevations) s += (s.empty() ? "" : ", ") + format_number(e);
    return s;
}

ModelSpec model_with_elevations(const ModelSpec& base, const std::vector<double>& elevations, int budget) {
    if (elevations.empty()) throw InputError("a candidate set needs at least one elevation");
    ModelSpec m = base;
    const int per_axis = budget / (base.bvc.n_dir * static_cast<int>(elevations.size()));
    if (per_axis < 2)
        throw InputError("a budget of " + std::to_string(budget) + " BVCs is too small for " +
                         std::to_string(elevations.size()) + " layers of " + std::to_string(base.bvc.n_dir) +
                         " directions");
    m.bvc.elevations = elevations;
    m.bvc.n_per_axis = per_axis;
    // A name that is also a file name a shell leaves alone (no brackets, spaces or commas): adaptive-0_0.35.
    m.name = "adaptive";
    for (std::size_t i = 0; i < elevations.size(); ++i) m.name += (i ? "_" : "-") + format_number(elevations[i]);
    m.validate();
    return m;
}

namespace {

// Whether two of the walk's positions lie farther apart than d_th (else aliasing has nothing to compare).
bool spreads_beyond(const ExplorationWalk& walk, double d_th) {
    const auto& steps = walk.steps;
    const double z_weight = walk.dims == 3 ? 1.0 : 0.0;
    for (std::size_t i = 0; i < steps.size(); ++i)
        for (std::size_t j = i + 1; j < steps.size(); ++j) {
            const double dx = steps[i].pose.x - steps[j].pose.x, dy = steps[i].pose.y - steps[j].pose.y;
            const double dz = z_weight * (steps[i].pose.z - steps[j].pose.z);
            if (dx * dx + dy * dy + dz * dz > d_th * d_th) return true;
        }
    return false;
}

}  // namespace

ExplorationWalk exploration_walk(const World& world, const AgentSpec& agent, std::uint64_t seed, double minutes,
                                 double d_th) {
    agent.validate();
    const auto walker = agent.make(&world, seed);
    ExplorationWalk walk{{}, agent.dims()};
    while (const auto s = walker->next(minutes * 60.0)) walk.steps.push_back(*s);
    if (spreads_beyond(walk, d_th)) return walk;
    throw InputError("the exploratory walk (" + format_number(minutes) + " min, " + std::to_string(walk.steps.size()) +
                     " steps) never gets two positions more than d_th = " + format_number(d_th) +
                     " m apart: explore longer");
}

std::vector<CandidateScore> score_elevation_sets(const World* world, const ModelSpec& base, const ExplorationWalk& walk,
                                                 const std::vector<std::vector<double>>& sets, int budget,
                                                 std::uint64_t seed, const analysis::AnalysisParams& analysis, int jobs,
                                                 const SourceFactory& sources, const std::atomic<bool>* stop) {
    // Slice k holds sets k, k + slices, ...: one group each, sharing its scans between its sets.
    const std::size_t slices = std::clamp<std::size_t>(thread_count(jobs), 1, std::max<std::size_t>(sets.size(), 1));
    if (walk.steps.size() < 2) throw InputError("the exploratory walk needs at least 2 steps");
    std::vector<TrialConfig> trials;
    const auto agent = two_passes(walk.steps, walk.dims);
    const Protocol protocol = two_pass_protocol(walk.steps);
    for (const auto& set : sets) {
        TrialConfig t;
        t.model = model_with_elevations(base, set, budget);
        t.protocol = protocol;
        t.protocol.record_bvc = true;  // for the BVC population's aliasing beside the criterion
        t.agent = agent;
        t.analysis = analysis;
        t.seed = seed;
        trials.push_back(std::move(t));
    }
    const std::uint64_t noise_seed = hash_u64(seed, static_cast<std::uint64_t>(Stream::sensor_noise), 0);
    std::vector<CandidateScore> out(sets.size());
    const CancelScope scope(stop ? stop : cancel_flag());
    parallel_for(slices, static_cast<int>(slices), [&](std::size_t k) {
        std::vector<TrialConfig> mine;
        std::vector<std::size_t> index;
        for (std::size_t i = k; i < trials.size(); i += slices) {
            mine.push_back(trials[i]);
            index.push_back(i);
        }
        if (mine.empty()) return;
        RunControl control;
        control.stop = cancel_flag();  // the pool's: Ctrl-C, or another slice's error
        const GroupResult r =
            run_trial_group(world, mine, control, replay_factory(sources, walk.steps.size(), noise_seed));
        for (std::size_t m = 0; m < mine.size(); ++m) out[index[m]] = score(world, r, m, mine[m]);
    });
    return out;
}

namespace {

// The greedy search on a walk already taken (world null: returns from `sources` alone).
ElevationChoice greedy_search(const World* world, const ModelSpec& base, const ExplorationWalk& walk,
                              const ChooserParams& params, const analysis::AnalysisParams& analysis,
                              const SourceFactory& sources) {
    const std::vector<double> pool = params.candidate_elevations();
    ElevationChoice choice;
    choice.walk_steps = walk.steps.size();
    std::vector<double> best_set;
    const int max_layers = std::min<int>(params.max_layers, static_cast<int>(pool.size()));
    for (int round = 1; round <= max_layers; ++round) {
        std::vector<std::vector<double>> sets;
        for (double e : pool) {
            if (std::find(best_set.begin(), best_set.end(), e) != best_set.end()) continue;
            auto set = best_set;
            set.insert(std::upper_bound(set.begin(), set.end(), e), e);
            sets.push_back(std::move(set));
        }
        auto scores = score_elevation_sets(world, base, walk, sets, params.budget, params.seed, analysis, params.jobs,
                                           sources, params.stop);
        for (auto& s : scores) s.round = round;
        choice.candidates.insert(choice.candidates.end(), scores.begin(), scores.end());
        const CandidateScore& top = scores[best_of(scores)];
        const bool improves = round == 1 || top.msai < choice.chosen.msai;
        if (!improves && round > params.min_layers) break;
        choice.chosen = top;
        best_set = top.elevations;
    }
    if (std::isnan(choice.chosen.msai)) throw InputError("the exploratory walk gave no bins to measure aliasing on");
    choice.model = model_with_elevations(base, choice.chosen.elevations, params.budget);
    return choice;
}

// The best of given sets on a walk already taken.
ElevationChoice best_of_sets(const World* world, const ModelSpec& base, const ExplorationWalk& walk,
                             const std::vector<std::vector<double>>& sets, const ChooserParams& params,
                             const analysis::AnalysisParams& analysis, const SourceFactory& sources) {
    ElevationChoice c;
    c.walk_steps = walk.steps.size();
    c.candidates = score_elevation_sets(world, base, walk, sets, params.budget, params.seed, analysis, params.jobs,
                                        sources, params.stop);
    for (auto& s : c.candidates) s.round = static_cast<int>(s.elevations.size());
    c.chosen = c.candidates[best_of(c.candidates)];
    if (std::isnan(c.chosen.msai)) throw InputError("the exploratory walk gave no bins to measure aliasing on");
    c.model = model_with_elevations(base, c.chosen.elevations, params.budget);
    return c;
}

// A returns spec's factory serves one run (its sources cache scans): one per worker thread.
SourceFactory factory_per_thread(std::shared_ptr<const ReturnsSpec> spec, std::uint64_t seed) {
    struct Factories {
        std::mutex mutex;
        std::map<std::thread::id, SourceFactory> of_thread;
    };
    auto all = std::make_shared<Factories>();
    return [spec, seed, all](const ModelSpec& model, const World* world) {
        SourceFactory mine;
        {
            const std::lock_guard lock(all->mutex);
            auto& slot = all->of_thread[std::this_thread::get_id()];
            if (!slot) slot = spec->factory(seed);
            mine = slot;
        }
        return mine(model, world);
    };
}

// Checks before any work: the parameters, and every given set against the budget.
void check_choice(const ModelSpec& base, const std::vector<std::vector<double>>& sets, const ChooserParams& params,
                  const analysis::AnalysisParams& analysis) {
    if (sets.empty()) params.validate(base.bvc.n_dir);
    else ChooserParams::table().check(params);
    analysis.validate();
    for (const auto& set : sets) model_with_elevations(base, set, params.budget);
}

}  // namespace

ElevationChoice choose_elevations(const World& world, const ModelSpec& base, const AgentSpec& agent,
                                  const ChooserParams& params, const analysis::AnalysisParams& analysis,
                                  const SourceFactory& sources) {
    check_choice(base, {}, params, analysis);
    const auto walk = exploration_walk(world, agent, params.seed, params.explore_minutes, analysis.d_th);
    return greedy_search(&world, base, walk, params, analysis, sources);
}

ElevationChoice choose_from_sets(const World& world, const ModelSpec& base, const AgentSpec& agent,
                                 const std::vector<std::vector<double>>& sets, const ChooserParams& params,
                                 const analysis::AnalysisParams& analysis, const SourceFactory& sources) {
    if (sets.empty()) throw InputError("no elevation sets to choose from");
    check_choice(base, sets, params, analysis);
    const auto walk = exploration_walk(world, agent, params.seed, params.explore_minutes, analysis.d_th);
    return best_of_sets(&world, base, walk, sets, params, analysis, sources);
}

ElevationChoice choose_elevations_on(const ReplaySource& source, const ModelSpec& base, const ChooserParams& params,
                                     const analysis::AnalysisParams& analysis,
                                     const std::vector<std::vector<double>>& sets) {
    check_choice(base, sets, params, analysis);
    if (!source.path || !source.returns)
        throw InputError("choosing elevations on recorded scans needs their poses and scans");
    const ExplorationWalk walk{source.path->steps(), source.path->dims()};
    if (walk.steps.size() < 2 || !spreads_beyond(walk, analysis.d_th))
        throw InputError("the recording's " + std::to_string(walk.steps.size()) + " poses never lie more than d_th = " +
                         format_number(analysis.d_th) + " m apart: nothing to measure aliasing on");
    const std::optional<World> world =
        source.world.is_none() ? std::nullopt : std::optional<World>(World(source.world.resolve()));
    const World* w = world ? &*world : nullptr;
    const SourceFactory sources = factory_per_thread(source.returns, params.seed);
    return sets.empty() ? greedy_search(w, base, walk, params, analysis, sources)
                        : best_of_sets(w, base, walk, sets, params, analysis, sources);
}

}  // namespace bvc3d
