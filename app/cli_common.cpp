#include "cli_common.hpp"

#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "bvc3d/agent/random_walk.hpp"
#include "bvc3d/core/angles.hpp"
#include "bvc3d/core/error.hpp"
#include "bvc3d/core/format.hpp"
#include "bvc3d/core/memory.hpp"

namespace bvc3d::cli {

double parse_number(const std::string& s, const std::string& what) {
    double v = 0;
    const auto* end = s.data() + s.size();
    const auto r = std::from_chars(s.data(), end, v);
    if (s.empty() || r.ec != std::errc() || r.ptr != end || !std::isfinite(v))
        throw InputError(what + " '" + s + "' is not a finite number");
    return v;
}

std::string printable(std::string_view text) {
    std::string out;
    out.reserve(text.size());
    for (std::size_t i = 0; i < text.size();) {
        const auto c = static_cast<unsigned char>(text[i]);
        if (c < 0x80) {
            out += (c < 0x20 && c != '\n' && c != '\t') || c == 0x7f ? '?' : static_cast<char>(c);
            ++i;
            continue;
        }
        // A well-formed UTF-8 sequence passes whole; anything else is one '?' per byte.
        const int len = c >= 0xf0 && c < 0xf5 ? 4 : c >= 0xe0 ? 3 : c >= 0xc2 && c < 0xe0 ? 2 : 0;
        bool ok = len > 0 && i + len <= text.size();
        for (int k = 1; ok && k < len; ++k) ok = (static_cast<unsigned char>(text[i + k]) & 0xc0) == 0x80;
        if (ok) {
            out.append(text.substr(i, len));
            i += len;
        } else {
            out += '?';
            ++i;
        }
    }
    return out;
}

const CLI::Validator seed_check(
    [](std::string& s) -> std::string {
        std::uint64_t v = 0;
        const auto r = std::from_chars(s.data(), s.data() + s.size(), v);
        return !s.empty() && r.ec == std::errc() && r.ptr == s.data() + s.size()
                   ? ""
                   : "a seed is a whole number from 0 to 18446744073709551615 (2^64 - 1), got '" + s + "'";
    },
    "SEED");

const CLI::Validator non_negative_check(
    [](std::string& s) -> std::string {
        double v = 0;
        const auto r = std::from_chars(s.data(), s.data() + s.size(), v);
        return r.ec == std::errc() && r.ptr == s.data() + s.size() && std::isfinite(v) && v >= 0
                   ? ""
                   : "must be a number >= 0";
    },
    "NUMBER>=0");

void warn_if_blocked(const World& world, const Pose& pose) {
    const BodyCollider body(world.description(), RobotParams{}.radius, RobotParams{}.height);
    const Vec2 p(pose.x, pose.y);
    if (!world.description().walkable.contains(p))
        std::fprintf(stderr, "bvc3d: warning: (%g, %g) lies outside the world's walkable region\n", pose.x, pose.y);
    else if (body.clearance(p) < 0)
        std::fprintf(stderr, "bvc3d: warning: at (%g, %g) the robot's body would overlap geometry by %.3f m\n", pose.x,
                     pose.y, -body.clearance(p));
}

Pose parse_pose(const std::string& text) {
    std::vector<std::string> parts;
    std::size_t start = 0;
    for (std::size_t i = 0; i <= text.size(); ++i)
        if (i == text.size() || text[i] == ',') {
            parts.push_back(text.substr(start, i - start));
            start = i + 1;
        }
    if (parts.size() != 3)
        throw InputError("--pose expects X,Y,HEADING (three comma-separated numbers), got '" + text + "'");
    Pose p;  // on the floor, level
    p.x = parse_number(parts[0], "--pose: X");
    p.y = parse_number(parts[1], "--pose: Y");
    std::string h = parts[2];
    const bool degrees = h.size() > 3 && h.compare(h.size() - 3, 3, "deg") == 0;
    if (degrees) h.resize(h.size() - 3);
    p.heading = parse_number(h, "--pose: HEADING");
    if (degrees) p.heading = deg_to_rad(p.heading);
    return p;
}

std::string num(double v) { return format_number(v); }

namespace {

// Text as one shell word: as it is when safe, else single-quoted.
std::string shell_word(const std::string& s) {
    const bool safe = !s.empty() && s.find_first_not_of(
                                        "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789"
                                        "_-./:=+,@%") == std::string::npos;
    if (safe) return s;
    std::string q = "'";
    for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return q + "'";
}

}  // namespace

std::string PythonCommand::shell_line(const std::string& module, const std::vector<std::string>& args) const {
    std::string line = "PYTHONPATH=" + shell_word(pythonpath) + " " + shell_word(python) + " -m " + module;
    for (const auto& a : args) line += " " + shell_word(a);
    return line;
}

PythonCommand python_command() {
    const char* py_env = std::getenv("BVC3D_PYTHON");
    const char* path_env = std::getenv("BVC3D_PYTHONPATH");
    PythonCommand c{py_env && *py_env ? py_env : BVC3D_PYTHON, path_env && *path_env ? path_env : BVC3D_PYTHON_DIR};
    if (const char* existing = std::getenv("PYTHONPATH"); existing && *existing && c.pythonpath != existing)
        c.pythonpath += std::string(":") + existing;
    return c;
}

int run_python_module(const std::string& module, const std::vector<std::string>& args) {
    const PythonCommand command = python_command();
    const std::string& python = command.python;
    const std::string& pythonpath = command.pythonpath;
    std::vector<std::string> argv_text{python, "-m", module};
    argv_text.insert(argv_text.end(), args.begin(), args.end());
    std::vector<char*> argv;
    for (auto& a : argv_text) argv.push_back(a.data());
    argv.push_back(nullptr);
    std::fflush(stdout);  // our lines first, then the module's
    const pid_t pid = ::fork();
    if (pid < 0) return -1;
    if (pid == 0) {
        ::setenv("PYTHONPATH", pythonpath.c_str(), 1);
        ::execv(python.c_str(), argv.data());
        std::perror(("bvc3d: cannot run " + python).c_str());
        ::_exit(127);
    }
    int status = 0;
    while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {}
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

const char* const extent_help =
    "Rate-map grid: 'data' (each trajectory's own bounds, the default), 'arena' (the walkable region's) or "
    "XMIN,XMAX,YMIN,YMAX in meters";

ExtentOption parse_extent(const std::string& text) {
    ExtentOption e;
    if (text == "data") return e;
    if (text == "arena") {
        e.kind = ExtentOption::Kind::arena;
        return e;
    }
    std::vector<std::string> parts;
    std::size_t start = 0;
    for (std::size_t i = 0; i <= text.size(); ++i)
        if (i == text.size() || text[i] == ',') {
            parts.push_back(text.substr(start, i - start));
            start = i + 1;
        }
    if (parts.size() != 4) throw InputError("--extent expects data, arena or XMIN,XMAX,YMIN,YMAX, got '" + text + "'");
    e.kind = ExtentOption::Kind::bounds;
    e.bounds = analysis::Extent{parse_number(parts[0], "--extent: XMIN"), parse_number(parts[1], "--extent: XMAX"),
                                parse_number(parts[2], "--extent: YMIN"), parse_number(parts[3], "--extent: YMAX")};
    try {
        e.bounds.validate();
    } catch (const InputError& err) {
        throw InputError(std::string("--extent: ") + err.what());
    }
    return e;
}

void apply_extent(const ExtentOption& e, TrialConfig& t) {
    t.arena_extent = e.kind == ExtentOption::Kind::arena;
    t.analysis.extent.reset();
    if (e.kind == ExtentOption::Kind::bounds) t.analysis.extent = e.bounds;
}

int check_jobs(int jobs) {
    if (jobs < 0) throw InputError("--jobs must be >= 0 (0: one per core), got " + std::to_string(jobs));
    if (jobs > max_jobs)
        throw InputError("--jobs " + std::to_string(jobs) + " is more than the limit of " + std::to_string(max_jobs));
    return jobs;
}

const char* const no_memory_check_help = "Run even when the estimated memory exceeds what the machine has available";

void check_run_memory(const std::vector<TrialConfig>& trials, int jobs, bool skip) {
    if (skip) return;
    const std::string what =
        trials.size() == 1 ? "this trial" : "this run (" + std::to_string(trials.size()) + " trials)";
    check_memory(estimate_memory(trials, jobs), what,
                 "shorten sample_hours, use fewer --jobs or smaller models, or pass --no-memory-check to try anyway");
}

}  // namespace bvc3d::cli
