#include "cli_common.hpp"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <vector>

#include "bvc3d/core/angles.hpp"
#include "bvc3d/core/error.hpp"

namespace bvc3d::cli {

namespace {
double parse_number(const std::string& s, const std::string& what) {
    double v = 0;
    const auto* end = s.data() + s.size();
    const auto r = std::from_chars(s.data(), end, v);
    if (s.empty() || r.ec != std::errc() || r.ptr != end || !std::isfinite(v))
        throw InputError("--pose: " + what + " '" + s + "' is not a finite number");
    return v;
}
}  // namespace

Pose parse_pose(const std::string& text) {
    std::vector<std::string> parts;
    std::size_t start = 0;
    for (std::size_t i = 0; i <= text.size(); ++i)
        if (i == text.size() || text[i] == ',') {
            parts.push_back(text.substr(start, i - start));
            start = i + 1;
        }
    if (parts.size() != 3) throw InputError("--pose expects X,Y,HEADING (three comma-separated numbers), got '" + text + "'");
    Pose p;
    p.x = parse_number(parts[0], "X");
    p.y = parse_number(parts[1], "Y");
    std::string h = parts[2];
    const bool degrees = h.size() > 3 && h.compare(h.size() - 3, 3, "deg") == 0;
    if (degrees) h.resize(h.size() - 3);
    p.heading = parse_number(h, "HEADING");
    if (degrees) p.heading = deg_to_rad(p.heading);
    return p;
}

std::string num(double v) {
    char buf[32];
    const auto r = std::to_chars(buf, buf + sizeof buf, v);  // shortest exact round-trip form
    return std::string(buf, r.ptr);
}

}  // namespace bvc3d::cli
