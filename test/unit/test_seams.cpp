// The seams new kinds of thing enter through (docs/architecture.md): the pose, agents (a trajectory
// fed from arrays and files; kinds found through one registry, paired with models by what they can
// do), return sources (returns fed from arrays), analysis in 3-D, and the parameter tables. Oracles:
// the definitions written out in the tests, brute force, hand-made cases.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>

#include "../support/bvc_reference.hpp"
#include "../support/temp_dir.hpp"
#include "bvc3d/agent/flying_walk.hpp"
#include "bvc3d/agent/trajectory.hpp"
#include "bvc3d/analysis/trial_metrics.hpp"
#include "bvc3d/config/agent_kinds.hpp"
#include "bvc3d/config/model_yaml.hpp"
#include "bvc3d/config/protocols.hpp"
#include "bvc3d/config/trial_yaml.hpp"
#include "bvc3d/config/world_yaml.hpp"
#include "bvc3d/core/error.hpp"
#include "bvc3d/experiment/trial_runner.hpp"
#include "bvc3d/recorder/checkpoint_file.hpp"

using namespace bvc3d;
namespace fs = std::filesystem;
using bvc3d::test::TempDir;

namespace {

// A short trial in the 45° arena following `agent`.
TrialConfig trial_with(std::shared_ptr<const AgentSpec> agent, const std::string& model, double hours) {
    TrialConfig t;
    t.world = WorldSpec{"cross", 45.0, "+x+y"};
    t.model = model_preset(model);
    t.agent = std::move(agent);
    t.protocol.explore_hours = t.protocol.sample_hours = hours;
    t.protocol.record_bvc = true;
    return t;
}

}  // namespace

// --- the pose ---------------------------------------------------------------------------------

TEST(Seams, PoseRotationRoundTripsAndFollowsItsConvention) {
    const Pose p{1, 2, 3, 0.7, -0.4, 0.25};
    const Eigen::Matrix3d R = p.rotation();
    // The forward axis is (cos p cos h, cos p sin h, sin p): pitch is nose up.
    EXPECT_NEAR(
        (R.col(0) - Vec3(std::cos(-0.4) * std::cos(0.7), std::cos(-0.4) * std::sin(0.7), std::sin(-0.4))).norm(), 0.0,
        1e-15);
    EXPECT_NEAR(R.determinant(), 1.0, 1e-15);
    const Pose q = Pose::from_rotation(p.position(), R);
    EXPECT_NEAR(q.heading, p.heading, 1e-14);
    EXPECT_NEAR(q.pitch, p.pitch, 1e-14);
    EXPECT_NEAR(q.roll, p.roll, 1e-14);
    EXPECT_TRUE(Pose::on_floor(1, 2, 3).level());
    EXPECT_FALSE(q.level());
}

TEST(Seams, TiltedSensorCastsItsBeamsInTheWorldFrame) {
    // A closed 20 m box around the origin: every beam hits a face at a range the geometry gives.
    WorldDescription w;
    w.name = "box";
    w.mesh = box_mesh(Vec3(20, 20, 20));
    w.walkable = Polygon2::rectangle(-10, -10, 10, 10);
    w.start.points = {Vec2(0, 0)};
    const World world(w);
    const Lidar lidar(LidarSpec::horizontal());
    // Rolled by 90°: the horizontal fan stands in the vertical plane through the heading (here +x).
    const Pose rolled{0, 0, 0, 0.0, 0.0, pi / 2};
    const Scan scan = lidar.scan(world, rolled);
    ASSERT_EQ(scan.size(), 720u);
    const Eigen::Matrix3d R = rolled.rotation();
    const Vec3 origin = R * Vec3(0, 0, 0.08);
    for (std::size_t k = 0; k < scan.size(); k += 37) {
        const double a = k * pi / 360;
        const Vec3 d = R * Vec3(std::cos(a), std::sin(a), 0.0);  // the beam in the world
        // Distance to the box's faces at ±10 along the beam.
        double range = INFINITY;
        for (int axis = 0; axis < 3; ++axis)
            if (std::abs(d[axis]) > 1e-12) range = std::min(range, ((d[axis] > 0 ? 10 : -10) - origin[axis]) / d[axis]);
        EXPECT_NEAR(scan[k].range, range, 1e-9) << k;
        EXPECT_NEAR(wrap_pi(scan[k].azimuth - std::atan2(d.y(), d.x())), 0.0, 1e-12) << k;
        EXPECT_NEAR(scan[k].elevation, std::atan2(d.z(), std::hypot(d.x(), d.y())), 1e-12) << k;
    }
    // A level pose takes the fast path; a pose tilted by a hair agrees with it.
    const Scan level = lidar.scan(world, Pose{1, 2, 0.5, 0.3, 0, 0});
    const Scan almost = lidar.scan(world, Pose{1, 2, 0.5, 0.3, 1e-13, 0});
    ASSERT_EQ(level.size(), almost.size());
    for (std::size_t k = 0; k < level.size(); ++k) {
        EXPECT_NEAR(level[k].range, almost[k].range, 1e-9);
        EXPECT_NEAR(std::abs(wrap_pi(level[k].azimuth - almost[k].azimuth)), 0.0, 1e-12);
    }
    EXPECT_THROW(lidar.scan(world, rolled, const_cast<Scan&>(scan), {}, std::vector<char>{1}), InputError);
}

// --- agents -----------------------------------------------------------------------------------

TEST(Seams, TrajectoryFromArraysIsFollowedStepForStep) {
    // A square loop around the arena's central walls, 0.144 m apart, repeated for an hour.
    std::vector<double> t, x, y, h;
    for (int i = 0; i < 25000; ++i) {
        const double s = std::fmod(i * 0.144, 24.0), side = std::floor(s / 6.0), u = s - 6.0 * side - 3.0;
        const double px[] = {u, 4.0, -u, -4.0}, py[] = {-4.0, u, 4.0, -u}, ph[] = {0, pi / 2, pi, -pi / 2};
        t.push_back(100.0 + 0.288 * i);  // shifted to start at 0
        x.push_back(px[static_cast<int>(side)]);
        y.push_back(py[static_cast<int>(side)]);
        h.push_back(ph[static_cast<int>(side)]);
    }
    auto spec = std::make_shared<TrajectorySpec>(trajectory_steps(t, x, y, {}, h, "arrays"), "arrays");
    const TrialConfig trial = trial_with(spec, "3d-0.2", 0.5);
    const GroupResult r = run_trial_group({trial});
    // Exploration takes every row up to and including the first at or past 0.5 h (a step begun before
    // the phase ends is completed, as the random walk does).
    std::int64_t explored = 0;
    while (t[explored] - 100.0 < 1800.0) ++explored;
    ASSERT_EQ(r.stats.explore_steps, explored + 1);
    ASSERT_GT(r.t.size(), 6000u);
    const std::size_t first = static_cast<std::size_t>(r.stats.explore_steps);
    const World world(trial.world.resolve());
    const Lidar lidar(trial.model.sensor);
    for (std::size_t i = 0; i < r.t.size(); i += 997) {
        EXPECT_EQ(r.t[i], t[first + i] - 100.0);
        EXPECT_EQ(r.x[i], x[first + i]);
        EXPECT_EQ(r.y[i], y[first + i]);
        // The recorded BVC rates are the model's on a scan cast at the given pose (the definition, summed
        // in full by the reference, normalized to a maximum of 0.5).
        const auto raw = reference::bvc_raw(
            trial.model.bvc, lidar.scan(world, Pose::on_floor(x[first + i], y[first + i], h[first + i])));
        const double top = *std::max_element(raw.begin(), raw.end());
        for (std::size_t c = 0; c < raw.size(); c += 7)
            EXPECT_NEAR(r.models[0].bvc[i * raw.size() + c], raw[c] / (2 * top), 1e-6 * 0.5 + 1e-7);
    }
    // A trajectory that ends before sampling begins is an error, not an empty trial.
    TrialConfig short_one = trial_with(spec, "2d", 2.0);
    EXPECT_THROW(run_trial_group({short_one}), InputError);
}

TEST(Seams, TrajectoryResumesFromACheckpointExactly) {
    std::vector<double> t, x, y, h;
    for (int i = 0; i < 3000; ++i) {
        t.push_back(0.288 * i);
        x.push_back(-4 + 8.0 * i / 3000);
        y.push_back(-4.2);
        h.push_back(0);
    }
    auto spec = std::make_shared<TrajectorySpec>(trajectory_steps(t, x, y, {}, h, "arrays"), "arrays");
    const TrialConfig trial = trial_with(spec, "2d", 0.1);
    const GroupResult straight = run_trial_group({trial});
    const TempDir dir("seams");
    const auto ckpt = dir / "checkpoint.h5";
    std::atomic<bool> stop{true};
    RunControl control;
    control.stop = &stop;
    control.checkpoint = ckpt;
    EXPECT_THROW(run_trial_group({trial}, control), Interrupted);
    stop = false;
    const GroupResult resumed = run_trial_group({trial}, control);
    EXPECT_EQ(resumed.x, straight.x);
    EXPECT_EQ(resumed.models[0].rates, straight.models[0].rates);
    EXPECT_EQ(resumed.models[0].weights, straight.models[0].weights);
    remove_checkpoint(ckpt);
}

TEST(Seams, TrajectoryFilesWithAndWithoutHeaders) {
    const TempDir dir("seams");
    const auto plain = dir.write("plain.txt", "# t x y heading\n0 1 2 0.5\n0.5, 1.1, 2, 0.5\n");
    const auto steps = read_trajectory_file(plain);
    ASSERT_EQ(steps.size(), 2u);
    EXPECT_EQ(steps[1].t, 0.5);
    EXPECT_EQ(steps[1].pose.x, 1.1);
    EXPECT_EQ(steps[1].pose.z, 0.0);
    const auto header = dir.write("header.csv", "x,y,z,heading_deg,t\n1,2,0.3,90,10\n1,2.1,0.3,90,11\n");
    const auto h = read_trajectory_file(header);
    EXPECT_EQ(h[0].t, 0.0);  // shifted to start at 0
    EXPECT_EQ(h[1].t, 1.0);
    EXPECT_EQ(h[0].pose.z, 0.3);
    EXPECT_NEAR(h[0].pose.heading, pi / 2, 1e-15);
    const std::pair<std::string, std::string> bad[] = {
        {"0 1 2\n", "line 1: expected 4 values"},
        {"0 1 2 0\n0 1 2 0\n", "row 1: times must increase"},
        {"t,x,y\n0,1,2\n", "needs exactly one of 'heading' and 'heading_deg'"},
        {"0 1 2 0\n1 1 nan 0\n", "row 1: every value must be finite"},
        {"0 1 2 0\n1 1 two 0\n", "line 2: 'two' is not a number"},
        {"# nothing\n", "has no rows"},
    };
    for (const auto& [text, reason] : bad) {
        const auto f = dir.write("bad.txt", text);
        try {
            read_trajectory_file(f);
            ADD_FAILURE() << "accepted: " << text;
        } catch (const InputError& e) {
            EXPECT_NE(std::string(e.what()).find(f.string()), std::string::npos) << e.what();
            EXPECT_NE(std::string(e.what()).find(reason), std::string::npos) << e.what();
        }
    }
    EXPECT_THROW(read_trajectory_file(fs::temp_directory_path()), InputError);
    // A path in another frame (outside the world's geometry) is refused when the trial starts.
    auto far =
        std::make_shared<TrajectorySpec>(trajectory_steps({0, 1}, {100, 101}, {0, 0}, {}, {0, 0}, "arrays"), "arrays");
    EXPECT_THROW(run_trial_group({trial_with(far, "2d", 0.0001)}), InputError);
    // In trial YAML, next to the random walk's robot.
    const auto yaml =
        dir.write("trial.yaml", "trajectory: " + header.string() + "\nprotocol: {kind: online, sample_hours: 0.001}\n");
    EXPECT_EQ(config::load_trial_file(yaml.string()).agent->kind(), "trajectory");
    const auto both = dir.write("both.yaml", "trajectory: " + header.string() + "\nrobot: {speed: 1}\n");
    EXPECT_THROW(config::load_trial_file(both.string()), ConfigError);
}

// --- agents: one registry, checks by what an agent can do -----------------------------------------

namespace {

// A kind of agent defined only here, moving as it is told: no registry entry and a kind() string no
// check knows. Whatever asks what it can do must get the answer from the spec itself.
class TestAgentSpec : public AgentSpec {
public:
    TestAgentSpec(Locomotion moves, int dims) : moves_(moves), dims_(dims) {}
    std::string kind() const override { return "test_agent"; }
    Locomotion locomotion() const override { return moves_; }
    int dims() const override { return dims_; }
    void validate() const override {}
    void check_world(const WorldDescription&) const override {}
    std::unique_ptr<Agent> make(const World*, std::uint64_t) const override { return nullptr; }
    std::string key() const override { return "agent: test\n"; }
    double steps_per_second() const override { return 1.0; }
    void write_yaml(params::CommentedYaml&) const override {}

private:
    Locomotion moves_;
    int dims_;
};

}  // namespace

TEST(Seams, ModelPresetsPairWithAgentsByHowTheyMove) {
    // Presets made for the ground robot refuse flying agents and the fly-* presets refuse agents on the
    // ground, whatever their kind; a given path takes any preset (the path is the data).
    struct Case {
        Locomotion moves;
        int dims;
        const char* model;
        const char* refusal;  // "" when the pair is accepted
    };
    const Case cases[] = {
        {Locomotion::ground, 2, "fly-up", "is a preset for flying agents"},
        {Locomotion::ground, 3, "fly-5l", "is a preset for flying agents"},
        {Locomotion::ground, 2, "3d-0.2", ""},
        {Locomotion::flying, 3, "3d-0.2", "is a preset for the ground robot"},
        {Locomotion::flying, 2, "2d", "is a preset for the ground robot"},
        {Locomotion::flying, 3, "fly-up", ""},
        {Locomotion::given_path, 2, "fly-9l", ""},
        {Locomotion::given_path, 3, "3d-3l", ""},
    };
    for (const auto& c : cases) {
        TrialConfig t;
        t.world = WorldSpec{"flight-room", std::nullopt, "+x+y"};
        t.model = model_preset(c.model);
        t.set_agent(std::make_shared<TestAgentSpec>(c.moves, c.dims));
        const std::string what =
            std::string(c.model) + " on a test agent of locomotion " + std::to_string(static_cast<int>(c.moves));
        if (*c.refusal == '\0') {
            EXPECT_NO_THROW(t.validate()) << what;
            continue;
        }
        try {
            t.validate();
            ADD_FAILURE() << "accepted: " << what;
        } catch (const InputError& e) {
            EXPECT_NE(std::string(e.what()).find(c.refusal), std::string::npos) << what << ": " << e.what();
        }
    }
}

TEST(Seams, AgentKindsAreFoundByNameByYamlKeyAndBySpec) {
    const TempDir dir("seams");
    const auto keys = config::trial_keys();
    for (const auto& k : agent_kinds()) {
        EXPECT_NE(std::find(keys.begin(), keys.end(), k.yaml_key), keys.end()) << k.yaml_key;
        EXPECT_NO_THROW(protocol_preset(k.protocol)) << k.name;
        if (!k.make_default) continue;  // a kind that needs data is not chosen by name
        const auto spec = k.make_default();
        EXPECT_EQ(spec->kind(), k.name);
        EXPECT_EQ(&agent_kind_of(*spec), &k);
        for (const auto& name : k.aliases) EXPECT_EQ(agent_by_name(name)->kind(), k.name) << name;
        EXPECT_EQ(agent_by_name(k.name)->key(), spec->key());
        // Its YAML key with no parameters gives the same agent back.
        const auto yaml =
            dir.write("agent.yaml", k.yaml_key + ": {}\nworld: flight-room\n" +
                                        (spec->locomotion() == Locomotion::flying ? "model: fly-up\n" : ""));
        EXPECT_EQ(config::load_trial_file(yaml.string()).agent->key(), spec->key()) << k.name;
    }
    // A parameter in the YAML reaches the agent through its kind's table.
    const auto fly = dir.write("fly.yaml", "world: flight-room\nmodel: fly-up\nflight: {radius: 0.3}\n");
    const auto fly_trial = config::load_trial_file(fly.string());  // kept: the agent lives in it
    const auto* flight = dynamic_cast<const FlightSpec*>(fly_trial.agent.get());
    ASSERT_NE(flight, nullptr);
    EXPECT_EQ(flight->flight().radius, 0.3);
    // Unknown names are refused with the names there are; two kinds in one trial are refused.
    try {
        agent_by_name("hover");
        ADD_FAILURE() << "accepted 'hover'";
    } catch (const InputError& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("agent 'hover' is not one of random_walk or ground"), std::string::npos) << what;
        EXPECT_NE(what.find("flight or flying"), std::string::npos) << what;
    }
    EXPECT_THROW(agent_by_name("trajectory"), InputError);  // needs its rows
    EXPECT_THROW(agent_kind_of(TestAgentSpec(Locomotion::ground, 2)), InputError);
    const auto two = dir.write("two.yaml", "robot: {}\nflight: {}\n");
    EXPECT_THROW(config::load_trial_file(two.string()), ConfigError);
}

// --- return sources ---------------------------------------------------------------------------

TEST(Seams, ReturnsFedFromArraysDriveTheModel) {
    // Random returns per step, given as data: the recorded BVC rates are the layer's on exactly those.
    std::mt19937_64 gen(3);
    std::uniform_real_distribution<double> r(0.2, 14), az(-pi, pi), el(-0.05, 0.3);
    std::vector<Scan> scans(400);
    for (auto& s : scans)
        for (int j = 0; j < 300; ++j) s.push_back({r(gen), az(gen), el(gen)});
    TrialConfig trial = trial_with(std::make_shared<RandomWalkSpec>(), "3d-3l", 0.03);
    trial.protocol.kind = Protocol::Kind::online;
    auto source = std::make_shared<ArrayReturnSource>(scans);
    const World world(trial.world.resolve());
    const GroupResult res = run_trial_group(world, {trial}, {}, [&](const ModelSpec&, const World*) { return source; });
    ASSERT_GT(res.t.size(), 300u);
    const std::size_t nb = static_cast<std::size_t>(trial.model.bvc.n_cells());
    for (std::size_t i = 0; i < res.t.size(); i += 61) {
        const auto raw = reference::bvc_raw(trial.model.bvc, scans[i]);
        const double top = *std::max_element(raw.begin(), raw.end());
        for (std::size_t c = 0; c < nb; c += 5)
            EXPECT_NEAR(res.models[0].bvc[i * nb + c], raw[c] / (2 * top), 1e-6 * 0.5 + 1e-7);
    }
    EXPECT_EQ(res.stats.full_scan_fallbacks, 0);
    // More steps than returns were given for: a clear error.
    ArrayReturnSource few({Scan{}});
    Scan out;
    EXPECT_THROW(few.returns(3, Pose{}, {}, out), InputError);
}

TEST(Seams, IrregularPointSetsGiveTheSameRatesAsTheDefinition) {
    // Real LiDAR repeats no azimuth or elevation: the layer computes angular factors directly then.
    const BoundaryVectorLayer layer(model_preset("3d-3l").bvc);
    std::mt19937_64 gen(11);
    std::uniform_real_distribution<double> r(0.3, 19), az(-pi, pi), el(-0.8, 0.8);
    for (int step = 0; step < 40; ++step) {  // many steps: the memo switches off and probes again
        Scan s;
        for (int j = 0; j < 2000; ++j) s.push_back({r(gen), az(gen), el(gen)});
        std::vector<double> out(layer.n_cells());
        layer.raw(s, out);
        if (step % 13 != 0) continue;
        const auto ref = reference::bvc_raw(layer.params(), s);
        const double top = *std::max_element(ref.begin(), ref.end());
        for (std::size_t c = 0; c < out.size(); ++c) ASSERT_NEAR(out[c], ref[c], 1e-7 * top) << step << " " << c;
    }
}

// --- analysis in 3-D --------------------------------------------------------------------------

namespace {
// Cubes of side h from the origin: a second kind of grid, as the analysis seam allows.
class CubeGrid : public analysis::Grid {
public:
    CubeGrid(int n, double h) : n_(n), h_(h) {}
    int dims() const override { return 3; }
    int size() const override { return n_ * n_ * n_; }
    int bin_of(const double* p) const override {
        int idx = 0;
        for (int d = 0; d < 3; ++d) {
            const int i = static_cast<int>(std::floor(p[d] / h_));
            if (i < 0 || i >= n_) return -1;
            idx = idx * n_ + i;
        }
        return idx;
    }
    void center(int bin, double* out) const override {
        for (int d = 2; d >= 0; --d) out[d] = (bin % n_ + 0.5) * h_, bin /= n_;
    }
    double bin_measure() const override { return h_ * h_ * h_; }

private:
    int n_;
    double h_;
};
}  // namespace

TEST(Seams, ModalityAndAliasingInThreeDimensions) {
    // Two blobs of active bins 3 m apart in z only: two fields in 3-D, one in the floor plane.
    analysis::Points c(2 * 27, 3);
    int row = 0;
    for (double z0 : {0.0, 3.0})
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j)
                for (int k = 0; k < 3; ++k) c.row(row++) << 0.5 * i, 0.5 * j, z0 + 0.5 * k;
    analysis::RowMatrixXd maps = analysis::RowMatrixXd::Ones(c.rows(), 1);
    EXPECT_EQ(analysis::modality(c, maps, {1.0, 5}), std::vector<int>{2});
    EXPECT_EQ(analysis::modality(c.leftCols(2), maps, {1.0, 5}), std::vector<int>{1});
    // SAI against the definition, a double loop over bins with 3-D distances.
    std::mt19937_64 gen(5);
    std::uniform_real_distribution<double> u(0, 1);
    analysis::RowMatrixXd m(c.rows(), 6);
    for (Eigen::Index i = 0; i < m.size(); ++i) m.data()[i] = u(gen) < 0.4 ? u(gen) : 0.0;
    const auto a = analysis::spatial_aliasing(c, m, 2.0);
    double msai = 0;
    for (Eigen::Index i = 0; i < c.rows(); ++i) {
        double sai = 0;
        for (Eigen::Index j = 0; j < c.rows(); ++j) {
            if (i == j || (c.row(i) - c.row(j)).norm() <= 2.0) continue;
            const double ni = m.row(i).norm(), nj = m.row(j).norm();
            if (ni > 0 && nj > 0) sai += m.row(i).dot(m.row(j)) / (ni * nj);
        }
        EXPECT_NEAR(a.sai(i), sai / c.rows(), 1e-12) << i;
        msai += sai / c.rows();
    }
    EXPECT_NEAR(a.msai, msai / c.rows(), 1e-12);
}

TEST(Seams, DecodingOnAThreeDimensionalGrid) {
    // Each sample's population vector is a one-hot code of its cube: decoding is exact except where
    // a cube has no template (visited only in the second half), counted as undecoded.
    const auto grid = std::make_shared<CubeGrid>(4, 1.0);
    std::mt19937_64 gen(9);
    std::uniform_real_distribution<double> u(0, 4);
    const int n = 4000;
    analysis::Points pos(n, 3);
    analysis::RowMatrixXd rates = analysis::RowMatrixXd::Zero(n, 64);
    for (int i = 0; i < n; ++i) {
        pos.row(i) << u(gen), u(gen), u(gen);
        rates(i, grid->bin_of(pos.row(i).data())) = 1.0;
    }
    const auto d = analysis::decoding_error<double>(*grid, pos, rates, analysis::DecodingTemplates::rate_maps, 0.1);
    EXPECT_EQ(d.n_decoded + d.n_undecoded, static_cast<std::size_t>(n - n / 2));
    // Brute force: the distance from each second-half sample to the center of its own cube.
    std::vector<double> errors;
    for (int i = n / 2; i < n; ++i) {
        double center[3];
        grid->center(grid->bin_of(pos.row(i).data()), center);
        errors.push_back(std::sqrt(std::pow(pos(i, 0) - center[0], 2) + std::pow(pos(i, 1) - center[1], 2) +
                                   std::pow(pos(i, 2) - center[2], 2)));
    }
    double mean = 0;
    for (double e : errors) mean += e;
    EXPECT_EQ(d.n_undecoded, 0u);
    EXPECT_NEAR(d.mean_m, mean / errors.size(), 1e-12);
    // Rate maps on the same grid: per-cube means, each one-hot cell's map is 1 in its own cube only.
    const auto maps = analysis::rate_maps<double>(grid, pos, rates, 0.1);
    EXPECT_EQ(maps.bins.size(), 64);
    EXPECT_EQ(maps.bins.centers.cols(), 3);
    for (int b = 0; b < 64; ++b) EXPECT_EQ(maps.map(b, maps.bins.ids[b]), 1.0);
    EXPECT_DOUBLE_EQ(analysis::cell_stats(maps).field_area[0], 1.0);  // one cube: 1 m³
}

// --- parameter tables -------------------------------------------------------------------------

namespace {
// For every field of a table: a value outside its limits is refused by validate() and by YAML,
// naming the key; the default struct passes.
template <class S>
void check_table_limits(const params::Table<S>& table, const std::string& yaml_section,
                        const std::function<void(const std::string& yaml)>& load) {
    S ok;
    EXPECT_NO_THROW(ok.validate()) << table.what();
    for (const auto& f : table.fields()) {
        if (f.kind != params::Kind::real && f.kind != params::Kind::integer) continue;
        const double bad = std::isfinite(f.limits.lo) ? f.limits.lo - 1 : f.limits.hi + 1;
        if (!std::isfinite(bad)) continue;
        S s;
        if (f.kind == params::Kind::real) f.set(s, bad);
        else f.set(s, static_cast<long long>(bad));
        try {
            s.validate();
            ADD_FAILURE() << table.what() << "." << f.key << " = " << bad << " passed validate()";
        } catch (const params::ParamError& e) {
            EXPECT_EQ(e.key(), f.key);
        }
        const std::string text = yaml_section + ":\n  " + f.key + ": " + params::to_text(f.get(s)) + "\n";
        try {
            load(text);
            ADD_FAILURE() << f.key << " = " << bad << " passed YAML";
        } catch (const ConfigError& e) {
            EXPECT_NE(e.key().find(f.key), std::string::npos) << e.what();
        }
    }
}
}  // namespace

TEST(Seams, ParameterTablesCheckTheSameWayEverywhere) {
    auto model = [](const std::string& text) {
        config::model_from_yaml(config::YamlView::load_string(text, "m.yaml"));
    };
    auto trial = [](const std::string& text) {
        config::trial_from_yaml(config::YamlView::load_string(text, "t.yaml"));
    };
    check_table_limits(BvcParams::table(), "bvc", model);
    check_table_limits(PlaceParams::table(), "place", model);
    check_table_limits(LidarSpec::table(), "sensor", [](const std::string& text) {
        config::model_from_yaml(config::YamlView::load_string(text + "  preset: spherical\n", "m.yaml"));
    });
    check_table_limits(RobotParams::table(), "robot", trial);
    check_table_limits(Protocol::table(), "protocol", trial);
    check_table_limits(analysis::AnalysisParams::table(), "analysis", trial);
    // Written and read back, every preset is itself (the text trial files store).
    for (const auto& name : model_preset_names()) {
        const ModelSpec m = model_preset(name);
        const ModelSpec back =
            config::model_from_yaml(config::YamlView::load_string(config::model_to_yaml(m), "m.yaml"));
        EXPECT_EQ(config::model_to_yaml(back), config::model_to_yaml(m)) << name;
        EXPECT_EQ(back.bvc.elevations, m.bvc.elevations);
        EXPECT_EQ(back.place.alpha_pb, m.place.alpha_pb);
    }
    // Angles in degrees where a key takes radians.
    const ModelSpec deg =
        config::model_from_yaml(config::YamlView::load_string("bvc: {elevations_deg: [0, 10]}\n", "m.yaml"));
    EXPECT_EQ(deg.bvc.elevations[1], deg_to_rad(10.0));
}

// What `bvc3d config` prints reads back to the same configuration: equal canonical text (so equal
// fingerprints and results) and bit-identical numbers, for presets and for awkward values.
TEST(Seams, CommentedYamlReadsBackToTheSameConfiguration) {
    const TempDir dir("seams");
    using config::YamlView;
    for (const auto& name : model_preset_names()) {
        const ModelSpec m = model_preset(name);
        const std::string text = config::model_to_commented_yaml(m);
        const ModelSpec back = config::model_from_yaml(YamlView::load_string(text, "m.yaml"));
        EXPECT_EQ(config::model_to_yaml(back), config::model_to_yaml(m)) << text;
        EXPECT_EQ(back.place.alpha_pb, std::sqrt(0.5));  // the exact value, not a rounded one
        EXPECT_EQ(config::preset_name_of(back), name);
    }
    LidarSpec odd = LidarSpec::spherical(false);
    odd.name = "odd: name #1";
    odd.elevations[3] = 0.1 + 0.2;
    odd.azimuth_offset = pi / 7;
    odd.range_noise_sd = 1e-300;
    for (const LidarSpec& s : {LidarSpec::horizontal(), LidarSpec::spherical(), odd}) {
        const LidarSpec back =
            config::sensor_from_yaml(YamlView::load_string(config::sensor_to_commented_yaml(s), "s.yaml"));
        EXPECT_EQ(params::yaml_lines(LidarSpec::table(), back, ""), params::yaml_lines(LidarSpec::table(), s, ""));
        EXPECT_EQ(back.elevations, s.elevations);
        EXPECT_EQ(back.name, s.name);
    }
    EXPECT_EQ(config::builtin_sensor_name(LidarSpec::spherical()), "spherical");
    EXPECT_EQ(config::builtin_sensor_name(odd), "");

    const auto read_back = [](const TrialConfig& t) {
        const std::string text = config::trial_to_commented_yaml(t);
        const TrialConfig back = config::trial_from_yaml(YamlView::load_string(text, "t.yaml"));
        EXPECT_EQ(back.canonical(), t.canonical()) << text;
        EXPECT_EQ(back.fingerprint(), t.fingerprint());
        return back;
    };
    read_back(TrialConfig{});
    TrialConfig t;
    t.world = WorldSpec{"cross", 37.5, "-x+y"};
    t.model = model_preset("3d-3l");
    t.model.name = "my model: #2";
    t.model.sensor = odd;
    t.model.bvc.sigma_phi = 0.1 + 0.2;
    t.model.bvc.elevations = {0.0, pi / 7, -1e-17};
    t.model.place.eta = 1.0 / 3.0;
    t.protocol.kind = Protocol::Kind::online;
    t.protocol.sample_hours = 0.123456789012345678;
    t.protocol.record_bvc = true;
    RobotParams robot;
    robot.turn_sd = pi / 5;
    t.agent = std::make_shared<RandomWalkSpec>(robot);
    t.analysis.quantile = 1.0 / 3.0;
    t.analysis.decoding_templates = analysis::DecodingTemplates::means;
    t.arena_extent = true;
    t.seed = 9007199254740993ull;
    const TrialConfig back = read_back(t);
    EXPECT_EQ(back.model.bvc.elevations, t.model.bvc.elevations);
    EXPECT_EQ(back.model.name, t.model.name);
    // A world file and a trajectory file, written as absolute paths.
    TrialConfig files;
    files.world = WorldSpec{std::string(BVC3D_SOURCE_DIR) + "/configs/worlds/two-rooms.yaml", std::nullopt, "+x+y"};
    const auto track = dir.write("config-track.csv", "t,x,y,heading\n0,-3,-1,0\n0.5,-2.9,-1,0\n");
    files.agent = std::make_shared<TrajectorySpec>(TrajectorySpec::from_file(track));
    files.protocol = Protocol{Protocol::Kind::online, 0, 0.001, false};
    read_back(files);
    EXPECT_NE(config::trial_to_commented_yaml(files).find("trajectory: " + track.string()), std::string::npos);
    // A path given as arrays has no file to name.
    TrialConfig arrays;
    arrays.agent =
        std::make_shared<TrajectorySpec>(trajectory_steps({0, 1}, {0, 0}, {0, 0}, {}, {0, 0}, "arrays"), "arrays");
    EXPECT_THROW(config::trial_to_commented_yaml(arrays), InputError);
    fs::remove(track);
}

// Text that needs quoting in YAML is quoted, and reads back as itself.
TEST(Seams, CommentedYamlQuotesTextThatNeedsIt) {
    for (const std::string text : {"plain", "+x+y", "-x-y", "a: b", "#x", "x #y", "", "null", "~", "- x", "[a]", "{a}",
                                   "it's \"q\"", "back\\slash", "colon:", "*star", "tab\there", " lead"}) {
        params::CommentedYaml out;
        out.line("", "name", params::CommentedYaml::scalar(text), "a label");
        const auto v = config::YamlView::load_string(out.str(), "q.yaml");
        EXPECT_EQ(v["name"].as_string(), text) << out.str();
    }
    EXPECT_EQ(params::CommentedYaml::scalar("+x+y"), "+x+y");
}
