#pragma once
// Numbers as text: the shortest decimal that reads back to the same double ("0.1", "45",
// "22.5", "nan"). Used for CSV, configuration text, labels and file names alike.
#include <charconv>
#include <cmath>
#include <string>

namespace bvc3d {

inline std::string format_number(double v) {
    if (std::isnan(v)) return "nan";
    if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
    char buf[32];
    const auto r = std::to_chars(buf, buf + sizeof buf, v);
    return std::string(buf, r.ptr);
}

}  // namespace bvc3d
