#include "bvc3d/config/returns_spec.hpp"

#include <map>

#include "bvc3d/agent/trajectory.hpp"
#include "bvc3d/config/model_yaml.hpp"
#include "bvc3d/core/error.hpp"
#include "bvc3d/core/format.hpp"
#include "bvc3d/core/random.hpp"

namespace bvc3d {

namespace {

bool planar(const ModelSpec& model) { return model.bvc.elevations.empty(); }

}  // namespace

RecordedReturnsSpec::RecordedReturnsSpec(std::shared_ptr<const recording::Recording> recording,
                                         RecordedReturnParams params)
    : recording_(std::move(recording)), params_(params), fingerprint_(recording_->fingerprint()) {
    params_.validate();
}

std::string RecordedReturnsSpec::key() const {
    return "returns:\n  recording: " + recording_->name + "\n  scans: " + std::to_string(recording_->size()) +
           "\n  files: " + fingerprint_ + "\n" + params::yaml_lines(RecordedReturnParams::table(), params_, "  ");
}

std::vector<std::pair<std::string, std::string>> RecordedReturnsSpec::attributes() const {
    std::vector<std::pair<std::string, std::string>> a{{"recording", recording_->name},
                                                       {"recording_scans", recording_->scans_source.string()},
                                                       {"recording_poses", recording_->poses_source.string()}};
    if (recording_->size() > 0 && recording_->time(0))
        a.emplace_back("recording_t0", format_number(*recording_->time(0)));
    return a;
}

SourceFactory RecordedReturnsSpec::factory(std::uint64_t) const {
    auto scans = std::make_shared<RecordedScans>(recording_);
    auto made = std::make_shared<std::map<ReturnSelection, std::shared_ptr<ReturnSource>>>();
    return [scans, made, params = params_](const ModelSpec& model, const World*) {
        const ReturnSelection s = selection_for(model.sensor, planar(model));
        auto& source = (*made)[s];
        if (!source) source = std::make_shared<RecordedSource>(scans, params, s);
        return source;
    };
}

SimulatedReturnsSpec::SimulatedReturnsSpec(LidarSpec sensor, RecordedReturnParams params)
    : sensor_(std::move(sensor)), params_(params) {
    sensor_.validate();
    params_.validate();
}

std::string SimulatedReturnsSpec::key() const {
    return "returns:\n  simulated_sensor:\n" + params::yaml_lines(LidarSpec::table(), sensor_, "    ") +
           params::yaml_lines(RecordedReturnParams::table(), params_, "  ");
}

SourceFactory SimulatedReturnsSpec::factory(std::uint64_t seed) const {
    auto made = std::make_shared<std::map<ReturnSelection, std::shared_ptr<ReturnSource>>>();
    auto cast = std::make_shared<std::shared_ptr<ReturnSource>>();
    const std::uint64_t noise_seed = hash_u64(seed, static_cast<std::uint64_t>(Stream::sensor_noise), 0);
    return [made, cast, noise_seed, sensor = sensor_, params = params_](const ModelSpec& model, const World* world) {
        if (!world) throw InputError("a simulated sensor needs a world to cast in");
        if (!*cast) *cast = std::make_shared<RayCastSource>(*world, sensor, noise_seed);
        // The sensor's own rows decide what an upper-half model keeps, as for a real scan.
        const ReturnSelection s = selection_for(model.sensor, planar(model));
        auto& source = (*made)[s];
        if (!source) source = std::make_shared<FilteredSource>(*cast, params, s);
        return source;
    };
}

std::vector<ModelStep> recording_steps(const recording::Recording& rec) {
    const std::size_t n = rec.size();
    std::vector<double> t(n), x(n), y(n), z(n), heading(n), pitch(n), roll(n);
    bool timed = true;
    for (std::size_t i = 0; i < n; ++i) timed = timed && rec.time(i).has_value();
    for (std::size_t i = 0; i < n; ++i) {
        const auto& m = rec.poses[i].world_from_sensor;
        const Pose p = Pose::from_rotation(m.translation(), m.linear());
        t[i] = timed ? *rec.time(i) : static_cast<double>(i);
        const auto where = [&] {
            return "recording '" + rec.name + "', scan " + std::to_string(i) + rec.pose_origin(i);
        };
        if (i > 0 && !(t[i] > t[i - 1]))
            throw InputError(where() + ": its time " + format_number(t[i]) + " s does not follow the previous scan's " +
                             format_number(t[i - 1]) + " s (scans must be in time order)");
        if (!(std::abs(p.x) <= 1e6 && std::abs(p.y) <= 1e6 && std::abs(p.z) <= 1e6))
            throw InputError(where() + ": its position (" + format_number(p.x) + ", " + format_number(p.y) + ", " +
                             format_number(p.z) + ") lies beyond ±1e6 m");
        x[i] = p.x;
        y[i] = p.y;
        z[i] = p.z;
        heading[i] = p.heading;
        pitch[i] = p.pitch;
        roll[i] = p.roll;
    }
    return trajectory_steps(t, x, y, z, heading, "recording '" + rec.name + "'", pitch, roll);
}

}  // namespace bvc3d
