#include "bvc3d/agent/trajectory.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>

#include "bvc3d/core/angles.hpp"
#include "bvc3d/core/atomic_file.hpp"
#include "bvc3d/core/csv.hpp"
#include "bvc3d/core/error.hpp"
#include "bvc3d/core/format.hpp"
#include "bvc3d/core/random.hpp"

namespace bvc3d {

const params::Table<TrajectoryParams>& TrajectoryParams::table() {
    using namespace params;
    static const Table<TrajectoryParams> t(
        "trajectory", {flag("step_per_row", &TrajectoryParams::step_per_row,
                            "one model step per row, whatever their interval (default: rows resampled to model_dt)"),
                       real("model_dt", &TrajectoryParams::model_dt, closed(1e-3, 3600),
                            "s between model steps when the rows are resampled (the robot's model step)")});
    return t;
}

double median_row_interval(const std::vector<ModelStep>& rows) {
    if (rows.size() < 2) return 0.0;
    std::vector<double> dt(rows.size() - 1);
    for (std::size_t i = 1; i < rows.size(); ++i) dt[i - 1] = rows[i].t - rows[i - 1].t;
    const auto mid = dt.begin() + static_cast<std::ptrdiff_t>(dt.size() / 2);
    std::nth_element(dt.begin(), mid, dt.end());
    return *mid;
}

bool rows_at_model_step(const std::vector<ModelStep>& rows, double model_dt) {
    return rows.size() < 2 || std::abs(median_row_interval(rows) / model_dt - 1) <= 1e-6;
}

std::vector<ModelStep> resample_steps(const std::vector<ModelStep>& rows, double dt, const std::string& source) {
    if (rows.empty()) throw InputError(source + ": the trajectory has no rows");
    const double span = rows.back().t - rows.front().t;
    // As many steps as the longest random walk takes at the robot's step, and no more.
    const double limit = max_agent_hours * 3600 / TrajectoryParams{}.model_dt;
    const double count = std::floor(span / dt + 1e-9) + 1;
    if (count > limit)
        throw InputError(source + ": resampled to model steps of " + format_number(dt) + " s, its " +
                         format_number(span / 3600) + " h would be " + format_number(count) +
                         " steps, more than the limit of " + format_number(limit) +
                         " (the longest walk); step once per row (step_per_row) or cut the rows");
    std::vector<ModelStep> steps(static_cast<std::size_t>(count));
    std::size_t i = 0;  // the row at or before the step
    for (std::size_t k = 0; k < steps.size(); ++k) {
        const double t = rows.front().t + static_cast<double>(k) * dt;
        while (i + 1 < rows.size() && rows[i + 1].t <= t) ++i;
        steps[k].t = t - rows.front().t;
        if (i + 1 == rows.size()) {  // at the last row (within the rounding of k·dt)
            steps[k].pose = rows.back().pose;
            continue;
        }
        const Pose &a = rows[i].pose, &b = rows[i + 1].pose;
        const double f = (t - rows[i].t) / (rows[i + 1].t - rows[i].t);
        const auto line = [f](double u, double v) { return u + f * (v - u); };
        const auto arc = [f](double u, double v) { return wrap_pi(u + f * wrap_pi(v - u)); };
        steps[k].pose = Pose{line(a.x, b.x),         line(a.y, b.y),     line(a.z, b.z), arc(a.heading, b.heading),
                             line(a.pitch, b.pitch), arc(a.roll, b.roll)};
    }
    return steps;
}

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

// A field quoted for a message: control bytes (a NUL would end the message) as \xNN.
std::string quoted_field(const std::string& field) {
    static const char* const hex = "0123456789abcdef";
    std::string out = "'";
    for (const unsigned char c : field) {
        if (c < 0x20 || c == 0x7f) out += std::string("\\x") + hex[c >> 4] + hex[c & 15];
        else out += static_cast<char>(c);
    }
    return out + "'";
}

bool is_number(const std::string& s) {
    char* end = nullptr;
    std::strtod(s.c_str(), &end);
    return end != s.c_str() && end == s.c_str() + s.size();  // all of it: "1\0junk" is no number
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
            for (std::size_t i = 0; i < columns.size(); ++i) {
                const auto& c = columns[i];
                if (c != "t" && c != "x" && c != "y" && c != "z" && c != "heading" && c != "heading_deg" &&
                    c != "pitch" && c != "roll" && c != "pitch_deg" && c != "roll_deg" && c != "bumped")
                    throw InputError(at + "unknown column '" + c +
                                     "' (known: t, x, y, z, heading or heading_deg, pitch or pitch_deg, roll or "
                                     "roll_deg; bumped, as bvc3d walk writes it, is read and left out)");
                if (std::find(columns.begin(), columns.begin() + static_cast<std::ptrdiff_t>(i), c) !=
                    columns.begin() + static_cast<std::ptrdiff_t>(i))
                    throw InputError(at + "the header names the column '" + c + "' twice");
            }
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
            if (!is_number(fields[c])) throw InputError(at + quoted_field(fields[c]) + " is not a number");
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
    CsvWriter csv(file.stream());
    csv.field("t").field("x").field("y").field("z").field("heading");
    if (tilted) csv.field("pitch").field("roll");
    csv.end_row();
    for (const auto& s : steps) {
        csv.field(s.t).field(s.pose.x).field(s.pose.y).field(s.pose.z).field(s.pose.heading);
        if (tilted) csv.field(s.pose.pitch).field(s.pose.roll);
        csv.end_row();
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
    : rows_(std::make_shared<const std::vector<ModelStep>>(std::move(steps))),
      steps_(rows_),
      source_(std::move(source)),
      hash_(hash_steps(*steps_)),
      dims_(dims) {
    if (dims != 2 && dims != 3)
        throw InputError("a trajectory's positions are analyzed in 2 or 3 dimensions, not " + std::to_string(dims));
}

TrajectorySpec::TrajectorySpec(std::vector<ModelStep> rows, std::string source, const TrajectoryParams& params)
    : rows_(std::make_shared<const std::vector<ModelStep>>(std::move(rows))),
      source_(std::move(source)),
      params_(params),
      user_(true) {
    try {
        params_.validate();
    } catch (const params::ParamError& e) {
        throw InputError("trajectory '" + source_ + "': " + e.what());
    }
    steps_ = params_.step_per_row || rows_at_model_step(*rows_, params_.model_dt)
                 ? rows_
                 : std::make_shared<const std::vector<ModelStep>>(
                       resample_steps(*rows_, params_.model_dt, "trajectory '" + source_ + "'"));
    hash_ = hash_steps(*steps_);
}

TrajectorySpec TrajectorySpec::from_file(const std::filesystem::path& path, const TrajectoryParams& params) {
    TrajectorySpec spec(read_trajectory_file(path), path.string(), params);
    spec.file_ = std::filesystem::absolute(path);
    return spec;
}

namespace {

std::string three_digits(double v) {
    char text[32];
    std::snprintf(text, sizeof text, "%.3g", v);
    return text;
}

}  // namespace

std::string TrajectorySpec::note() const {
    if (!user_ || rows_at_model_step(*rows_, params_.model_dt)) return {};
    const std::string rows = "trajectory '" + source_ + "': " + std::to_string(rows_->size()) + " rows every " +
                             three_digits(median_row_interval(*rows_)) + " s (median), ";
    if (resampled())
        return rows + "resampled to " + std::to_string(steps_->size()) + " model steps of " +
               format_number(params_.model_dt) +
               " s (positions linearly, headings along the shorter arc); step_per_row steps once per row";
    return rows + "one model step per row (step_per_row): the place cells' time constant and Oja's rate are per " +
           "step, so their dynamics run " + three_digits(params_.model_dt / median_row_interval(*rows_)) +
           " times as fast per second as at the model step of " + format_number(params_.model_dt) + " s";
}

void TrajectorySpec::write_yaml(params::CommentedYaml& out) const {
    if (file_.empty())
        throw InputError("trajectory '" + source_ +
                         "' was given as arrays: write it to a file to describe the trial in YAML");
    const char* doc = "a given path instead of the random walk: a file of t, x, y, [z], heading rows";
    if (params_ == TrajectoryParams{}) {
        out.line("", "trajectory", params::CommentedYaml::scalar(file_.string()), doc);
        return;
    }
    out.section("", "trajectory", doc);
    out.line("  ", "file", params::CommentedYaml::scalar(file_.string()), "t, x, y, [z], heading rows");
    out.fields(TrajectoryParams::table(), params_, "  ");
}

std::unique_ptr<Agent> TrajectorySpec::make(const World* world, std::uint64_t) const {
    if (world) check_world(world->description());
    return std::make_unique<Trajectory>(steps_);
}

void TrajectorySpec::check_world(const WorldDescription& world) const {
    const Eigen::AlignedBox3d box = world.bounds();    // triangles and point clouds
    for (std::size_t i = 0; i < rows_->size(); ++i) {  // resampled steps lie between rows, inside the box too
        const Pose& p = (*rows_)[i].pose;
        if (!box.contains(p.position()))
            throw InputError("trajectory '" + source_ + "', row " + std::to_string(i) + ": (" + format_number(p.x) +
                             ", " + format_number(p.y) + ", " + format_number(p.z) + ") lies outside world '" +
                             world.name + "' (another coordinate frame?)");
    }
}

std::string TrajectorySpec::key() const {
    std::ostringstream os;
    os << "trajectory:\n  source: " << std::filesystem::path(source_).filename().string()
       << "\n  rows: " << rows_->size() << "\n  hash: " << std::hex << hash_ << "\n";
    if (dims_ == 3) os << "  dims: 3\n";  // 2-D keys stay as they were
    if (resampled())                      // paths stepped once per row keep the keys they always had
        os << "  resampled_to: " << format_number(params_.model_dt) << "\n  steps: " << std::dec << steps_->size()
           << "\n";
    return os.str();
}

double TrajectorySpec::steps_per_second() const {
    const double span = steps_->back().t;
    return span > 0 ? static_cast<double>(steps_->size()) / span : static_cast<double>(steps_->size());
}

}  // namespace bvc3d
