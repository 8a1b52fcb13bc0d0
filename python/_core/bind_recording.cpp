// Recordings: Recording (scans + poses), replays through models, localization.
#include "bindings.hpp"

#include <limits>

#include "bvc3d/agent/trajectory.hpp"
#include "bvc3d/analysis/localization.hpp"
#include "bvc3d/config/model_yaml.hpp"
#include "bvc3d/config/world_yaml.hpp"
#include "bvc3d/experiment/replay.hpp"
#include "bvc3d/recorder/trial_file.hpp"
#include "bvc3d/recording/bag_recording.hpp"
#include "bvc3d/recording/extrinsics.hpp"
#include "bvc3d/recording/recording.hpp"

namespace bvc3d::py {

namespace {

using RecordingPtr = std::shared_ptr<recording::Recording>;  // pybind11 holders are non-const
using ArrayF = pyb::array_t<float, pyb::array::c_style | pyb::array::forcecast>;

RecordedReturnParams preprocess_of(const pyb::kwargs& kwargs, const std::vector<std::string>& skip) {
    RecordedReturnParams p;
    apply_kwargs(p, RecordedReturnParams::table(), kwargs, skip);
    return p;
}

pyb::array_t<double> matrix4(const Eigen::Isometry3d& m) {
    const Eigen::Matrix<double, 4, 4, Eigen::RowMajor> r = m.matrix();
    return to_numpy(r.data(), {4, 4});
}

pyb::array_t<double> points_of(const recording::PointCloud& c) {
    return to_numpy(c.xyz.data(), {static_cast<pyb::ssize_t>(c.size()), 3});
}

std::shared_ptr<const InitialWeights> weights_of(const pyb::object& obj) {
    if (obj.is_none()) return nullptr;
    auto w = std::make_shared<InitialWeights>();
    if (pyb::isinstance<pyb::str>(obj) || pyb::hasattr(obj, "__fspath__")) {
        return weights_from_trial_file(pyb::str(obj).cast<std::string>());
    }
    const auto a = obj.cast<ArrayF>();
    if (a.ndim() != 2) throw InputError("weights must be a trial file or an (n_place, n_bvc) array");
    w->source = "array";
    w->values.assign(a.data(), a.data() + a.size());
    w->n_place = static_cast<int>(a.shape(0));
    w->n_bvc = static_cast<int>(a.shape(1));
    return w;
}

pyb::dict run(const ReplaySource& source, const std::string& model, bool learn, const pyb::object& weights,
              std::uint64_t seed) {
    const TrialConfig t = replay_trial(source, config::resolve_model(model), learn, weights_of(weights), seed);
    GroupResult r;
    {
        pyb::gil_scoped_release release;
        r = run_replay({t});
    }
    return samples_to_dict(r, true);  // a replay records the BVC rates
}

// Extrinsics from Python: a file, or 12/16 numbers.
Eigen::Isometry3d extrinsics_of(const pyb::object& extrinsics) {
    if (pyb::isinstance<pyb::str>(extrinsics) || pyb::hasattr(extrinsics, "__fspath__"))
        return recording::read_extrinsics(pyb::str(extrinsics).cast<std::string>());
    // Python's repr of each float is its shortest exact text: the parser reads what numpy holds.
    const auto a = extrinsics.cast<ArrayD>();
    std::string text;
    for (pyb::ssize_t i = 0; i < a.size(); ++i) text += pyb::repr(pyb::float_(a.data()[i])).cast<std::string>() + " ";
    return recording::parse_extrinsics(text, "extrinsics");
}

const char* preprocess_doc = "Preprocessing keywords (docs/recordings.md):\n";

// A scan index: a Python integer, negative from the end as in a list; past the end (or not an integer)
// an InputError naming the recording and the index, as Recording::load words it.
std::size_t scan_index(const recording::Recording& r, const pyb::handle& obj) {
    if (pyb::isinstance<pyb::bool_>(obj) || !pyb::hasattr(obj, "__index__"))
        throw InputError("recording '" + r.name + "': a scan index must be an integer, not " +
                         pyb::str(pyb::type::of(obj).attr("__name__")).cast<std::string>());
    const auto n = static_cast<long long>(r.size());
    long long i = 0;
    try {
        i = obj.cast<long long>();
    } catch (const pyb::cast_error&) {
        i = std::numeric_limits<long long>::max();
    }
    if (i < 0 && i >= -n) i += n;
    if (i < 0 || i >= n)
        throw InputError("recording '" + r.name + "': scan " + pyb::str(obj).cast<std::string>() + " does not exist (" +
                         std::to_string(n) + " scans)");
    return static_cast<std::size_t>(i);
}

void bind_recording_class(pyb::module_& m) {
    pyb::class_<recording::Recording, RecordingPtr>(m, "Recording", R"doc(
A recording: scans (PCD, PLY, KITTI .bin) in order, each with its pose (world_from_sensor, 4×4) and
time. Recording.open(scans, poses) reads a scan folder or list file and a pose file (KITTI, TUM or
4×4 rows) and pairs them (in order, or by time). Iterating gives (pose, points) pairs: a (4, 4)
array and the scan's (N, 3) points in the sensor frame (docs/recordings.md).)doc")
        .def_static(
            "open",
            [](const std::filesystem::path& scans, const std::filesystem::path& poses, const std::string& pose_format,
               const pyb::object& extrinsics, double time_tolerance) {
                recording::RecordingOptions o;
                o.pose_format = recording::parse_pose_format(pose_format);
                o.time_tolerance = time_tolerance;
                if (!extrinsics.is_none()) o.base_from_sensor = extrinsics_of(extrinsics);
                return std::make_shared<recording::Recording>(recording::open_recording(scans, poses, o));
            },
            pyb::arg("scans"), pyb::arg("poses"), pyb::arg("pose_format") = "auto",
            pyb::arg("extrinsics") = pyb::none(),
            pyb::arg("time_tolerance") = recording::RecordingOptions{}.time_tolerance,
            "extrinsics: base_from_sensor as a file or 12/16 numbers; the poses are then the base's")
        .def_static(
            "open_bag",
            [](const std::filesystem::path& bag, const std::string& cloud_topic, const std::string& pose_topic,
               const std::string& tf_frames, double tf_tolerance, const pyb::object& extrinsics,
               double time_tolerance) {
                recording::RecordingOptions o;
                o.time_tolerance = time_tolerance;
                if (!extrinsics.is_none()) o.base_from_sensor = extrinsics_of(extrinsics);
                recording::BagSource s;
                s.bag = bag;
                s.cloud_topic = cloud_topic;
                s.pose_topic = pose_topic;
                if (!tf_frames.empty()) recording::parse_tf_frames(tf_frames, s);
                s.tf_tolerance = tf_tolerance;
                std::shared_ptr<recording::Recording> r;
                {
                    pyb::gil_scoped_release release;
                    r = std::make_shared<recording::Recording>(recording::open_bag_recording(s, o));
                }
                return r;
            },
            pyb::arg("bag"), pyb::arg("cloud_topic"), pyb::arg("pose_topic") = "", pyb::arg("tf_frames") = "",
            pyb::arg("tf_tolerance") = recording::BagSource{}.tf_tolerance, pyb::arg("extrinsics") = pyb::none(),
            pyb::arg("time_tolerance") = recording::RecordingOptions{}.time_tolerance,
            R"doc(A ROS bag as a recording (docs/ros.md): bag is a ROS 1 .bag, an .mcap file or a ROS 2 bag folder;
cloud_topic a sensor_msgs/PointCloud2 topic; the poses from pose_topic (nav_msgs/Odometry or
geometry_msgs/PoseStamped, each cloud paired with the pose nearest its stamp within time_tolerance)
or from tf, tf_frames="FIXED,SENSOR" (the chain interpolated at each cloud's stamp; tf_tolerance
bounds a link's gap, s). extrinsics as for open.)doc")
        .def_property_readonly("name", [](const recording::Recording& r) { return r.name; })
        .def("__len__", &recording::Recording::size)
        .def_property_readonly(
            "poses",
            [](const recording::Recording& r) {
                pyb::array_t<double> a({static_cast<pyb::ssize_t>(r.size()), pyb::ssize_t{4}, pyb::ssize_t{4}});
                auto v = a.mutable_unchecked<3>();
                for (std::size_t i = 0; i < r.size(); ++i) {
                    const Eigen::Matrix4d mm = r.poses[i].world_from_sensor.matrix();
                    for (int j = 0; j < 4; ++j)
                        for (int k = 0; k < 4; ++k) v(i, j, k) = mm(j, k);
                }
                return a;
            },
            "(n, 4, 4) world_from_sensor poses")
        .def_property_readonly(
            "times",
            [](const recording::Recording& r) {
                std::vector<double> t;
                for (std::size_t i = 0; i < r.size(); ++i) t.push_back(r.time(i).value_or(NAN));
                return to_numpy(t.data(), {static_cast<pyb::ssize_t>(t.size())});
            },
            "(n,) scan times in seconds (NaN where the recording has none)")
        .def_property_readonly("scan_paths",
                               [](const recording::Recording& r) {
                                   std::vector<std::string> p;
                                   for (const auto& s : r.scans) p.push_back(s.path.string());
                                   return p;
                               })
        .def(
            "points",
            [](const recording::Recording& r, const pyb::object& index) {
                const std::size_t i = scan_index(r, index);
                recording::PointCloud c;
                {
                    pyb::gil_scoped_release release;
                    c = r.load(i);
                }
                return points_of(c);
            },
            pyb::arg("i"), "Scan i's (N, 3) points in the sensor frame (NaN points dropped)")
        .def("__getitem__",
             [](const recording::Recording& r, long i) {
                 const long n = static_cast<long>(r.size());
                 if (i < 0) i += n;
                 if (i < 0 || i >= n) throw pyb::index_error("scan index out of range");
                 const auto k = static_cast<std::size_t>(i);
                 return pyb::make_tuple(matrix4(r.poses[k].world_from_sensor), points_of(r.load(k)));
             })
        .def(
            "returns",
            [](const RecordingPtr& r, const pyb::object& index, const std::string& model, const pyb::kwargs& kwargs) {
                const std::size_t i = scan_index(*r, index);
                const ModelSpec spec = config::resolve_model(model);
                const RecordedReturnParams p = preprocess_of(kwargs, {});
                const recording::PointCloud cloud = r->load(i);
                Scan s;
                returns_from_points(cloud.xyz, r->poses.at(i).world_from_sensor.linear(), p,
                                    selection_for(spec.sensor, spec.bvc.elevations.empty()), s);
                static_assert(sizeof(LidarReturn) == 3 * sizeof(double));
                return to_numpy(reinterpret_cast<const double*>(s.data()), {static_cast<pyb::ssize_t>(s.size()), 3});
            },
            pyb::arg("i"), pyb::arg("model") = "3d-0.2",
            (std::string(R"doc(Scan i's returns as `model` reads them: an (N, 3) array of range, allocentric azimuth,
elevation (gravity-aligned by the scan's pose; the 3-D presets keep the upper half, 2-D models the
horizontal slice). )doc") +
             preprocess_doc + describe(RecordedReturnParams::table(), RecordedReturnParams{}))
                .c_str())
        .def(
            "replay",
            [](const RecordingPtr& r, const std::string& model, bool learn, const pyb::object& weights,
               std::uint64_t seed, const pyb::kwargs& kwargs) {
                return run(recorded_source(r, preprocess_of(kwargs, {})), model, learn, weights, seed);
            },
            pyb::arg("model") = "3d-0.2", pyb::arg("learn") = false, pyb::arg("weights") = pyb::none(),
            pyb::arg("seed") = 0,
            (std::string(
                 R"doc(Every scan through `model`, as `bvc3d replay` does it: a dict of arrays t, x, y, z, heading
(n,), bvc_rates (n, n_bvc), rates (n, n_place) and the final weights. learn: place cells learn
(online); weights: a trial file or an array to start from (default: the seed's draw). )doc") +
             preprocess_doc + describe(RecordedReturnParams::table(), RecordedReturnParams{}))
                .c_str())
        .def("__repr__", [](const recording::Recording& r) {
            return "Recording('" + r.name + "', " + std::to_string(r.size()) + " scans)";
        });
}

}  // namespace

void bind_recording(pyb::module_& m) {
    bind_recording_class(m);
    m.def(
        "replay_simulated",
        [](const pyb::object& world, const pyb::object& trajectory, const pyb::object& sensor, const std::string& model,
           bool learn, const pyb::object& weights, std::uint64_t seed, const pyb::kwargs& kwargs) {
            const WorldSpec where = world_source_of(world, "replay_simulated: world");
            const auto path = trajectory_of(trajectory, kwargs);
            const LidarSpec s = pyb::isinstance<pyb::str>(sensor) ? config::resolve_sensor(sensor.cast<std::string>())
                                                                  : sensor.cast<LidarSpec>();
            return run(simulated_source(where, path, s, preprocess_of(kwargs, trajectory_keywords())), model, learn,
                       weights, seed);
        },
        pyb::arg("world"), pyb::arg("trajectory"), pyb::arg("sensor"), pyb::arg("model") = "3d-0.2",
        pyb::arg("learn") = false, pyb::arg("weights") = pyb::none(), pyb::arg("seed") = 0,
        R"doc(A simulated sensor along a path in a world, its scans preprocessed as a recording's, through `model`
(as `bvc3d replay --world --trajectory --sensor`): the dict Recording.replay gives. trajectory: a
file or a dict of arrays t, x, y, heading[, z, pitch, roll], resampled to the model step (model_dt=0.288 s:
positions linearly, headings and roll along the shorter arc) unless its rows are at that step already;
step_per_row=True takes one scan and model step per row instead. sensor: a name, a YAML file or a
Sensor. Preprocessing keywords as Recording.replay.)doc");
    m.def(
        "localize",
        [](const pyb::object& templates_in, const pyb::object& template_xyz_in, const pyb::object& queries_in,
           const pyb::object& query_xyz_in) {
            // Real numbers only (no booleans, complex or text cast into numbers), as every array argument.
            const ArrayF templates = real_array_f32(templates_in, "templates");
            const ArrayF queries = real_array_f32(queries_in, "queries");
            const ArrayD template_xyz = real_array(template_xyz_in, "template_positions");
            const ArrayD query_xyz = real_array(query_xyz_in, "query_positions");
            auto matrix = [](const auto& a, const char* name) {
                if (a.ndim() != 2) throw InputError(std::string(name) + " must be a 2-D array");
                return a;
            };
            matrix(templates, "templates");
            matrix(queries, "queries");
            matrix(template_xyz, "template_positions");
            matrix(query_xyz, "query_positions");
            using namespace analysis;
            const Eigen::Map<const RowMatrixXf> t(templates.data(), templates.shape(0), templates.shape(1));
            const Eigen::Map<const RowMatrixXf> q(queries.data(), queries.shape(0), queries.shape(1));
            const Eigen::Map<const Points> tp(template_xyz.data(), template_xyz.shape(0), template_xyz.shape(1));
            const Eigen::Map<const Points> qp(query_xyz.data(), query_xyz.shape(0), query_xyz.shape(1));
            LocalizationResult r;
            {
                pyb::gil_scoped_release release;
                r = analysis::localize(t, tp, q, qp);
            }
            auto summary = [](const ErrorSummary& s) {
                pyb::dict d;
                d["median_m"] = s.median;
                d["mean_m"] = s.mean;
                d["within_1m"] = s.within_1m;
                d["within_2m"] = s.within_2m;
                return d;
            };
            const auto n = static_cast<pyb::ssize_t>(r.decoded.size());
            pyb::dict out;
            std::vector<std::int64_t> decoded(r.decoded.begin(), r.decoded.end());
            out["decoded"] = to_numpy(decoded.data(), {n});
            out["similarity"] = to_numpy(r.similarity.data(), {n});
            out["error"] = to_numpy(r.error.data(), {n});
            out["vertical_error"] = to_numpy(r.vertical_error.data(), {n});
            out["nearest_error"] = to_numpy(r.nearest_error.data(), {n});
            out["n_undecoded"] = r.n_undecoded;
            out["decoded_summary"] = summary(r.decoded_summary);
            out["chance"] = summary(r.chance);
            out["nearest"] = summary(r.nearest);
            out["vertical_median_m"] = r.vertical_median;
            out["vertical_mean_m"] = r.vertical_mean;
            return out;
        },
        pyb::arg("templates"), pyb::arg("template_positions"), pyb::arg("queries"), pyb::arg("query_positions"),
        R"doc(Localization on recordings (docs/analysis.md#localization-on-recordings): templates (T, C) and
queries (Q, C) population vectors (float32), positions (T, 3) and (Q, 3) as x, y, z. Each query is
decoded to the most cosine-similar template (ties: the lowest index; no positive similarity:
undecoded, index -1, left out of the summaries). Returns per query: decoded, similarity, error
(horizontal, m), vertical_error, nearest_error (to the nearest template); and summaries
decoded_summary, chance (a uniformly random template), nearest (the best possible): dicts of
median_m, mean_m, within_1m, within_2m.)doc");
}

}  // namespace bvc3d::py
