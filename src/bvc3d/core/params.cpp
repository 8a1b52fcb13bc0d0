#include "bvc3d/core/params.hpp"

#include <cmath>

#include "bvc3d/core/format.hpp"

namespace bvc3d::params {

bool Limits::contains(double v) const {
    if (!std::isfinite(v)) return false;
    const bool lo_ok = lo_open ? v > lo : v >= lo;
    const bool hi_ok = hi_open ? v < hi : v <= hi;
    return lo_ok && hi_ok;
}

std::string Limits::describe() const {
    const bool has_lo = std::isfinite(lo), has_hi = std::isfinite(hi);
    if (has_lo && has_hi)
        return std::string("in ") + (lo_open ? "(" : "[") + format_number(lo) + ", " + format_number(hi) +
               (hi_open ? ")" : "]");
    if (has_lo) return (lo_open ? "> " : ">= ") + format_number(lo);
    if (has_hi) return (hi_open ? "< " : "<= ") + format_number(hi);
    return "finite";
}

std::string problem(Kind kind, const Limits& limits, const std::vector<std::string>& choices, std::size_t min_size,
                    std::size_t max_size, const Value& v) {
    switch (kind) {
        case Kind::real:
        case Kind::integer: {
            const double x = kind == Kind::real ? std::get<double>(v) : static_cast<double>(std::get<long long>(v));
            if (!limits.contains(x)) return "must be " + limits.describe() + ", got " + to_text(v);
            return "";
        }
        case Kind::reals: {
            const auto& xs = std::get<std::vector<double>>(v);
            if (xs.size() < min_size) return "must list at least " + std::to_string(min_size) + " value(s)";
            if (xs.size() > max_size) return "must list at most " + std::to_string(max_size) + " values";
            for (std::size_t i = 0; i < xs.size(); ++i)
                if (!limits.contains(xs[i]))
                    return "must hold values " + limits.describe() + ", got " + format_number(xs[i]) + " at position " +
                           std::to_string(i);
            return "";
        }
        case Kind::choice: {
            const auto& s = std::get<std::string>(v);
            std::string list;
            for (const auto& c : choices) {
                if (c == s) return "";
                list += (list.empty() ? "" : ", ") + c;
            }
            return "must be one of " + list + ", got '" + s + "'";
        }
        case Kind::flag:
        case Kind::text: return "";
    }
    return "";
}

std::string to_text(const Value& v) {
    struct Visitor {
        std::string operator()(double x) const { return format_number(x); }
        std::string operator()(long long x) const { return std::to_string(x); }
        std::string operator()(bool x) const { return x ? "true" : "false"; }
        std::string operator()(const std::string& x) const { return x; }
        std::string operator()(const std::vector<double>& xs) const {
            std::string s = "[";
            for (std::size_t i = 0; i < xs.size(); ++i) s += (i ? ", " : "") + format_number(xs[i]);
            return s + "]";
        }
    };
    return std::visit(Visitor{}, v);
}

}  // namespace bvc3d::params
