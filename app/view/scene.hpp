#pragma once
// What the viewer shows, computed from the library's stages: a trial file's arrays, the world it
// ran in, and at any recorded sample the sensor's returns and the BVC and place-cell rates; a world
// on its own; a recording (scans + poses). Each is encoded once as a blob (blob.hpp).
// Takes: files (trial files, world YAML or presets, scan lists and pose files). Gives: blobs.
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "bvc3d/config/model_spec.hpp"
#include "bvc3d/recorder/trial_file.hpp"
#include "bvc3d/recording/pose_file.hpp"
#include "bvc3d/recording/recording.hpp"
#include "bvc3d/recording/scan_list.hpp"
#include "bvc3d/world/world.hpp"
#include "view/blob.hpp"

namespace bvc3d::view {

// A world as the page draws it: triangles, the walkable outline, start points, and any point
// cloud (a recording's map).
std::string world_blob(const WorldDescription& world, const std::string& source, const std::vector<float>& points = {});

// What a model's scanner sees at a pose: the drawn scan's points (world frame), their ranges, which
// of them are in rows the model keeps, and the model's BVC rates (arrays points, range, kept, bvc);
// the header gains returns, model_returns and sensor_origin.
std::vector<BlobArray> sensed_arrays(const World& world, const ModelSpec& model, const Pose& pose,
                                     nlohmann::json& header);
// The same at a pose of the page's choosing, in a world shown on its own.
std::string probe_blob(const World& world, const ModelSpec& model, const Pose& pose);

// The scanner drawn at each step: the model's own, except that a spherical scanner is drawn with
// all its rows (the model keeps some), so the page shows the full scan.
LidarSpec drawn_sensor(const LidarSpec& model_sensor);

class TrialScene {
public:
    // Reads the file (InputError if it is missing, broken or not a trial file). The world and model
    // come from the file's configuration; a world that cannot be found (a YAML file that moved)
    // leaves world() empty and says why in world_problem().
    static std::shared_ptr<const TrialScene> load(const std::filesystem::path& file);

    const std::string& blob() const { return blob_; }  // the trial's arrays and identity
    std::size_t samples() const { return data_.x.size(); }
    // The sample's pose, returns (world frame), BVC rates and place-cell rates.
    std::string step_blob(std::size_t sample) const;
    const World* world() const { return world_.get(); }
    const std::string& world_source() const { return world_source_; }
    const std::string& world_problem() const { return world_problem_; }

private:
    Pose pose(std::size_t sample) const;
    void resolve_model_and_world(const std::filesystem::path& file);
    void encode(const std::filesystem::path& file);

    TrialFileData data_;
    std::vector<double> t_, heading_;
    std::optional<ModelSpec> model_;
    std::string model_problem_;
    std::shared_ptr<const World> world_;
    std::string world_source_, world_problem_;
    std::string blob_;
};

// A recording: scans paired with sensor poses, and the model whose BVCs the page shows.
class RecordingScene {
public:
    RecordingScene(std::shared_ptr<const recording::Recording> recording, ModelSpec model);
    std::size_t size() const { return recording_->size(); }
    const std::string& blob() const { return blob_; }  // poses and scan names
    // The points of a map: every few scans, thinned, in the world frame (for the world view).
    std::string map_blob() const;
    std::string scan_blob(std::size_t index) const;

private:
    std::shared_ptr<const recording::Recording> recording_;  // scans (files or a bag) paired with poses
    ModelSpec model_;
    std::string blob_;
};

}  // namespace bvc3d::view
