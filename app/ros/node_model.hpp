#pragma once
// The model behind the bvc3d_ros node (docs/ros.md#the-node), apart from ROS: what one scan does.
// Takes: a scan's points in the sensor frame and its world-from-sensor pose. Gives: the BVC rates
// and place-cell rates (exactly as `bvc3d replay` computes them for the same scan: the same
// preprocessing, BVC layer and place-cell step), the template nearest in population-vector
// cosine (when templates are given) and the recognised revisit of SPEC §15 (the best match among
// the scans older than the exclusion window, when its distance 1 − cosine is within the threshold).
//
// This header is read by the node's ROS side, which is compiled as C++17 (the ROS 1 message
// headers need it): it uses nothing newer.
#include <Eigen/Geometry>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace bvc3d::ros_node {

struct NodeParams {
    std::string model = "3d-3l";  // a preset or a model YAML
    bool learn = false;           // place cells learn (Oja's rule, the online protocol)
    std::string weights;          // a trial file's trained weights (same model); else the seed's draw
    std::uint64_t seed = 0;
    double min_range = 0.3, max_range = 20.0, slice_half_width_deg = 1.0;  // the preprocessing
    // Templates for decoding: a bag (with its topics) or a scan folder/list with a pose file.
    std::string templates_bag, templates_cloud_topic, templates_pose_topic, templates_tf_frames;
    std::string templates_scans, templates_poses;
    bool decode_place = false;  // decode on place-cell rates (else BVC rates)
    // Revisits (SPEC §15): the descriptor, the exclusion window and the distance threshold.
    bool revisit_place = false;  // place-cell rates as the descriptor (else BVC rates)
    int revisit_window_scans = 50;
    double revisit_window_s = 30.0;
    double revisit_threshold = 0.1;  // publish when 1 − cosine <= this
};

struct Decoded {
    std::size_t template_index = 0;  // the template's scan index in its recording
    double similarity = 0;
    Eigen::Isometry3d world_from_sensor = Eigen::Isometry3d::Identity();
};

struct Revisit {
    std::int64_t scan = 0;  // the matched earlier scan's index (0 = the node's first scan)
    double distance = 0;    // 1 − cosine of the two descriptors
};

struct ScanResult {
    std::vector<float> bvc, place;
    std::optional<Decoded> decoded;  // none without templates, or when no similarity is positive
    std::optional<Revisit> revisit;
    std::size_t returns = 0;  // returns the model read
};

class NodeModel {
public:
    // Errors (InputError) name the parameter or file at fault.
    explicit NodeModel(const NodeParams& params);
    ~NodeModel();
    // xyz: N × 3 row-major, the sensor frame; `stamp` in seconds (for the revisit window).
    ScanResult step(const std::vector<double>& xyz, const Eigen::Isometry3d& world_from_sensor, double stamp);
    std::size_t n_bvc() const;
    std::size_t n_place() const;
    std::size_t templates() const;
    std::string model_name() const;

private:
    struct State;
    std::unique_ptr<State> s_;
};

}  // namespace bvc3d::ros_node
