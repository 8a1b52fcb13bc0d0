#include "view/view_data.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <charconv>
#include <cmath>

#include "bvc3d/config/model_yaml.hpp"
#include "bvc3d/config/world_yaml.hpp"
#include "bvc3d/core/error.hpp"
#include "view/blob.hpp"
#include "view/safe_path.hpp"

namespace bvc3d::view {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

constexpr std::size_t trials_kept = 4;  // scenes kept in memory (two side by side, and some slack)

const std::string& param(const Query& q, const char* name) {
    const auto it = q.find(name);
    if (it == q.end() || it->second.empty()) throw RequestError(400, std::string("missing parameter '") + name + "'");
    return it->second;
}

std::size_t index_param(const Query& q, const char* name) {
    const std::string& text = param(q, name);
    std::size_t v = 0;
    const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
    if (ec != std::errc() || end != text.data() + text.size())
        throw RequestError(400, std::string("parameter '") + name + "' must be a whole number, not '" + text + "'");
    return v;
}

double number_param(const Query& q, const char* name) {
    const std::string& text = param(q, name);
    double v = 0;
    const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
    if (ec != std::errc() || end != text.data() + text.size() || !std::isfinite(v))
        throw RequestError(400, std::string("parameter '") + name + "' must be a finite number, not '" + text + "'");
    return v;
}

Reply blob_reply(std::string body) { return Reply{200, "application/octet-stream", std::move(body)}; }

}  // namespace

ViewData::ViewData(ViewTarget target) : target_(std::move(target)) {
    if (target_.recording)  // opened already: a bad recording fails before serving
        recording_ = std::make_unique<RecordingScene>(target_.recording, config::resolve_model(target_.model));
    // A recording given with trial files is the recording those trials replayed: checked before serving.
    if (target_.recording)
        for (const auto& name : target_.open) {
            const auto scene = trial(name);
            if (scene->replayed().empty())
                throw InputError("--scans/--poses (or --bag) with trial file '" + name +
                                 "': the trial did not replay a recording (its returns were cast in its world); "
                                 "view the recording on its own, or the trial without it");
        }
}

Reply ViewData::get(const std::string& endpoint, const Query& query) {
    try {
        return route(endpoint, query);
    } catch (const RequestError& e) {
        return Reply{e.status, "application/json", json{{"error", e.what()}}.dump()};
    } catch (const InputError& e) {
        return Reply{422, "application/json", json{{"error", e.what()}}.dump()};
    }
}

Reply ViewData::route(const std::string& endpoint, const Query& query) {
    if (endpoint == "index") {
        json index = {{"root", target_.root.empty() ? "" : target_.root.filename().string()},
                      {"trials", target_.trials},
                      {"open", target_.open},
                      {"world", target_.world},
                      {"worlds", target_.worlds},
                      {"recording", target_.recording != nullptr},
                      {"trajectory", target_.trajectory_name},
                      {"model", target_.model}};
        return Reply{200, "application/json", index.dump()};
    }
    if (endpoint == "trial") return blob_reply(trial(param(query, "path"))->blob());
    if (endpoint == "step") {
        const auto scene = trial(param(query, "path"));
        const std::size_t i = index_param(query, "i");
        if (i >= scene->samples())
            throw RequestError(
                404, "sample " + std::to_string(i) + " is past the trial's " + std::to_string(scene->samples()));
        return blob_reply(scene->step_blob(i));
    }
    if (endpoint == "world") return blob_reply(world_reply(query));
    if (endpoint == "probe") {
        const auto world = world_by_source(param(query, "source"));
        if (query.count("step")) {  // step i of the trajectory shown
            const std::size_t i = index_param(query, "step");
            if (i >= target_.trajectory.size())
                throw RequestError(404, "step " + std::to_string(i) + " is past the trajectory's " +
                                            std::to_string(target_.trajectory.size()));
            return blob_reply(probe_blob(*world, config::resolve_model(target_.model), target_.trajectory[i].pose, i));
        }
        const Pose pose =
            Pose::on_floor(number_param(query, "x"), number_param(query, "y"), number_param(query, "heading"));
        return blob_reply(probe_blob(*world, config::resolve_model(target_.model), pose));
    }
    if (endpoint == "recording") return blob_reply(recording().blob());
    if (endpoint == "trajectory") return blob_reply(trajectory_reply());
    if (endpoint == "scan") {
        const std::size_t i = index_param(query, "i");
        if (i >= recording().size())
            throw RequestError(
                404, "scan " + std::to_string(i) + " is past the recording's " + std::to_string(recording().size()));
        return blob_reply(recording().scan_blob(i));
    }
    throw RequestError(404, "no such data: '" + endpoint + "'");
}

std::shared_ptr<const TrialScene> ViewData::trial(const std::string& relative) {
    const auto file = path_inside(target_.root, relative);
    if (!file) throw RequestError(403, "'" + relative + "' is not inside the served folder");
    std::error_code ec;
    if (fs::is_directory(*file, ec)) throw RequestError(422, "trial file '" + relative + "' is a folder, not a file");
    if (!fs::is_regular_file(*file, ec)) throw RequestError(404, "trial file '" + relative + "' does not exist");
    {
        std::lock_guard lock(mutex_);
        if (auto it = trials_.find(*file); it != trials_.end()) {
            it->second.used = ++clock_;
            return it->second.scene;
        }
    }
    // Read outside the lock: another browser may be loading another file meanwhile. Two requests for
    // the same new file may both read it; the second result is dropped.
    // A recording given on the command line belongs to the trials opened first (checked when
    // serving starts); the other trials of a folder find their own.
    const bool opened = std::find(target_.open.begin(), target_.open.end(), relative) != target_.open.end();
    auto scene = TrialScene::load(*file, opened ? target_.recording : nullptr);
    std::lock_guard lock(mutex_);
    auto& slot = trials_[*file];
    if (!slot.scene) slot.scene = scene;
    slot.used = ++clock_;
    while (trials_.size() > trials_kept) {
        auto oldest = std::min_element(trials_.begin(), trials_.end(),
                                       [](const auto& a, const auto& b) { return a.second.used < b.second.used; });
        trials_.erase(oldest);
    }
    return slot.scene;
}

std::string ViewData::world_reply(const Query& query) {
    if (query.count("trial")) {
        const auto scene = trial(param(query, "trial"));
        if (!scene->replayed().empty()) return scene->recording_map_blob();
        if (!scene->world()) throw RequestError(422, scene->world_problem());
        return world_blob(scene->world()->description(), scene->world_source());
    }
    if (query.count("recording")) return recording().map_blob();
    const std::string& source = param(query, "source");
    return world_blob(world_by_source(source)->description(), source);
}

std::shared_ptr<const World> ViewData::world_by_source(const std::string& source) {
    {
        std::lock_guard lock(mutex_);
        if (auto it = worlds_.find(source); it != worlds_.end()) return it->second;
    }
    const auto presets = config::world_preset_names();
    std::shared_ptr<const World> world;
    if (std::find(presets.begin(), presets.end(), source) != presets.end()) {
        world = std::make_shared<World>(config::resolve_world(source));
    } else {
        const auto file = path_inside(target_.root, source);
        if (target_.root.empty() || !file) throw RequestError(403, "'" + source + "' is not inside the served folder");
        std::error_code ec;
        if (fs::is_directory(*file, ec))
            throw RequestError(422, "world file '" + source + "' is a folder, not a world file");
        if (!fs::is_regular_file(*file, ec)) throw RequestError(404, "world file '" + source + "' does not exist");
        world = std::make_shared<World>(config::resolve_world(file->string()));  // YAML or Gazebo (.world, .sdf)
    }
    std::lock_guard lock(mutex_);
    return worlds_.emplace(source, std::move(world)).first->second;
}

std::string ViewData::trajectory_reply() const {
    const auto& steps = target_.trajectory;
    if (steps.empty()) throw RequestError(404, "no trajectory is being shown (bvc3d view WORLD --trajectory FILE)");
    std::vector<double> t, x, y, z, heading;
    for (const ModelStep& s : steps) {
        t.push_back(s.t);
        x.push_back(s.pose.x);
        y.push_back(s.pose.y);
        z.push_back(s.pose.z);
        heading.push_back(s.pose.heading);
    }
    return encode_blob(
        {{"name", target_.trajectory_name}, {"steps", steps.size()}},
        {f64_array("t", t), f64_array("x", x), f64_array("y", y), f64_array("z", z), f64_array("heading", heading)});
}

const RecordingScene& ViewData::recording() {
    if (!recording_)
        throw RequestError(404, "no recording is being shown (bvc3d view --scans ... --poses ..., or --bag ...)");
    return *recording_;
}

}  // namespace bvc3d::view
