#include "cli_common.hpp"

#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <charconv>
#include <cstdlib>
#include <cmath>
#include <cstdio>
#include <vector>

#include "bvc3d/core/angles.hpp"
#include "bvc3d/agent/random_walk.hpp"
#include "bvc3d/core/error.hpp"
#include "bvc3d/core/format.hpp"

namespace bvc3d::cli {

double parse_number(const std::string& s, const std::string& what) {
    double v = 0;
    const auto* end = s.data() + s.size();
    const auto r = std::from_chars(s.data(), end, v);
    if (s.empty() || r.ec != std::errc() || r.ptr != end || !std::isfinite(v))
        throw InputError(what + " '" + s + "' is not a finite number");
    return v;
}

const CLI::Validator seed_check(
    [](std::string& s) -> std::string {
        return !s.empty() && s.find_first_not_of("0123456789") == std::string::npos ? "" : "a seed is a whole number >= 0";
    },
    "SEED>=0");

const CLI::Validator non_negative_check(
    [](std::string& s) -> std::string {
        double v = 0;
        const auto r = std::from_chars(s.data(), s.data() + s.size(), v);
        return r.ec == std::errc() && r.ptr == s.data() + s.size() && std::isfinite(v) && v >= 0 ? ""
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
    if (parts.size() != 3) throw InputError("--pose expects X,Y,HEADING (three comma-separated numbers), got '" + text + "'");
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

int run_python_module(const std::string& module, const std::vector<std::string>& args) {
    const char* py_env = std::getenv("BVC3D_PYTHON");
    const std::string python = py_env && *py_env ? py_env : BVC3D_PYTHON;
    const char* path_env = std::getenv("BVC3D_PYTHONPATH");
    std::string pythonpath = path_env && *path_env ? path_env : BVC3D_PYTHON_DIR;
    if (const char* existing = std::getenv("PYTHONPATH"); existing && *existing && pythonpath != existing)
        pythonpath += std::string(":") + existing;  // as the report's command (cmd_experiment.cpp) does
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
    while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
    }
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

}  // namespace bvc3d::cli
