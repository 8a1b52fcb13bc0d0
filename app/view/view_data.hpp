#pragma once
// The viewer's data API, independent of HTTP: the server (server.hpp) and the static export
// (export.hpp) both answer the page's requests here (endpoints: docs/viewer.md#data).
// Takes: what `bvc3d view` was asked to show. Gives: replies (JSON or blobs) to named requests.
#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "bvc3d/agent/agent.hpp"
#include "bvc3d/config/model_spec.hpp"
#include "view/scene.hpp"

namespace bvc3d::view {

struct ViewTarget {
    std::filesystem::path root;       // the served folder: requests name files inside it
    std::vector<std::string> trials;  // trial files, relative to root, in listing order
    std::vector<std::string> open;    // the trials opened first (a second one is shown beside)
    std::string world;                // a world opened first: a preset or a YAML file relative to root
    std::vector<std::string> worlds;  // the worlds offered: presets and YAML files under root
    std::shared_ptr<const bvc3d::recording::Recording> recording;  // a recording (scan files or a bag), opened
    std::string model = "3d-0.2";                                  // the model whose BVCs a recording's page shows
    // A path drawn over the world (`--trajectory FILE`: a route, a tour, a walk), its rows as the file has them.
    std::string trajectory_name;
    std::vector<ModelStep> trajectory;
};

struct Reply {
    int status = 200;
    std::string content_type = "application/json";
    std::string body;
};

using Query = std::map<std::string, std::string>;

class ViewData {
public:
    explicit ViewData(ViewTarget target);
    const ViewTarget& target() const { return target_; }

    // index, trial?path=, step?path=&i=, world?source= | world?trial= | world?recording=1,
    // probe?source=&x=&y=&heading= | probe?source=&step= (the default model's view at that pose, or at the trajectory's
    // step), recording, scan?i=, trajectory (the path drawn over the world). Errors are replies with a status and
    // {"error": message}: 400 bad request, 403 a path outside the served folder, 404 missing, 422 a file that cannot
    // be read (or a folder where a file is named).
    Reply get(const std::string& endpoint, const Query& query);

    std::size_t recording_scans() const { return recording_ ? recording_->size() : 0; }

    // The trial scene for a path relative to root (cached: the last few opened stay in memory).
    std::shared_ptr<const TrialScene> trial(const std::string& relative);

private:
    Reply route(const std::string& endpoint, const Query& query);
    std::string world_reply(const Query& query);
    std::string trajectory_reply() const;
    std::shared_ptr<const World> world_by_source(const std::string& source);
    const RecordingScene& recording();

    ViewTarget target_;
    std::mutex mutex_;
    struct Cached {
        std::shared_ptr<const TrialScene> scene;
        std::uint64_t used = 0;
    };
    std::map<std::filesystem::path, Cached> trials_;
    std::uint64_t clock_ = 0;
    std::map<std::string, std::shared_ptr<const World>> worlds_;  // by source (ray casting is built once)
    std::unique_ptr<const RecordingScene> recording_;
};

// Request errors carry their HTTP status.
struct RequestError : std::runtime_error {
    RequestError(int s, const std::string& message) : std::runtime_error(message), status(s) {}
    int status;
};

}  // namespace bvc3d::view
