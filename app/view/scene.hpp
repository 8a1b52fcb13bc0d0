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
#include "bvc3d/sensor/recorded_returns.hpp"
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
std::string probe_blob(const World& world, const ModelSpec& model, const Pose& pose,
                       std::optional<std::size_t> step = std::nullopt);  // step: of the trajectory shown

// The scanner drawn at each step: the model's own, except that a spherical scanner is drawn with
// all its rows (the model keeps some), so the page shows the full scan.
LidarSpec drawn_sensor(const LidarSpec& model_sensor);

// One recorded scan as the page draws it: its points in the world frame (arrays points, range,
// kept), kept = the points that drive the model's BVC layers (read by the model after the
// preprocessing `params`, and within 4σφ of a layer's elevation); the header gains returns (the
// points the model reads), points and sensor_origin.
std::vector<BlobArray> recorded_scan_arrays(const recording::Recording& recording, std::size_t scan,
                                            const ModelSpec& model, const RecordedReturnParams& params,
                                            nlohmann::json& header);
// The model's BVC rates for that scan, as a replay computes them.
std::vector<double> recorded_scan_rates(const recording::Recording& recording, std::size_t scan, const ModelSpec& model,
                                        const RecordedReturnParams& params);

class RecordingScene;

// A trial that replayed a recording (`bvc3d replay`) is shown with that recording: its scans instead
// of a world's. The recording is the one given to `bvc3d view` (--scans/--poses or --bag), else the
// files the trial names (relative paths: beside the trial file, then from the current folder).
using GivenRecording = std::shared_ptr<const recording::Recording>;

class TrialScene {
public:
    // Reads the file (InputError naming the file if it is missing, broken or not a trial file). The
    // world and model come from the file's configuration; a world that cannot be found (a YAML file
    // that moved) leaves world() empty and says why in world_problem(). A replay's recording: see
    // GivenRecording; one given that is not the trial's (other files, other poses) is an InputError.
    static std::shared_ptr<const TrialScene> load(const std::filesystem::path& file, const GivenRecording& given = {});
    TrialScene();
    ~TrialScene();

    // The name of the recording the trial replayed ("" for a trial in a world).
    const std::string& replayed() const { return replayed_; }
    // The recording's map as a world blob (replays only).
    std::string recording_map_blob() const;

    const std::string& blob() const { return blob_; }  // the trial's arrays and identity
    std::size_t samples() const { return data_.x.size(); }
    // The sample's pose, returns (world frame), BVC rates and place-cell rates.
    std::string step_blob(std::size_t sample) const;
    const World* world() const { return world_.get(); }
    const std::string& world_source() const { return world_source_; }
    const std::string& world_problem() const { return world_problem_; }

private:
    static std::shared_ptr<const TrialScene> load_unchecked(const std::filesystem::path& file,
                                                            const GivenRecording& given);
    Pose pose(std::size_t sample) const;
    void resolve_model_and_world(const std::filesystem::path& file);
    void resolve_recording(const std::filesystem::path& file, const GivenRecording& given);
    void encode(const std::filesystem::path& file);

    // A replay: its recording (null when it cannot be opened: world_problem_ says why), the
    // preprocessing it used, the scan each sample read, and the recorded BVC rates (samples × n_bvc).
    std::string replayed_;
    std::shared_ptr<const recording::Recording> recording_;
    std::unique_ptr<RecordingScene> recording_scene_;
    RecordedReturnParams recorded_params_;
    std::vector<std::size_t> scan_of_sample_;
    std::vector<float> bvc_rates_;
    std::size_t n_bvc_ = 0;

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
    RecordingScene(std::shared_ptr<const recording::Recording> recording, ModelSpec model,
                   RecordedReturnParams params = {});
    std::size_t size() const { return recording_->size(); }
    const std::string& blob() const { return blob_; }  // poses and scan names
    // The points of a map: every few scans, thinned, in the world frame (for the world view).
    std::string map_blob() const;
    std::string scan_blob(std::size_t index) const;

private:
    std::shared_ptr<const recording::Recording> recording_;  // scans (files or a bag) paired with poses
    ModelSpec model_;
    RecordedReturnParams params_;
    std::string blob_;
};

}  // namespace bvc3d::view
