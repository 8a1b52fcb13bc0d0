#include "bvc3d/agent/route.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "bvc3d/core/angles.hpp"
#include "bvc3d/core/error.hpp"
#include "bvc3d/core/format.hpp"

namespace bvc3d {

const params::Table<RouteParams>& RouteParams::table() {
    using namespace params;
    static const Table<RouteParams> t(
        "route",
        {real("speed", &RouteParams::speed, open_closed(0, 100), "m/s, cruising"),
         real("lateral_acceleration", &RouteParams::lateral_acceleration, open_closed(0, 100),
              "m/s², at most, in turns"),
         real("acceleration", &RouteParams::acceleration, open_closed(0, 100), "m/s², speeding up and slowing down"),
         real("min_turn_radius", &RouteParams::min_turn_radius, open_closed(0, 100),
              "m, tighter corners are turns in place"),
         real("turn_rate", &RouteParams::turn_rate, open_closed(0, 100), "rad/s, turning in place"),
         real("model_dt", &RouteParams::model_dt, open_closed(0, 3600), "s of motion per model step")});
    return t;
}

namespace {

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

// A node of the path, every centimeter or so: where, which way, how fast at most.
struct Node {
    Vec2 p;
    double heading = 0;
    double cap = 0;   // m/s at most here
    double turn = 0;  // rad turned in place here (a stop)
};

constexpr double node_step = 0.01;  // m between nodes

void add_line(std::vector<Node>& nodes, const Vec2& a, const Vec2& b, double speed) {
    const double len = (b - a).norm();
    if (len <= 0) return;
    const double heading = std::atan2(b.y() - a.y(), b.x() - a.x());
    // Two nodes at least: between two stops the robot speeds up, then slows down.
    const int n = std::max(2, static_cast<int>(std::ceil(len / node_step)));
    for (int i = 1; i <= n; ++i) nodes.push_back({a + (b - a) * (static_cast<double>(i) / n), heading, speed, 0});
}

// The arc of radius R around `center` from angle a0 turning by `sweep` (signed: > 0 counter-clockwise).
void add_arc(std::vector<Node>& nodes, const Vec2& center, double R, double a0, double sweep, double speed) {
    const int n = std::max(1, static_cast<int>(std::ceil(std::abs(sweep) * R / node_step)));
    for (int i = 1; i <= n; ++i) {
        const double a = a0 + sweep * i / n;
        nodes.push_back(
            {center + R * Vec2(std::cos(a), std::sin(a)), wrap_pi(a + (sweep > 0 ? pi / 2 : -pi / 2)), speed, 0});
    }
}

// Whether the body driven along the arc stays clear: chords at most `sagitta` from the arc, each
// clear by that much.
bool arc_clear(const BodyCollider& body, const Vec2& center, double R, double a0, double sweep) {
    constexpr double sagitta = 1e-4;  // m
    const double max_angle = 2 * std::acos(std::max(-1.0, 1 - sagitta / R));
    const int n = std::max(1, static_cast<int>(std::ceil(std::abs(sweep) / max_angle)));
    Vec2 prev = center + R * Vec2(std::cos(a0), std::sin(a0));
    for (int i = 1; i <= n; ++i) {
        const double a = a0 + sweep * i / n;
        const Vec2 next = center + R * Vec2(std::cos(a), std::sin(a));
        if (body.clearance(prev, next) < sagitta) return false;
        prev = next;
    }
    return true;
}

}  // namespace

std::vector<ModelStep> route_through(const std::vector<Vec2>& input, const BodyCollider& body,
                                     const RouteParams& params) {
    params.validate();
    std::vector<Vec2> w;
    std::vector<std::size_t> number;  // each kept point's waypoint number, for messages
    for (std::size_t i = 0; i < input.size(); ++i) {
        if (!input[i].allFinite() || input[i].cwiseAbs().maxCoeff() > 1e6)
            throw InputError("waypoint " + std::to_string(i) + ": coordinates must be finite and within ±1e6 m");
        if (w.empty() || (input[i] - w.back()).norm() > 1e-9) {
            w.push_back(input[i]);
            number.push_back(i);
        }
    }
    if (w.size() < 2) throw InputError("a route needs at least two different waypoints");
    const double r = body.radius();
    for (std::size_t i = 0; i < w.size(); ++i) {
        if (!body.walkable().contains(w[i]))
            throw InputError("waypoint " + std::to_string(number[i]) + " " + point_text(w[i]) +
                             " lies outside the walkable region");
        const double c = body.clearance(w[i]);
        if (c < 0)
            throw InputError("waypoint " + std::to_string(number[i]) + " " + point_text(w[i]) +
                             " lies inside geometry or closer than the body's radius (" + format_number(r) +
                             " m) to it: the nearest obstacle is " + format_number(c + r) + " m away");
    }
    for (std::size_t i = 0; i + 1 < w.size(); ++i) {
        const double len = (w[i + 1] - w[i]).norm();
        const Vec2 u = (w[i + 1] - w[i]) / len;
        const double free = body.free_distance(w[i], u, len);
        if (body.clearance(w[i], w[i + 1]) < 0 || free < len)
            throw InputError("segment " + std::to_string(number[i]) + " (waypoint " + std::to_string(number[i]) + " " +
                             point_text(w[i]) + " to waypoint " + std::to_string(number[i + 1]) + " " +
                             point_text(w[i + 1]) + ") cannot be driven: the body comes closer than its radius (" +
                             format_number(r) + " m) to geometry near " + point_text(w[i] + free * u));
    }

    // The corners: an arc where one fits, else a turn in place.
    const double r_full = params.speed * params.speed / params.lateral_acceleration;
    std::vector<Node> nodes{{w[0], std::atan2(w[1].y() - w[0].y(), w[1].x() - w[0].x()), 0.0, 0.0}};
    Vec2 from = w[0];
    for (std::size_t k = 1; k + 1 < w.size(); ++k) {
        const Vec2 in = (w[k] - w[k - 1]).normalized(), out = (w[k + 1] - w[k]).normalized();
        const double turn = std::atan2(in.x() * out.y() - in.y() * out.x(), in.dot(out));  // signed
        if (std::abs(turn) < 1e-9) continue;
        const double room = 0.5 * std::min((w[k] - w[k - 1]).norm(), (w[k + 1] - w[k]).norm());
        const double t = std::tan(std::abs(turn) / 2);
        double R = std::abs(turn) < pi - 1e-6 ? std::min(r_full, room / t) : 0.0;
        const Vec2 left_in(-in.y(), in.x());
        const double side = turn > 0 ? 1.0 : -1.0;
        bool arc = false;
        for (; R >= params.min_turn_radius; R *= 0.7) {
            const Vec2 t_in = w[k] - R * t * in;
            const Vec2 center = t_in + side * R * left_in;
            const double a0 = std::atan2(t_in.y() - center.y(), t_in.x() - center.x());
            if (!arc_clear(body, center, R, a0, turn)) continue;
            add_line(nodes, from, t_in, params.speed);
            add_arc(nodes, center, R, a0, turn, std::min(params.speed, std::sqrt(params.lateral_acceleration * R)));
            from = w[k] + R * t * out;
            arc = true;
            break;
        }
        if (!arc) {  // stop at the corner and turn in place
            add_line(nodes, from, w[k], params.speed);
            nodes.back().cap = 0;
            nodes.back().turn = turn;
            from = w[k];
        }
    }
    add_line(nodes, from, w.back(), params.speed);
    nodes.back().cap = 0;

    // Speeds: from rest to rest, within each node's cap and the acceleration.
    const std::size_t n = nodes.size();
    std::vector<double> v(n), ds(n, 0.0);
    for (std::size_t i = 1; i < n; ++i) ds[i] = (nodes[i].p - nodes[i - 1].p).norm();
    v[0] = 0;
    for (std::size_t i = 1; i < n; ++i)
        v[i] = std::min(nodes[i].cap, std::sqrt(v[i - 1] * v[i - 1] + 2 * params.acceleration * ds[i]));
    for (std::size_t i = n - 1; i-- > 0;)
        v[i] = std::min(v[i], std::sqrt(v[i + 1] * v[i + 1] + 2 * params.acceleration * ds[i + 1]));

    // Samples every model_dt of motion; turns in place add their time.
    const auto step_at = [](double t, const Vec2& p, double heading) {
        ModelStep s;
        s.t = t;
        s.pose = Pose::on_floor(p.x(), p.y(), heading);
        return s;
    };
    std::vector<ModelStep> steps{step_at(0.0, w[0], nodes[0].heading)};
    double motion = 0, turning = 0, next = params.model_dt;
    for (std::size_t i = 1; i < n; ++i) {
        const double v0 = v[i - 1], v1 = v[i], len = ds[i];
        const double dt = len > 0 ? 2 * len / (v0 + v1) : 0.0;
        const double a = dt > 0 ? (v1 - v0) / dt : 0.0;
        while (dt > 0 && next <= motion + dt) {
            const double tau = next - motion;
            const double frac = (v0 * tau + 0.5 * a * tau * tau) / len;
            const Vec2 p = nodes[i - 1].p + std::clamp(frac, 0.0, 1.0) * (nodes[i].p - nodes[i - 1].p);
            const double h = wrap_pi(nodes[i - 1].heading + frac * wrap_pi(nodes[i].heading - nodes[i - 1].heading));
            steps.push_back(step_at(next + turning, p, h));
            next += params.model_dt;
        }
        motion += dt;
        turning += std::abs(nodes[i].turn) / params.turn_rate;
    }
    const Vec2& end = nodes.back().p;
    if (motion + turning - steps.back().t > 1e-9 * std::max(1.0, motion))  // the last, shorter step
        steps.push_back(step_at(motion + turning, end, nodes.back().heading));
    return steps;
}

std::vector<Vec2> read_waypoints(const std::string& path) {
    const std::string name = "waypoint file '" + path + "'";
    std::error_code ec;
    if (std::filesystem::is_directory(path, ec)) throw InputError(name + " is a folder, not a file");
    std::ifstream in(path);
    if (!in) throw InputError(name + (std::filesystem::exists(path, ec) ? " cannot be read" : " does not exist"));
    std::vector<Vec2> points;
    std::string line;
    for (int line_no = 1; std::getline(in, line); ++line_no) {
        if (const auto hash = line.find('#'); hash != std::string::npos) line.resize(hash);
        for (char& c : line)
            if (c == ',' || c == '\t' || c == '\r') c = ' ';
        std::vector<std::string> fields;
        std::string f;
        for (std::istringstream is(line); is >> f;) fields.push_back(f);
        if (fields.empty()) continue;
        const std::string at = name + ", line " + std::to_string(line_no) + ": ";
        if (points.empty() && fields.size() == 2 && fields[0] == "x" && fields[1] == "y") continue;  // header
        if (fields.size() != 2) throw InputError(at + "expected 2 values (x y), got " + std::to_string(fields.size()));
        Vec2 p;
        for (int k = 0; k < 2; ++k) {
            char* end = nullptr;
            p[k] = std::strtod(fields[k].c_str(), &end);
            if (end == fields[k].c_str() || end != fields[k].c_str() + fields[k].size())
                throw InputError(at + quoted_field(fields[k]) + " is not a number");
            if (!std::isfinite(p[k]) || std::abs(p[k]) > 1e6)
                throw InputError(at + "coordinates must be finite and within ±1e6 m");
        }
        points.push_back(p);
    }
    if (points.size() < 2)
        throw InputError(name + ": lists " + std::to_string(points.size()) + " waypoints; a route needs at least 2");
    return points;
}

}  // namespace bvc3d
