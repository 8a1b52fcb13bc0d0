#include "bvc3d/navigation/failure_class.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace bvc3d {

const std::vector<std::string>& failure_class_names() {
    static const std::vector<std::string> names{"",     "blocked", "closing-in", "plateau", "wrong-basin",
                                                "loop", "wander"};
    return names;
}

std::string to_string(FailureClass c) { return failure_class_names().at(static_cast<std::size_t>(c)); }

std::size_t tail_start(std::span<const Vec3> path, double fraction) {
    if (path.size() < 2) return 0;
    double total = 0;
    for (std::size_t i = 1; i < path.size(); ++i) total += (path[i] - path[i - 1]).norm();
    double behind = 0;
    std::size_t i = path.size() - 1;
    while (i > 0 && behind < fraction * total) behind += (path[i] - path[i - 1]).norm(), --i;
    return i;
}

namespace {

constexpr std::size_t none = std::numeric_limits<std::size_t>::max();

std::size_t nearest_point(std::span<const Vec2> points, const Vec2& p) {
    std::size_t best = none;
    double d = std::numeric_limits<double>::infinity();
    for (std::size_t k = 0; k < points.size(); ++k)
        if ((points[k] - p).squaredNorm() < d) d = (points[k] - p).squaredNorm(), best = k;
    return best;
}

bool blocked(const FailedStart& s) {
    if (s.end == StartEnd::wedged) return true;
    const std::size_t moves = s.bumped.size();
    if (moves == 0 || s.path.size() != moves + 1) return false;
    const std::size_t last = std::min<std::size_t>(20, moves);
    std::size_t bumps = 0;
    for (std::size_t k = moves - last; k < moves; ++k) bumps += s.bumped[k] != 0;
    const Vec3 from = s.path[s.path.size() - 1 - last], to = s.path.back();
    return (to - from).norm() < 0.5 && 2 * bumps >= last;
}

bool closing_in(const FailedStart& s) {
    return (s.end == StartEnd::path_cap || s.end == StartEnd::time_cap) &&
           s.distance_at_end <= s.distance_at_last_quarter - 1.0;
}

bool plateau(const FailedStart& s, double top) {
    if (s.map_points.empty() || !(top > 0)) return false;
    const std::size_t from = tail_start(s.path, 0.5);
    std::size_t low = 0, count = 0;
    for (std::size_t i = from; i < s.path.size(); ++i) {
        const std::size_t k = nearest_point(s.map_points, s.path[i].head<2>());
        ++count, low += s.map_values[k] < 0.01 * top;
    }
    return count > 0 && low >= 0.8 * double(count);
}

bool wrong_basin(const FailedStart& s) {
    if (s.map_points.empty()) return false;
    std::size_t at = nearest_point(s.map_points, s.path.back().head<2>());
    const double reach = 1.5 * s.map_cell;
    for (std::size_t guard = 0; guard < s.map_points.size(); ++guard) {
        std::size_t best = at;
        for (std::size_t k = 0; k < s.map_points.size(); ++k)
            if ((s.map_points[k] - s.map_points[at]).norm() <= reach && s.map_values[k] > s.map_values[best]) best = k;
        if (best == at) break;
        at = best;
    }
    return (s.map_points[at] - s.goal).norm() > 2.0;
}

bool loop(const FailedStart& s) {
    const std::size_t from = tail_start(s.path, 0.25);
    std::vector<double> along(s.path.size(), 0.0);
    for (std::size_t i = from + 1; i < s.path.size(); ++i) along[i] = along[i - 1] + (s.path[i] - s.path[i - 1]).norm();
    for (std::size_t j = from; j < s.path.size(); ++j)
        for (std::size_t i = from; i < j && along[j] - along[i] >= 3.0; ++i)
            if ((s.path[j] - s.path[i]).norm() < 0.5) return true;
    return false;
}

}  // namespace

FailureClass classify_failure(const FailedStart& s) {
    if (s.end == StartEnd::reached) return FailureClass::none;
    if (blocked(s)) return FailureClass::blocked;
    if (closing_in(s)) return FailureClass::closing_in;
    double top = 0;
    for (double v : s.map_values) top = std::max(top, v);
    if (plateau(s, top)) return FailureClass::plateau;
    if (wrong_basin(s)) return FailureClass::wrong_basin;
    if (loop(s)) return FailureClass::loop;
    return FailureClass::wander;
}

}  // namespace bvc3d
