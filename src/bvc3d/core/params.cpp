#include "bvc3d/core/params.hpp"

#include <algorithm>
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
        case Kind::text:
            return "";
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

namespace bvc3d::params {

namespace {

constexpr std::size_t kWidth = 100;      // wrap lists beyond this many characters
constexpr std::size_t kMaxAligned = 44;  // longer lines get their comment on the line above

}  // namespace

std::string CommentedYaml::scalar(const std::string& text) {
    static const std::string special_first = "?:,[]{}#&*!|>'\"%@`";
    bool plain = !text.empty() && text.front() != ' ' && text.back() != ' ' &&
                 special_first.find(text.front()) == std::string::npos && text.find(": ") == std::string::npos &&
                 text.find(" #") == std::string::npos && text.back() != ':' && text != "~" && text != "-" &&
                 text.rfind("- ", 0) != 0 && text != "null" && text != "Null" && text != "NULL";
    for (unsigned char c : text)
        if (c < 0x20 || c == 0x7f) plain = false;
    if (plain) return text;
    std::string q = "\"";
    for (char c : text) {
        if (c == '"' || c == '\\') q += '\\';
        if (c == '\n') {
            q += "\\n";
            continue;
        }
        q += c;
    }
    return q + "\"";
}

void CommentedYaml::comment(const std::string& indent, const std::string& text) {
    entries_.push_back({indent + "# " + text, "", indent});
}

void CommentedYaml::section(const std::string& indent, const std::string& key, const std::string& doc) {
    entries_.push_back({indent + key + ":", doc, indent});
}

void CommentedYaml::line(const std::string& indent, const std::string& key, const std::string& value,
                         const std::string& doc) {
    std::string text = indent + key + ": " + value;
    if (text.size() > kWidth && value.size() > 2 && value.front() == '[' && value.back() == ']') {
        // A long list: continuation lines start under the first item.
        const std::string cont(indent.size() + key.size() + 3, ' ');
        std::string cur = indent + key + ": [";
        bool empty_line = true;
        text.clear();
        for (std::size_t pos = 1; pos < value.size();) {
            std::size_t end = value.find(", ", pos);
            const bool last = end == std::string::npos;
            if (last) end = value.size() - 1;
            const std::string item = value.substr(pos, end - pos) + (last ? "]" : ",");
            if (!empty_line && cur.size() + 1 + item.size() > kWidth) {
                text += cur + "\n";
                cur = cont;
                empty_line = true;
            }
            cur += (empty_line ? "" : " ") + item;
            empty_line = false;
            pos = last ? value.size() : end + 2;
        }
        text += cur;
    }
    entries_.push_back({std::move(text), doc, indent});
}

std::string CommentedYaml::str() const {
    const auto aligned = [](const Entry& e) {
        return e.text.find('\n') == std::string::npos && e.text.size() <= kMaxAligned;
    };
    std::size_t column = 0;
    for (const auto& e : entries_)
        if (!e.doc.empty() && aligned(e)) column = std::max(column, e.text.size() + 2);
    std::string out;
    for (const auto& e : entries_) {
        if (e.doc.empty()) {
            out += e.text + "\n";
        } else if (aligned(e)) {
            out += e.text + std::string(column - e.text.size(), ' ') + "# " + e.doc + "\n";
        } else {
            out += e.indent + "# " + e.doc + "\n" + e.text + "\n";
        }
    }
    return out;
}

}  // namespace bvc3d::params
