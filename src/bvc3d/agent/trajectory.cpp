#include "bvc3d/agent/trajectory.hpp"

#include <cmath>
#include <cstring>
#include <fstream>
#include <sstream>

#include "bvc3d/core/angles.hpp"
#include "bvc3d/core/atomic_file.hpp"
#include "bvc3d/core/error.hpp"
#include "bvc3d/core/format.hpp"
#include "bvc3d/core/random.hpp"

namespace bvc3d {

Trajectory::Trajectory(std::shared_ptr<const std::vector<ModelStep>> steps) : steps_(std::move(steps)) {}

std::optional<ModelStep> Trajectory::next(double t_end) {
    if (finished() || time() >= t_end) return std::nullopt;
    return (*steps_)[next_++];
}

std::string Trajectory::save_state() const { return "trajectory " + std::to_string(next_); }

void Trajectory::restore_state(const std::string& state) {
    std::istringstream is(state);
    std::string kind;
    std::size_t next = 0;
    is >> kind >> next;
    if (!is || kind != "trajectory" || next > steps_->size()) throw InputError("saved state is not this trajectory's");
    next_ = next;
}

std::vector<ModelStep> trajectory_steps(const std::vector<double>& t, const std::vector<double>& x,
                                        const std::vector<double>& y, const std::vector<double>& z,
                                        const std::vector<double>& heading, const std::string& source,
                                        const std::vector<double>& pitch, const std::vector<double>& roll) {
    const std::size_t n = t.size();
    if (x.size() != n || y.size() != n || heading.size() != n || (!z.empty() && z.size() != n) ||
        (!pitch.empty() && pitch.size() != n) || (!roll.empty() && roll.size() != n))
        throw InputError(source + ": t, x, y, z, heading, pitch and roll must have the same length");
    if (n == 0) throw InputError(source + ": the trajectory has no rows");
    std::vector<ModelStep> steps(n);
    for (std::size_t i = 0; i < n; ++i) {
        const double zi = z.empty() ? 0.0 : z[i];
        const double pi_ = pitch.empty() ? 0.0 : pitch[i], ri = roll.empty() ? 0.0 : roll[i];
        const auto where = [&] { return source + ": row " + std::to_string(i) + ": "; };
        for (double v : {t[i], x[i], y[i], zi, heading[i], pi_, ri})
            if (!std::isfinite(v)) throw InputError(where() + "every value must be finite");
        if (std::abs(pi_) > pi / 2) throw InputError(where() + "pitch must lie within ±90°");
        if (std::abs(x[i]) > 1e6 || std::abs(y[i]) > 1e6 || std::abs(zi) > 1e6)
            throw InputError(where() + "coordinates must lie within ±1e6 m");
        if (i > 0 && !(t[i] > t[i - 1]))
            throw InputError(where() + "times must increase (" + format_number(t[i]) + " after " +
                             format_number(t[i - 1]) + ")");
        steps[i] =
            ModelStep{t[i] - t[0], Pose{x[i], y[i], zi, wrap_pi(heading[i]), pi_, wrap_pi(ri)}, false, std::nullopt};
    }
    return steps;
}

namespace {

std::vector<std::string> split_fields(const std::string& line) {
    std::vector<std::string> out;
    std::string cur;
    for (char c : line) {
        if (c == ',' || c == ' ' || c == '\t' || c == '\r') {
            if (!cur.empty()) out.push_back(cur);
            cur.clear();
        } else {
            cur += c;
        }
    }
    if (!cur.empty()) out.push_back(cur);
    return out;
}

bool is_number(const std::string& s) {
    char* end = nullptr;
    std::strtod(s.c_str(), &end);
    return end != s.c_str() && *end == '\0';
}

}  // namespace

std::vector<ModelStep> read_trajectory_file(const std::filesystem::path& path) {
    const std::string name = "trajectory file '" + path.string() + "'";
    std::error_code ec;
    if (std::filesystem::is_directory(path, ec)) throw InputError(name + " is a folder, not a file");
    if (std::filesystem::exists(path, ec) && !std::filesystem::is_regular_file(path, ec))
        throw InputError(name + " is not a regular file");
    std::ifstream in(path);
    if (!in) throw InputError(name + (std::filesystem::exists(path, ec) ? " cannot be read" : " does not exist"));
    std::vector<std::string> columns;  // from the header, if any
    std::vector<double> t, x, y, z, heading, pitch, roll;
    bool degrees = false;
    std::string line;
    for (int line_no = 1; std::getline(in, line); ++line_no) {
        if (const auto hash = line.find('#'); hash != std::string::npos) line.resize(hash);
        const auto fields = split_fields(line);
        if (fields.empty()) continue;
        const std::string at = name + ", line " + std::to_string(line_no) + ": ";
        if (columns.empty() && t.empty() && !is_number(fields[0])) {  // a header
            columns = fields;
            for (const auto& c : {"t", "x", "y"})
                if (std::find(columns.begin(), columns.end(), c) == columns.end())
                    throw InputError(at + "the header lacks the column '" + c + "'");
            const auto has = [&](const char* c) {
                return std::find(columns.begin(), columns.end(), c) != columns.end();
            };
            degrees = has("heading_deg");
            if (has("heading") == degrees)
                throw InputError(at + "the header needs exactly one of 'heading' and 'heading_deg'");
            for (const auto& c : columns)
                if (c != "t" && c != "x" && c != "y" && c != "z" && c != "heading" && c != "heading_deg" &&
                    c != "pitch" && c != "roll" && c != "pitch_deg" && c != "roll_deg")
                    throw InputError(
                        at + "unknown column '" + c +
                        "' (known: t, x, y, z, heading or heading_deg, pitch or pitch_deg, roll or roll_deg)");
            if ((has("pitch") && has("pitch_deg")) || (has("roll") && has("roll_deg")))
                throw InputError(at + "give each angle in radians or in degrees, not both");
            continue;
        }
        if (columns.empty()) {
            if (fields.size() != 4 && fields.size() != 5)
                throw InputError(at + "expected 4 values (t x y heading) or 5 (t x y z heading), got " +
                                 std::to_string(fields.size()));
            columns = fields.size() == 4 ? std::vector<std::string>{"t", "x", "y", "heading"}
                                         : std::vector<std::string>{"t", "x", "y", "z", "heading"};
        }
        if (fields.size() != columns.size())
            throw InputError(at + "expected " + std::to_string(columns.size()) + " values, got " +
                             std::to_string(fields.size()));
        for (std::size_t c = 0; c < fields.size(); ++c) {
            if (!is_number(fields[c])) throw InputError(at + "'" + fields[c] + "' is not a number");
            const double v = std::strtod(fields[c].c_str(), nullptr);
            const auto& col = columns[c];
            if (col == "t") t.push_back(v);
            else if (col == "x") x.push_back(v);
            else if (col == "y") y.push_back(v);
            else if (col == "z") z.push_back(v);
            else if (col == "heading") heading.push_back(v);
            else if (col == "heading_deg") heading.push_back(deg_to_rad(v));
            else if (col == "pitch") pitch.push_back(v);
            else if (col == "pitch_deg") pitch.push_back(deg_to_rad(v));
            else if (col == "roll") roll.push_back(v);
            else if (col == "roll_deg") roll.push_back(deg_to_rad(v));
        }
    }
    return trajectory_steps(t, x, y, z, heading, name, pitch, roll);
}

void write_trajectory_file(const std::filesystem::path& path, const std::vector<ModelStep>& steps) {
    bool tilted = false;
    for (const auto& s : steps) tilted = tilted || !s.pose.level();
    AtomicFile file(path);
    auto& out = file.stream();
    out << (tilted ? "t,x,y,z,heading,pitch,roll\n" : "t,x,y,z,heading\n");
    for (const auto& s : steps) {
        out << format_number(s.t) << ',' << format_number(s.pose.x) << ',' << format_number(s.pose.y) << ','
            << format_number(s.pose.z) << ',' << format_number(s.pose.heading);
        if (tilted) out << ',' << format_number(s.pose.pitch) << ',' << format_number(s.pose.roll);
        out << '\n';
    }
    file.commit();
}

namespace {

std::uint64_t hash_steps(const std::vector<ModelStep>& steps) {
    std::uint64_t h = 0x7472616a;  // "traj"
    auto mix = [&](double v) {
        std::uint64_t bits;
        std::memcpy(&bits, &v, sizeof bits);
        h = hash_u64(h, bits, 0x51);
    };
    for (const auto& s : steps) {
        for (double v : {s.t, s.pose.x, s.pose.y, s.pose.z, s.pose.heading}) mix(v);
        if (!s.pose.level()) {  // level paths keep the keys they always had
            mix(s.pose.pitch);
            mix(s.pose.roll);
        }
    }
    return h;
}

}  // namespace

TrajectorySpec::TrajectorySpec(std::vector<ModelStep> steps, std::string source, int dims)
    : steps_(std::make_shared<const std::vector<ModelStep>>(std::move(steps))),
      source_(std::move(source)),
      hash_(hash_steps(*steps_)),
      dims_(dims) {
    if (dims != 2 && dims != 3)
        throw InputError("a trajectory's positions are analyzed in 2 or 3 dimensions, not " + std::to_string(dims));
}

TrajectorySpec TrajectorySpec::from_file(const std::filesystem::path& path) {
    TrajectorySpec spec(read_trajectory_file(path), path.string());
    spec.file_ = std::filesystem::absolute(path);
    return spec;
}

void TrajectorySpec::write_yaml(params::CommentedYaml& out) const {
    if (file_.empty())
        throw InputError("trajectory '" + source_ +
                         "' was given as arrays: write it to a file to describe the trial in YAML");
    out.line("", "trajectory", params::CommentedYaml::scalar(file_.string()),
             "a given path instead of the random walk: a file of t, x, y, [z], heading rows");
}

std::unique_ptr<Agent> TrajectorySpec::make(const World* world, std::uint64_t) const {
    if (world) check_world(world->description());
    return std::make_unique<Trajectory>(steps_);
}

void TrajectorySpec::check_world(const WorldDescription& world) const {
    const Eigen::AlignedBox3d box = world.bounds();  // triangles and point clouds
    for (std::size_t i = 0; i < steps_->size(); ++i) {
        const Pose& p = (*steps_)[i].pose;
        if (!box.contains(p.position()))
            throw InputError("trajectory '" + source_ + "', row " + std::to_string(i) + ": (" + format_number(p.x) +
                             ", " + format_number(p.y) + ", " + format_number(p.z) + ") lies outside world '" +
                             world.name + "' (another coordinate frame?)");
    }
}

std::string TrajectorySpec::key() const {
    std::ostringstream os;
    os << "trajectory:\n  source: " << std::filesystem::path(source_).filename().string()
       << "\n  rows: " << steps_->size() << "\n  hash: " << std::hex << hash_ << "\n";
    if (dims_ == 3) os << "  dims: 3\n";  // 2-D keys stay as they were
    return os.str();
}

double TrajectorySpec::steps_per_second() const {
    const double span = steps_->back().t;
    return span > 0 ? static_cast<double>(steps_->size()) / span : static_cast<double>(steps_->size());
}

}  // namespace bvc3d
