#include "node_model.hpp"

#include <Eigen/Core>
#include <cmath>

#include "bvc3d/bvc/boundary_vector_layer.hpp"
#include "bvc3d/config/model_yaml.hpp"
#include "bvc3d/core/angles.hpp"
#include "bvc3d/core/error.hpp"
#include "bvc3d/experiment/replay.hpp"
#include "bvc3d/place/place_cell_network.hpp"
#include "bvc3d/recorder/trial_file.hpp"
#include "bvc3d/recording/bag_recording.hpp"
#include "bvc3d/sensor/recorded_returns.hpp"

namespace bvc3d::ros_node {

namespace {

// Rows scaled to unit length (an all-zero row stays zero: its cosine with anything is 0).
void normalise(std::vector<float>& row) {
    double n = 0;
    for (const float v : row) n += double{v} * v;
    if (n > 0)
        for (float& v : row) v = static_cast<float>(v / std::sqrt(n));
}

// Vectorised (Eigen): the revisit search runs one per earlier scan, thousands per scan after an hour.
double dot(const std::vector<float>& a, const std::vector<float>& b) {
    using V = Eigen::Map<const Eigen::VectorXf>;
    return V(a.data(), static_cast<Eigen::Index>(a.size())).dot(V(b.data(), static_cast<Eigen::Index>(b.size())));
}

}  // namespace

struct NodeModel::State {
    ModelSpec model;
    RecordedReturnParams preprocess;
    ReturnSelection selection;
    BoundaryVectorLayer layer;
    PlaceCellNetwork net;
    bool learn;
    Scan scan;
    std::vector<double> bvc;
    // Templates: unit population vectors and their poses.
    std::vector<std::vector<float>> templates;
    std::vector<Eigen::Isometry3d> template_poses;
    std::vector<std::size_t> template_index;
    bool decode_place;
    // Revisits: every scan's unit descriptor and stamp.
    std::vector<std::vector<float>> history;
    std::vector<double> stamps;
    NodeParams p;

    State(const NodeParams& params, ModelSpec m)
        : model(std::move(m)),
          selection(selection_for(model.sensor, model.bvc.elevations.empty())),
          layer(model.bvc),
          net(model.bvc.n_cells(), model.place, params.seed),
          learn(params.learn),
          bvc(layer.n_cells()),
          decode_place(params.decode_place),
          p(params) {
        preprocess.min_range = params.min_range;
        preprocess.max_range = params.max_range;
        preprocess.slice_half_width = deg_to_rad(params.slice_half_width_deg);
        preprocess.validate();
        if (!params.weights.empty()) {
            const auto w = weights_from_trial_file(params.weights);
            if (w->n_place != model.place.n_place || w->n_bvc != model.bvc.n_cells())
                throw InputError("~weights: '" + params.weights + "' holds " + std::to_string(w->n_place) + " × " +
                                 std::to_string(w->n_bvc) + " weights; model '" + model.name + "' has " +
                                 std::to_string(model.place.n_place) + " × " + std::to_string(model.bvc.n_cells()));
            if (const std::string why = weights_model_mismatch(w->model_config, model); !why.empty())
                throw InputError("~weights: '" + params.weights + "' were trained by model '" + w->model +
                                 "', whose BVCs are not model '" + model.name + "''s: " + why);
            net.set_weights(w->values);
        }
        if (p.revisit_window_scans < 0 || !(p.revisit_window_s >= 0) || !(p.revisit_threshold >= 0))
            throw InputError("~revisit_window_scans, ~revisit_window_s and ~revisit_threshold must be >= 0");
        try {
            load_templates();
        } catch (const InputError& e) {
            throw InputError(std::string("the templates (~templates_bag with ~templates_cloud_topic and "
                                         "~templates_pose_topic or ~templates_tf_frames, or ~templates_scans with "
                                         "~templates_poses): ") +
                             e.what());
        }
    }

    void load_templates() {
        std::shared_ptr<const recording::Recording> rec;
        if (!p.templates_bag.empty()) {
            recording::BagSource s;
            s.bag = p.templates_bag;
            s.cloud_topic = p.templates_cloud_topic;
            s.pose_topic = p.templates_pose_topic;
            if (!p.templates_tf_frames.empty()) recording::parse_tf_frames(p.templates_tf_frames, s);
            rec = std::make_shared<const recording::Recording>(recording::open_bag_recording(s));
        } else if (!p.templates_scans.empty()) {
            rec = std::make_shared<const recording::Recording>(
                recording::open_recording(p.templates_scans, p.templates_poses));
        } else {
            return;
        }
        // The templates' rates as `bvc3d localize` makes them: a frozen replay (with ~weights if given).
        std::shared_ptr<const InitialWeights> weights;
        if (!p.weights.empty()) weights = weights_from_trial_file(p.weights);
        const ReplaySource source = recorded_source(rec, preprocess);
        const GroupResult r = run_replay({replay_trial(source, model, false, weights, p.seed)});
        const ReplayRates rates = replay_rates(r, 0, !decode_place);
        for (Eigen::Index i = 0; i < rates.rates.rows(); ++i) {
            std::vector<float> row(rates.rates.row(i).data(), rates.rates.row(i).data() + rates.rates.cols());
            normalise(row);
            templates.push_back(std::move(row));
            template_poses.push_back(rec->poses[static_cast<std::size_t>(i)].world_from_sensor);
            template_index.push_back(static_cast<std::size_t>(i));
        }
    }
};

NodeModel::NodeModel(const NodeParams& params)
    : s_(std::make_unique<State>(params, config::resolve_model(params.model))) {}
NodeModel::~NodeModel() = default;

std::size_t NodeModel::n_bvc() const { return s_->layer.n_cells(); }
std::size_t NodeModel::n_place() const { return static_cast<std::size_t>(s_->net.n_place()); }
std::size_t NodeModel::templates() const { return s_->templates.size(); }
std::string NodeModel::model_name() const { return s_->model.name; }

ScanResult NodeModel::step(const std::vector<double>& xyz, const Eigen::Isometry3d& pose, double stamp) {
    State& s = *s_;
    ScanResult out;
    // The replay's step: returns from the points, BVC rates, one place-cell step.
    returns_from_points(xyz, pose.linear(), s.preprocess, s.selection, s.scan);
    out.returns = s.scan.size();
    s.layer.rates(s.scan, s.bvc);
    const auto place = s.net.step(s.bvc, s.learn);
    out.bvc.assign(s.bvc.begin(), s.bvc.end());  // as a trial file records them: float32
    out.place.assign(place.begin(), place.end());

    if (!s.templates.empty()) {
        std::vector<float> v = s.decode_place ? out.place : out.bvc;
        normalise(v);
        double best = 0;
        std::size_t at = 0;
        for (std::size_t j = 0; j < s.templates.size(); ++j)
            if (const double c = dot(v, s.templates[j]); c > best) {  // ties: the lowest index
                best = c;
                at = j;
            }
        if (best > 0) out.decoded = Decoded{s.template_index[at], best, s.template_poses[at]};
    }

    std::vector<float> d = s.p.revisit_place ? out.place : out.bvc;
    normalise(d);
    const std::size_t i = s.history.size();
    double best = -2;
    std::size_t match = 0;
    for (std::size_t j = 0; j < i; ++j) {
        if (i - j <= static_cast<std::size_t>(s.p.revisit_window_scans)) break;  // j rises: the rest are too near
        if (!(stamp - s.stamps[j] > s.p.revisit_window_s)) continue;
        if (const double c = dot(d, s.history[j]); c > best) {
            best = c;
            match = j;
        }
    }
    if (best > -2 && 1 - best <= s.p.revisit_threshold)
        out.revisit = Revisit{static_cast<std::int64_t>(match), 1 - best};
    s.history.push_back(std::move(d));
    s.stamps.push_back(stamp);
    return out;
}

}  // namespace bvc3d::ros_node
