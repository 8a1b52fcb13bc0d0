#include "cli_common.hpp"

#include <unistd.h>

#include <charconv>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <vector>

#include "bvc3d/agent/random_walk.hpp"
#include "bvc3d/config/sweep_yaml.hpp"
#include "bvc3d/core/angles.hpp"
#include "bvc3d/core/atomic_file.hpp"
#include "bvc3d/core/error.hpp"
#include "bvc3d/core/format.hpp"

namespace bvc3d::cli {

std::vector<std::string> split_commas(const std::string& text, EmptyItems empty) {
    std::vector<std::string> items;
    std::size_t start = 0;
    for (std::size_t i = 0; i <= text.size(); ++i)
        if (i == text.size() || text[i] == ',') {
            if (empty == EmptyItems::keep || i > start) items.push_back(text.substr(start, i - start));
            start = i + 1;
        }
    return items;
}

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

const CLI::Validator output_path(
    [](std::string& s) -> std::string {
        s = without_trailing_slash(s).string();
        return "";
    },
    "", "output path");

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
    const auto parts = split_commas(text, EmptyItems::keep);
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

void check_seed_count(int seeds, const std::vector<std::pair<std::size_t, std::string>>& factors) {
    if (seeds < 1) throw InputError("--seeds must be >= 1, got " + std::to_string(seeds));
    double n_trials = seeds;
    std::string product = "--seeds " + std::to_string(seeds);
    for (const auto& [count, what] : factors) {
        n_trials *= static_cast<double>(count);
        product += " × " + std::to_string(count) + " " + what;
    }
    if (n_trials > config::max_trials)
        throw InputError(product + " = " + num(n_trials) + " trials; the limit is " +
                         std::to_string(static_cast<long long>(config::max_trials)));
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
    const auto parts = split_commas(text, EmptyItems::keep);
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

namespace {

// Ctrl-C (SIGINT) or SIGTERM (mpirun passing on a Ctrl-C, a batch system's time limit) asks running
// trials to checkpoint and stop; a second signal ends the program at once.
extern "C" void on_stop_signal(int sig) {
    stop_flag().store(true);
    std::signal(sig, SIG_DFL);
}

}  // namespace

std::atomic<bool>& stop_flag() {
    static std::atomic<bool> stop{false};  // set from the SIGINT handler
    return stop;
}

InterruptGuard::InterruptGuard() {
    std::signal(SIGINT, on_stop_signal);
    std::signal(SIGTERM, on_stop_signal);
}
InterruptGuard::~InterruptGuard() {
    std::signal(SIGINT, SIG_DFL);
    std::signal(SIGTERM, SIG_DFL);
}

void exit_interrupted() {
    std::cerr << "\nbvc3d: interrupted; finished trials are kept. Run the same command again to resume.\n";
    std::exit(130);
}

ProgressStyle progress_style() { return ::isatty(STDERR_FILENO) ? ProgressStyle::terminal : ProgressStyle::lines; }

}  // namespace bvc3d::cli
