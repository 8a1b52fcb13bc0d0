#include "view/scene.hpp"

#include <algorithm>
#include <cmath>

#include "bvc3d/analysis/hexbin.hpp"
#include "bvc3d/bvc/boundary_vector_layer.hpp"
#include "bvc3d/config/model_yaml.hpp"
#include "bvc3d/config/trial_yaml.hpp"
#include "bvc3d/config/world_yaml.hpp"
#include "bvc3d/core/error.hpp"
#include "bvc3d/core/format.hpp"
#include "bvc3d/recording/pairing.hpp"
#include "bvc3d/recording/scan_file.hpp"
#include "bvc3d/sensor/lidar.hpp"
#include "view/blob.hpp"

namespace bvc3d::view {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

json number_or_null(double v) { return std::isfinite(v) ? json(v) : json(nullptr); }

json value_json(const params::Value& v) {
    if (const auto* d = std::get_if<double>(&v)) return number_or_null(*d);
    if (const auto* i = std::get_if<long long>(&v)) return *i;
    if (const auto* b = std::get_if<bool>(&v)) return *b;
    if (const auto* s = std::get_if<std::string>(&v)) return *s;
    return nullptr;
}

// A stored array as float32 (or int32 for integers), under `name`.
BlobArray array_blob(const std::string& name, const NamedArray& a) {
    if (const auto* d = std::get_if<std::vector<double>>(&a.data))
        return f32_array(name, std::span<const double>(*d), a.shape);
    if (const auto* f = std::get_if<std::vector<float>>(&a.data))
        return f32_array(name, std::span<const float>(*f), a.shape);
    return i32_array(name, std::get<std::vector<std::int64_t>>(a.data), a.shape);
}

json sensor_json(const LidarSpec& s) {
    return {{"name", s.name},
            {"rows", s.elevations.size()},
            {"elevations", s.elevations},
            {"azimuth_count", s.azimuth_count},
            {"height", s.height},
            {"max_range", s.max_range}};
}

json model_json(const ModelSpec& m) {
    const auto& b = m.bvc;
    return {{"name", m.name},
            {"sensor", sensor_json(m.sensor)},
            {"bvc",
             {{"elevations", b.elevations},
              {"n_layers", b.n_layers()},
              {"n_dir", b.n_dir},
              {"n_per_axis", b.n_per_axis},
              {"max_dist", b.max_dist},
              {"n_cells", b.n_cells()}}},
            {"n_place", m.place.n_place}};
}

// Returns as world-frame points from the sensor at `origin`.
void add_point(std::vector<float>& xyz, const Vec3& origin, const LidarReturn& r) {
    const double c = std::cos(r.elevation);
    xyz.push_back(static_cast<float>(origin.x() + r.range * c * std::cos(r.azimuth)));
    xyz.push_back(static_cast<float>(origin.y() + r.range * c * std::sin(r.azimuth)));
    xyz.push_back(static_cast<float>(origin.z() + r.range * std::sin(r.elevation)));
}

// Which rows of the drawn sensor feed the model's BVCs: rows of the model's own sensor that its
// BVC layer's plan casts.
std::vector<char> kept_rows(const LidarSpec& drawn, const ModelSpec& model) {
    const auto plan = BoundaryVectorLayer(model.bvc).plan(model.sensor);
    std::vector<char> kept(drawn.elevations.size(), 0);
    for (std::size_t r = 0; r < drawn.elevations.size(); ++r)
        for (std::size_t j = 0; j < model.sensor.elevations.size(); ++j)
            if (std::abs(drawn.elevations[r] - model.sensor.elevations[j]) < 1e-9 && plan.rows[j]) kept[r] = 1;
    return kept;
}

// What a model reads of a recorded scan: the preprocessing's range limits and the elevations kept.
json reading_json(const RecordedReturnParams& p, const ModelSpec& model) {
    return {{"min_range", p.min_range},
            {"max_range", p.max_range},
            {"selection", selection_name(selection_for(model.sensor, model.bvc.elevations.empty()))},
            {"slice_half_width", p.slice_half_width}};
}

std::size_t nearest_row(const std::vector<double>& elevations, double e) {
    std::size_t best = 0;
    for (std::size_t r = 1; r < elevations.size(); ++r)
        if (std::abs(elevations[r] - e) < std::abs(elevations[best] - e)) best = r;
    return best;
}

}  // namespace

std::string world_blob(const WorldDescription& w, const std::string& source, const std::vector<float>& points) {
    std::vector<float> tri;
    tri.reserve(w.mesh.size() * 9);
    Eigen::AlignedBox3d box;
    for (std::size_t t = 0; t < w.mesh.size(); ++t)
        for (const auto& v : w.mesh.corners(t)) {
            box.extend(v);
            for (int k = 0; k < 3; ++k) tri.push_back(static_cast<float>(v[k]));
        }
    for (std::size_t i = 0; i + 2 < points.size(); i += 3) box.extend(Vec3(points[i], points[i + 1], points[i + 2]));
    json walkable = json::array(), starts = json::array();
    for (const auto& p : w.walkable.points) walkable.push_back({p.x(), p.y()});
    for (const auto& p : w.start.points) starts.push_back({p.x(), p.y()});
    json header = {
        {"kind", "world"},      {"name", w.name},         {"source", source},           {"triangles", w.mesh.size()},
        {"walkable", walkable}, {"start_points", starts}, {"points", points.size() / 3}};
    if (w.tilt_deg) header["tilt_deg"] = *w.tilt_deg;
    // Where the page first probes the world: a start point, or the middle of the walkable region.
    // As text, so that the page asks for exactly this pose (an export holds the reply under it).
    if (!w.walkable.points.empty() || !w.start.points.empty()) {
        Vec2 at = w.start.points.empty() ? Vec2(w.walkable.bounds().center()) : w.start.points.front();
        header["probe"] = {{"x", format_number(at.x())}, {"y", format_number(at.y())}, {"heading", "0"}};
    }
    if (!box.isEmpty())
        header["bounds"] = {{box.min().x(), box.min().y(), box.min().z()},
                            {box.max().x(), box.max().y(), box.max().z()}};
    std::vector<BlobArray> arrays{f32_array("triangles", std::span<const float>(tri), {w.mesh.size() * 3, 3})};
    if (!points.empty()) arrays.push_back(f32_array("points", std::span<const float>(points), {points.size() / 3, 3}));
    return encode_blob(std::move(header), arrays);
}

LidarSpec drawn_sensor(const LidarSpec& model_sensor) {
    if (model_sensor.name != "spherical") return model_sensor;
    LidarSpec all = LidarSpec::spherical(false);
    all.height = model_sensor.height;
    all.max_range = model_sensor.max_range;
    all.azimuth_offset = model_sensor.azimuth_offset;
    // Keep the model's own rows if it has some the preset lacks (a custom table named spherical).
    for (double e : model_sensor.elevations)
        if (std::none_of(all.elevations.begin(), all.elevations.end(),
                         [&](double a) { return std::abs(a - e) < 1e-9; }))
            return model_sensor;
    if (model_sensor.azimuth_count != all.azimuth_count) return model_sensor;
    return all;
}

std::shared_ptr<const TrialScene> TrialScene::load(const fs::path& file, const GivenRecording& given) {
    // Every error names the file: a reader's message that does not is prefixed with it.
    try {
        return load_unchecked(file, given);
    } catch (const InputError& e) {
        const std::string why = e.what();
        if (why.find(file.string()) != std::string::npos) throw;
        throw InputError("trial file '" + file.string() + "': " + why);
    }
}

std::shared_ptr<const TrialScene> TrialScene::load_unchecked(const fs::path& file, const GivenRecording& given) {
    auto s = std::make_shared<TrialScene>();
    s->data_ = read_trial_samples(file);
    auto doubles = [&](const char* name) {
        const auto a = read_trial_array(file, name);
        if (!a) return std::vector<double>(s->data_.x.size(), 0.0);
        if (const auto* d = std::get_if<std::vector<double>>(&a->data)) return *d;
        throw InputError("'" + file.string() + "': " + name + " is not float64");
    };
    s->t_ = doubles("samples/t");
    s->heading_ = doubles("samples/heading");
    if (s->t_.size() != s->data_.x.size() || s->heading_.size() != s->data_.x.size())
        throw InputError("'" + file.string() + "': samples/t and samples/heading must have one value per sample");
    s->resolve_model_and_world(file);
    s->resolve_recording(file, given);
    s->encode(file);
    return s;
}

TrialScene::TrialScene() = default;
TrialScene::~TrialScene() = default;

namespace {

// A path a trial file names: as it is when absolute, else beside the trial file, else from the
// current folder (where the command that wrote the trial ran, most often).
fs::path beside_or_here(const fs::path& trial, const std::string& named) {
    const fs::path p(named);
    std::error_code ec;
    if (p.is_absolute() || !fs::exists(trial.parent_path() / p, ec)) return p;
    return trial.parent_path() / p;
}

std::string attribute(const TrialIdentity& id, const std::string& name) {
    for (const auto& [k, v] : id.data_source)
        if (k == name) return v;
    return {};
}

}  // namespace

namespace {

// A recording's input as the trial's attributes name it, compared by what it reads: a file's name, or a bag's
// file name and what follows it (its topic, or "tf FIXED SENSOR").
std::string input_key(const std::string& source) {
    const auto colon = source.rfind(':');  // a bag's "<bag>:<topic>" or "<bag>:tf FIXED SENSOR"
    if (colon == std::string::npos || colon == 0) return fs::path(source).filename().string();
    return fs::path(source.substr(0, colon)).filename().string() + ":" + source.substr(colon + 1);
}

// Which of the recording's inputs (its scans, its poses) differ from those the trial replayed, in words.
std::string differing_inputs(const recording::Recording& rec, const std::string& scans, const std::string& poses) {
    std::string out;
    const auto compare = [&](const std::string& what, const std::string& mine, const std::string& theirs) {
        if (theirs.empty() || input_key(mine) == input_key(theirs)) return;
        out += (out.empty() ? "" : "; ") + what + " come from '" + mine + "', the trial's from '" + theirs + "'";
    };
    compare("its scans", rec.scans_source.string(), scans);
    compare("its poses", rec.poses_source.string(), poses);
    return out.empty() ? "its scans and poses are named as the trial's, but their contents (the pose file's bytes, "
                         "the scans' names and sizes, a bag's topics) differ"
                       : out;
}

}  // namespace

void TrialScene::resolve_recording(const fs::path& file, const GivenRecording& given) {
    replayed_ = attribute(data_, "recording");
    if (replayed_.empty()) return;
    // A replay has no world: what it saw is its recording.
    world_.reset();
    world_source_.clear();
    world_problem_.clear();
    std::string files;  // the recorded fingerprint of the scan and pose files
    try {
        const auto yaml = config::YamlView::load_string(data_.config, file.string());
        if (yaml.has("returns")) {
            const auto r = yaml["returns"];
            if (r.has("files")) files = r["files"].as_string();
            config::read_table(r, recorded_params_, RecordedReturnParams::table(), {"recording", "scans", "files"});
        }
    } catch (const InputError& e) {
        world_problem_ = e.what();
        return;
    }
    const std::string scans = attribute(data_, "recording_scans"), poses = attribute(data_, "recording_poses");
    std::shared_ptr<const recording::Recording> rec = given;
    std::string problem;
    if (!rec) {
        try {
            // A bag's scans are named "<bag>:<topic>": its options (topics, tf frames) are not recorded.
            std::error_code ec;
            const auto colon = scans.find(':');
            if (!fs::exists(beside_or_here(file, scans), ec) && colon != std::string::npos &&
                fs::exists(beside_or_here(file, scans.substr(0, colon)), ec))
                throw InputError("its scans are the messages of ROS bag '" + scans.substr(0, colon) +
                                 "', which is not opened again on its own");
            rec = std::make_shared<const recording::Recording>(
                recording::open_recording(beside_or_here(file, scans), beside_or_here(file, poses)));
        } catch (const InputError& e) {
            problem = e.what();
        }
    }
    // The files must be the ones replayed, and the poses those the trial recorded.
    if (rec && !files.empty() && rec->fingerprint() != files)
        problem = "the scan and pose files " + std::string(given ? "given" : "found") +
                  " are not those the trial replayed: " + differing_inputs(*rec, scans, poses) +
                  " (their fingerprint is " + rec->fingerprint() + ", the trial's " + files + ")";
    std::vector<ModelStep> steps;
    if (rec && problem.empty()) {
        try {
            steps = recording_steps(*rec);
        } catch (const InputError& e) {
            problem = e.what();
        }
    }
    if (rec && problem.empty()) {
        // Sample i read the scan recorded at its time (samples/t starts at the first scan's time).
        scan_of_sample_.resize(samples());
        std::size_t k = 0;
        for (std::size_t i = 0; i < samples(); ++i) {
            while (k + 1 < steps.size() && std::abs(steps[k + 1].t - t_[i]) <= std::abs(steps[k].t - t_[i])) ++k;
            scan_of_sample_[i] = k;
            const ModelStep& s = steps[k];
            const double dz = data_.z.empty() ? 0.0 : data_.z[i] - s.pose.z;
            if (std::hypot(s.pose.x - data_.x[i], s.pose.y - data_.y[i], dz) > 1e-3 || std::abs(s.t - t_[i]) > 1e-3) {
                problem = "sample " + std::to_string(i) + " at t " + format_number(t_[i]) + " s, (" +
                          format_number(data_.x[i]) + ", " + format_number(data_.y[i]) +
                          ") m, matches no scan of the recording: scan " + std::to_string(k) + " is at t " +
                          format_number(s.t) + " s, (" + format_number(s.pose.x) + ", " + format_number(s.pose.y) +
                          ") m (other poses, extrinsics or pairing than the replay's?)";
                break;
            }
        }
    }
    if (!problem.empty()) {
        scan_of_sample_.clear();
        const std::string what =
            "the trial replayed recording '" + replayed_ + "' (scans '" + scans + "', poses '" + poses + "')";
        if (given) throw InputError("--scans/--poses (or --bag) with trial file '" + file.string() + "': " + problem);
        world_problem_ = what + ", which cannot be shown: " + problem +
                         "; give the recording to bvc3d view with --scans and --poses (or --bag) after the trial file";
        return;
    }
    recording_ = rec;
    if (model_) recording_scene_ = std::make_unique<RecordingScene>(rec, *model_, recorded_params_);
    if (const auto b = read_trial_array(file, "samples/bvc_rates");
        b && b->shape.size() == 2 && b->shape[0] == samples()) {
        n_bvc_ = b->shape[1];
        if (const auto* f = std::get_if<std::vector<float>>(&b->data)) bvc_rates_ = *f;
        if (const auto* d = std::get_if<std::vector<double>>(&b->data)) bvc_rates_.assign(d->begin(), d->end());
    }
}

std::string TrialScene::recording_map_blob() const {
    if (!recording_scene_)
        throw InputError(world_problem_.empty() ? "the trial replayed no recording" : world_problem_);
    return recording_scene_->map_blob();
}

void TrialScene::resolve_model_and_world(const fs::path& file) {
    // The configuration as recorded; relative paths in it are tried next to the trial file first.
    try {
        const TrialConfig t = config::trial_from_yaml(config::YamlView::load_string(data_.config, file.string()));
        model_ = t.model;
        world_source_ = t.world.source;
        world_ = std::make_shared<World>(t.world.resolve());
        return;
    } catch (const InputError& e) {
        world_problem_ = e.what();
    }
    // The whole configuration does not resolve (most often a world file that moved): take the
    // model and world on their own.
    try {
        const auto yaml = config::YamlView::load_string(data_.config, file.string());
        if (yaml.has("model")) {
            const auto m = yaml["model"];
            model_ = m.is_scalar() ? config::resolve_model(m.as_string()) : config::model_from_yaml(m);
        } else {
            model_ = config::resolve_model(data_.model);
        }
    } catch (const InputError& e) {
        model_problem_ = e.what();
    }
    world_source_ = data_.world_source.empty() ? data_.world : data_.world_source;
    try {
        std::optional<double> tilt;
        if (std::isfinite(data_.tilt_deg) && world_source_ == "cross") tilt = data_.tilt_deg;
        world_ = std::make_shared<World>(config::resolve_world(world_source_, tilt));
        world_problem_.clear();
    } catch (const InputError& e) {
        world_problem_ = "the trial's world '" + world_source_ + "' cannot be opened: " + e.what();
    }
}

void TrialScene::encode(const fs::path& file) {
    const std::size_t n = data_.x.size();
    json metrics = json::object();
    for (const auto& [name, v] : data_.metric_attributes) metrics[name] = value_json(v);
    json swept = json::object();
    for (const auto& [k, v] : data_.swept) swept[k] = v;
    json header = {{"kind", "trial"},
                   {"name", data_.name},
                   {"condition", data_.condition},
                   {"swept", swept},
                   {"world", data_.world},
                   {"world_source", world_source_},
                   {"world_problem", world_problem_},
                   {"model_name", data_.model},
                   {"seed", data_.seed},
                   {"tilt_deg", number_or_null(data_.tilt_deg)},
                   {"samples", n},
                   {"n_place", data_.n_place},
                   {"dims", data_.z.empty() ? 2 : 3},
                   {"metrics", metrics},
                   {"model_problem", model_problem_}};
    if (model_) {
        header["model"] = model_json(*model_);
        if (replayed_.empty()) header["drawn_sensor"] = sensor_json(drawn_sensor(model_->sensor));
    }
    if (!replayed_.empty()) {
        // A replay: the recording's scans are what the model read; its rates are the recorded ones.
        json r = {{"name", replayed_},
                  {"scans_file", attribute(data_, "recording_scans")},
                  {"poses_file", attribute(data_, "recording_poses")},
                  {"shown", recording_ != nullptr},
                  {"bvc_recorded", n_bvc_ > 0}};
        if (recording_) r["scans"] = recording_->size();
        if (model_) r["reading"] = reading_json(recorded_params_, *model_);
        header["recording"] = r;
    }
    if (data_.extent) header["extent"] = *data_.extent;
    float rate_max = 0;  // the population's color scale
    for (float r : data_.rates) rate_max = std::max(rate_max, r);
    header["rate_max"] = rate_max;

    std::vector<BlobArray> arrays{
        f32_array("x", std::span<const double>(data_.x)), f32_array("y", std::span<const double>(data_.y)),
        f32_array("heading", std::span<const double>(heading_)), f32_array("t", std::span<const double>(t_))};
    if (!data_.z.empty()) arrays.push_back(f32_array("z", std::span<const double>(data_.z)));
    for (const char* name : {"bin_centers", "bin_counts", "rate_maps", "sai", "modality", "spatial_info", "peak_rate"})
        if (const auto a = read_trial_array(file, std::string("metrics/") + name))
            arrays.push_back(array_blob(name, *a));

    // The hexagons' size, for drawing maps as the figures do: the grid the analysis fits.
    const auto centers =
        std::find_if(arrays.begin(), arrays.end(), [](const BlobArray& a) { return a.name == "bin_centers"; });
    if (centers != arrays.end() && centers->shape.size() == 2 && centers->shape[1] == 2 && n > 0) {
        int gridsize = 50;
        for (const auto& [name, v] : data_.metric_attributes)
            if (name == "gridsize" && std::holds_alternative<long long>(v)) {
                // Checked as read, before narrowing: 2^40 must not become 0.
                const long long g = std::get<long long>(v);
                if (g < 2 || g > 100000)
                    throw InputError("trial file '" + file.string() + "': attribute 'metrics/gridsize' is " +
                                     std::to_string(g) + "; the hexagonal grid needs 2 to 100000");
                gridsize = static_cast<int>(g);
            }
        std::optional<analysis::Extent> extent;
        if (data_.extent && data_.extent->size() == 4)
            extent = analysis::Extent{(*data_.extent)[0], (*data_.extent)[1], (*data_.extent)[2], (*data_.extent)[3]};
        const auto grid = analysis::HexGrid::fit(data_.x, data_.y, gridsize, extent);
        header["grid"] = {{"kind", "hex"}, {"gridsize", gridsize}, {"sx", grid.sx}, {"sy", grid.sy}};
    } else if (centers != arrays.end() && centers->shape.size() == 2 && centers->shape[1] == 3) {
        header["grid"] = {{"kind", "voxel"}};
    }
    blob_ = encode_blob(std::move(header), arrays);
}

Pose TrialScene::pose(std::size_t i) const {
    return Pose{data_.x[i], data_.y[i], data_.z.empty() ? 0.0 : data_.z[i], heading_[i], 0.0, 0.0};
}

std::vector<BlobArray> sensed_arrays(const World& world, const ModelSpec& model, const Pose& p, json& header) {
    const LidarSpec drawn = drawn_sensor(model.sensor);
    const auto rows = kept_rows(drawn, model);
    const Scan all = Lidar(drawn).scan(world, p);
    const Vec3 origin = p.position() + p.rotation() * Vec3(0, 0, drawn.height);
    std::vector<float> xyz, range;
    std::vector<std::uint8_t> kept;
    xyz.reserve(all.size() * 3);
    for (const auto& r : all) {
        add_point(xyz, origin, r);
        range.push_back(static_cast<float>(r.range));
        kept.push_back(static_cast<std::uint8_t>(rows[nearest_row(drawn.elevations, r.elevation)]));
    }
    // The BVC rates from the model's own scanner, as the model computed them (without noise).
    const Scan seen = Lidar(model.sensor).scan(world, p);
    const BoundaryVectorLayer layer(model.bvc);
    std::vector<double> rates(layer.n_cells());
    layer.rates(seen, rates);
    header["returns"] = all.size();
    header["model_returns"] = seen.size();
    header["sensor_origin"] = {origin.x(), origin.y(), origin.z()};
    return {f32_array("points", std::span<const float>(xyz), {xyz.size() / 3, 3}),
            f32_array("range", std::span<const float>(range)), u8_array("kept", kept),
            f32_array("bvc", std::span<const double>(rates))};
}

std::string probe_blob(const World& world, const ModelSpec& model, const Pose& p, std::optional<std::size_t> step) {
    json header = {{"kind", "probe"},
                   {"x", p.x},
                   {"y", p.y},
                   {"z", p.z},
                   {"heading", p.heading},
                   {"model", model_json(model)},
                   {"drawn_sensor", sensor_json(drawn_sensor(model.sensor))}};
    if (step) header["step"] = *step;
    auto arrays = sensed_arrays(world, model, p, header);
    return encode_blob(std::move(header), arrays);
}

std::string TrialScene::step_blob(std::size_t i) const {
    if (i >= samples())
        throw InputError("sample " + std::to_string(i) + " is past the trial's " + std::to_string(samples()));
    const Pose p = pose(i);
    json header = {{"kind", "step"}, {"sample", i}, {"t", t_[i]},          {"x", p.x},
                   {"y", p.y},       {"z", p.z},    {"heading", p.heading}};
    std::vector<BlobArray> arrays;
    if (recording_ && model_) {
        const std::size_t scan = scan_of_sample_[i];
        header["scan"] = scan;
        header["scan_name"] = recording_->store->scan_name(scan);
        arrays = recorded_scan_arrays(*recording_, scan, *model_, recorded_params_, header);
        // The BVC rates the replay recorded; computed again from the scan when it did not record them.
        if (n_bvc_ > 0) {
            header["bvc_source"] = "recorded";
            arrays.push_back(f32_array("bvc", std::span<const float>(bvc_rates_.data() + i * n_bvc_, n_bvc_)));
        } else {
            header["bvc_source"] = "computed";
            arrays.push_back(f32_array(
                "bvc", std::span<const double>(recorded_scan_rates(*recording_, scan, *model_, recorded_params_))));
        }
    } else if (world_ && model_) {
        arrays = sensed_arrays(*world_, *model_, p, header);
        header["bvc_source"] = "computed";
    } else {
        const std::vector<float> none;
        arrays = {f32_array("points", std::span<const float>(none), {0, 3}),
                  f32_array("range", std::span<const float>(none)), u8_array("kept", {}),
                  f32_array("bvc", std::span<const float>(none))};
    }
    arrays.push_back(f32_array("place", std::span<const float>(data_.rates.data() + i * data_.n_place, data_.n_place)));
    return encode_blob(std::move(header), arrays);
}

// ---- recordings ----

RecordingScene::RecordingScene(std::shared_ptr<const recording::Recording> recording, ModelSpec model,
                               RecordedReturnParams params)
    : recording_(std::move(recording)), model_(std::move(model)), params_(params) {
    const auto& scans_ = recording_->scans;
    const auto& poses_ = recording_->poses;
    std::vector<float> position, rotation;
    json names = json::array(), times = json::array();
    for (std::size_t i = 0; i < scans_.size(); ++i) {
        const auto& T = poses_[i].world_from_sensor;
        for (int k = 0; k < 3; ++k) position.push_back(static_cast<float>(T.translation()[k]));
        for (int r = 0; r < 3; ++r)
            for (int c = 0; c < 3; ++c) rotation.push_back(static_cast<float>(T.linear()(r, c)));
        names.push_back(recording_->store->scan_name(i));
        const auto t = recording_->time(i);  // the scan list's, else the pose's
        times.push_back(t ? json(*t) : json(nullptr));
    }
    json header = {{"kind", "recording"},
                   {"scans", scans_.size()},
                   {"names", names},
                   {"times", times},
                   {"model", model_json(model_)},
                   {"paired_by_time", recording_->paired_by_time},
                   {"reading", reading_json(params_, model_)}};
    blob_ =
        encode_blob(std::move(header), {f32_array("position", std::span<const float>(position), {scans_.size(), 3}),
                                        f32_array("rotation", std::span<const float>(rotation), {scans_.size(), 9})});
}

std::string RecordingScene::map_blob() const {
    const auto& scans_ = recording_->scans;
    const auto& poses_ = recording_->poses;
    // At most 60 scans and 250 000 points: enough to see the place, quick to read and draw.
    const std::size_t every = std::max<std::size_t>(1, (scans_.size() + 59) / 60);
    const std::size_t used = (scans_.size() + every - 1) / every;
    const std::size_t per_scan = 250000 / std::max<std::size_t>(used, 1);
    std::vector<float> points;
    for (std::size_t i = 0; i < scans_.size(); i += every) {
        const auto cloud = recording_->load(i);
        const std::size_t stride = std::max<std::size_t>(1, (cloud.size() + per_scan - 1) / per_scan);
        const auto& T = poses_[i].world_from_sensor;
        for (std::size_t p = 0; p < cloud.size(); p += stride) {
            const Vec3 w = T * Vec3(cloud.xyz[3 * p], cloud.xyz[3 * p + 1], cloud.xyz[3 * p + 2]);
            for (int k = 0; k < 3; ++k) points.push_back(static_cast<float>(w[k]));
        }
    }
    WorldDescription empty;
    empty.name = "recording";
    return world_blob(empty, "recording", points);
}

std::vector<BlobArray> recorded_scan_arrays(const recording::Recording& rec, std::size_t i, const ModelSpec& model,
                                            const RecordedReturnParams& params, json& header) {
    const auto cloud = rec.load(i);
    const auto& T = rec.poses[i].world_from_sensor;
    const Eigen::Matrix3d R = T.linear();
    const ReturnSelection selection = selection_for(model.sensor, model.bvc.elevations.empty());
    const auto& psi = model.bvc.elevations;
    const double window = 4 * model.bvc.sigma_phi;
    std::vector<float> xyz, range;
    std::vector<std::uint8_t> kept;
    std::size_t read = 0;
    Scan one;
    for (std::size_t p = 0; p < cloud.size(); ++p) {
        const std::span<const double> point(cloud.xyz.data() + 3 * p, 3);
        const Vec3 local(point[0], point[1], point[2]);
        const double r = (R * local).norm();
        if (!(r > 0)) continue;
        // Whether the model reads it: the replay's own preprocessing, on this one point.
        returns_from_points(point, R, params, selection, one);
        const bool is_read = !one.empty();
        read += is_read;
        const bool near_layer = psi.empty() || (is_read && std::any_of(psi.begin(), psi.end(), [&](double e) {
                                                    return std::abs(one.front().elevation - e) <= window;
                                                }));
        const Vec3 w = T * local;
        for (int k = 0; k < 3; ++k) xyz.push_back(static_cast<float>(w[k]));
        range.push_back(static_cast<float>(r));
        kept.push_back(is_read && near_layer ? 1 : 0);
    }
    const Vec3 origin = T.translation();
    header["returns"] = read;
    header["points"] = range.size();
    header["sensor_origin"] = {origin.x(), origin.y(), origin.z()};
    header["dropped_nonfinite"] = cloud.dropped_nonfinite;
    return {f32_array("points", std::span<const float>(xyz), {xyz.size() / 3, 3}),
            f32_array("range", std::span<const float>(range)), u8_array("kept", kept)};
}

std::vector<double> recorded_scan_rates(const recording::Recording& rec, std::size_t i, const ModelSpec& model,
                                        const RecordedReturnParams& params) {
    const auto cloud = rec.load(i);
    Scan returns;
    returns_from_points(cloud.xyz, rec.poses[i].world_from_sensor.linear(), params,
                        selection_for(model.sensor, model.bvc.elevations.empty()), returns);
    const BoundaryVectorLayer layer(model.bvc);
    std::vector<double> rates(layer.n_cells());
    layer.rates(returns, rates);
    return rates;
}

std::string RecordingScene::scan_blob(std::size_t i) const {
    if (i >= recording_->size())
        throw InputError("scan " + std::to_string(i) + " is past the recording's " +
                         std::to_string(recording_->size()));
    json header = {{"kind", "scan"}, {"scan", i}, {"name", recording_->store->scan_name(i)}};
    auto arrays = recorded_scan_arrays(*recording_, i, model_, params_, header);
    arrays.push_back(f32_array("bvc", std::span<const double>(recorded_scan_rates(*recording_, i, model_, params_))));
    if (const auto t = recording_->time(i)) header["t"] = *t;
    return encode_blob(std::move(header), arrays);
}

}  // namespace bvc3d::view
