#include "bvc3d/config/yaml_reader.hpp"

#include <yaml-cpp/eventhandler.h>
#include <yaml-cpp/parser.h>

#include "bvc3d/core/format.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace bvc3d::config {

YamlView YamlView::load_file(const std::string& file) {
    std::error_code ec;
    if (std::filesystem::is_directory(file, ec)) throw ConfigError(file, "", "is a folder, not a file");
    if (std::filesystem::exists(file, ec) && !std::filesystem::is_regular_file(file, ec))
        throw ConfigError(file, "", "is not a regular file");
    std::ifstream in(file);
    if (!in) {
        throw ConfigError(file, "",
                          std::filesystem::exists(file, ec) ? "cannot be opened for reading" : "file does not exist");
    }
    std::stringstream text;
    text << in.rdbuf();
    return load_string(text.str(), file);
}

namespace {

// Counts the values of a document with its aliases expanded, as reading it would visit them: a
// few lines of anchors and aliases can stand for billions of values (a "billion laughs"), which
// are refused before the document is built.
class ExpandedSize : public YAML::EventHandler {
public:
    static constexpr double limit = 1e6;
    void OnDocumentStart(const YAML::Mark&) override {}
    void OnDocumentEnd() override {}
    void OnNull(const YAML::Mark&, YAML::anchor_t anchor) override { value(1, anchor); }
    void OnAlias(const YAML::Mark&, YAML::anchor_t anchor) override {
        value(anchor < sizes_.size() ? sizes_[anchor] : 1, 0);
    }
    void OnScalar(const YAML::Mark&, const std::string&, YAML::anchor_t anchor, const std::string&) override {
        value(1, anchor);
    }
    void OnSequenceStart(const YAML::Mark&, const std::string&, YAML::anchor_t anchor,
                         YAML::EmitterStyle::value) override {
        open_.push_back({1, anchor});
    }
    void OnSequenceEnd() override { close(); }
    void OnMapStart(const YAML::Mark&, const std::string&, YAML::anchor_t anchor, YAML::EmitterStyle::value) override {
        open_.push_back({1, anchor});
    }
    void OnMapEnd() override { close(); }
    double total() const { return total_; }

private:
    void value(double size, YAML::anchor_t anchor) {
        if (anchor) record(anchor, size);
        if (open_.empty()) total_ += size;
        else open_.back().first += size;
    }
    void close() {
        const auto [size, anchor] = open_.back();
        open_.pop_back();
        value(std::min(size, 2 * limit), anchor);
    }
    void record(YAML::anchor_t anchor, double size) {
        if (sizes_.size() <= anchor) sizes_.resize(anchor + 1, 1);
        sizes_[anchor] = size;
    }
    std::vector<std::pair<double, YAML::anchor_t>> open_;
    std::vector<double> sizes_;
    double total_ = 0;
};

}  // namespace

YamlView YamlView::load_string(const std::string& text, const std::string& name) {
    try {
        std::istringstream in(text);
        YAML::Parser parser(in);
        ExpandedSize size;
        parser.HandleNextDocument(size);
        if (size.total() > ExpandedSize::limit)
            throw ConfigError(name, "",
                              "its anchors and aliases expand to more than " +
                                  std::to_string(static_cast<long long>(ExpandedSize::limit)) + " values");
        YAML::Node n = YAML::Load(text);
        if (!n.IsDefined() || n.IsNull()) throw ConfigError(name, "", "is empty");
        return YamlView(n, name);
    } catch (const YAML::Exception& e) {
        throw ConfigError(name, "",
                          "malformed YAML at line " + std::to_string(e.mark.line + 1) + ", column " +
                              std::to_string(e.mark.column + 1) + ": " + e.msg);
    }
}

std::string YamlView::directory() const {
    const auto parent = std::filesystem::path(file_).parent_path();
    return parent.empty() ? "." : parent.string();
}

std::string YamlView::location() const {
    const auto m = node_.Mark();
    if (m.line < 0) return "";
    return " (line " + std::to_string(m.line + 1) + ")";
}

void YamlView::fail(const std::string& reason) const { throw ConfigError(file_, path_, reason + location()); }

void YamlView::fail_key(const std::string& key, const std::string& reason) const {
    throw ConfigError(file_, child_path(key), reason + location());
}

std::string path_in_file(const YamlView& v, const std::string& path) {
    if (std::filesystem::path(path).is_absolute()) return path;
    const auto candidate = std::filesystem::path(v.directory()) / path;
    std::error_code ec;
    return std::filesystem::exists(candidate, ec) ? candidate.string() : path;
}

void YamlView::expect_map(std::initializer_list<const char*> allowed) const {
    expect_map(std::vector<std::string>(allowed.begin(), allowed.end()));
}

void YamlView::expect_map(const std::vector<std::string>& allowed) const {
    if (!node_.IsMap()) fail("expected a mapping of keys to values");
    std::vector<std::string> seen;
    for (const auto& kv : node_) {
        if (!kv.first.IsScalar())
            YamlView(kv.first, file_, path_).fail("a key must be a name, not a list or a mapping");
        const std::string k = kv.first.Scalar();
        if (std::find(seen.begin(), seen.end(), k) != seen.end())
            YamlView(kv.first, file_, child_path(k)).fail("appears twice in the same mapping");
        seen.push_back(k);
        bool ok = false;
        for (const auto& a : allowed) ok = ok || a == k;
        if (!ok) {
            std::string list;
            for (const auto& a : allowed) list += (list.empty() ? "" : ", ") + a;
            YamlView(kv.first, file_, child_path(k)).fail("unknown key (allowed: " + list + ")");
        }
    }
}

YamlView YamlView::operator[](const std::string& key) const {
    if (!node_.IsMap()) fail("expected a mapping of keys to values");
    YAML::Node child = node_[key];
    if (!child.IsDefined()) fail_key(key, "is required but missing");
    return YamlView(child, file_, child_path(key));
}

YamlView YamlView::at(std::size_t i) const {
    if (!node_.IsSequence()) fail("expected a list");
    return YamlView(node_[i], file_, path_ + "[" + std::to_string(i) + "]");
}

std::size_t YamlView::size() const {
    if (!node_.IsSequence()) fail("expected a list");
    return node_.size();
}

std::vector<std::string> YamlView::keys() const {
    if (!node_.IsMap()) fail("expected a mapping of keys to values");
    std::vector<std::string> out;
    for (const auto& kv : node_) {
        if (!kv.first.IsScalar())
            YamlView(kv.first, file_, path_).fail("a key must be a name, not a list or a mapping");
        out.push_back(kv.first.Scalar());
    }
    return out;
}

double YamlView::as_double() const {
    if (!node_.IsScalar()) fail("expected a number");
    double v;
    try {
        v = node_.as<double>();
    } catch (const YAML::Exception&) {
        fail("expected a number, got '" + node_.Scalar() + "'");
    }
    if (!std::isfinite(v)) fail("expected a finite number, got '" + node_.Scalar() + "'");
    return v;
}

long long YamlView::as_int() const {
    if (!node_.IsScalar()) fail("expected an integer");
    try {
        return node_.as<long long>();
    } catch (const YAML::Exception&) {
        fail("expected an integer, got '" + node_.Scalar() + "'");
    }
}

std::uint64_t YamlView::as_uint64() const {
    if (!node_.IsScalar()) fail("expected a whole number from 0 to 18446744073709551615");
    const std::string& text = node_.Scalar();
    std::uint64_t v = 0;
    const auto r = std::from_chars(text.data(), text.data() + text.size(), v);
    if (text.empty() || r.ec != std::errc() || r.ptr != text.data() + text.size())
        fail("expected a whole number from 0 to 18446744073709551615 (2^64 - 1), got '" + text + "'");
    return v;
}

bool YamlView::as_bool() const {
    if (!node_.IsScalar()) fail("expected true or false");
    try {
        return node_.as<bool>();
    } catch (const YAML::Exception&) {
        fail("expected true or false, got '" + node_.Scalar() + "'");
    }
}

std::string YamlView::as_string() const {
    if (!node_.IsScalar()) fail("expected a text value");
    return node_.Scalar();
}

std::vector<double> YamlView::as_doubles(std::optional<std::size_t> n) const {
    if (!node_.IsSequence())
        fail(n ? "expected a list of " + std::to_string(*n) + " numbers" : "expected a list of numbers");
    if (n && node_.size() != *n)
        fail("expected a list of " + std::to_string(*n) + " numbers, got " + std::to_string(node_.size()));
    std::vector<double> out;
    for (std::size_t i = 0; i < node_.size(); ++i) out.push_back(at(i).as_double());
    return out;
}

double YamlView::get(const std::string& key, double fallback) const {
    return has(key) ? (*this)[key].as_double() : fallback;
}

int YamlView::get(const std::string& key, int fallback) const {
    if (!has(key)) return fallback;
    const long long v = (*this)[key].as_int();
    if (v < INT32_MIN || v > INT32_MAX) (*this)[key].fail("integer out of range");
    return static_cast<int>(v);
}

std::string YamlView::get(const std::string& key, const std::string& fallback) const {
    return has(key) ? (*this)[key].as_string() : fallback;
}

bool YamlView::get_bool(const std::string& key, bool fallback) const {
    return has(key) ? (*this)[key].as_bool() : fallback;
}

void read_fields(const YamlView& v, std::initializer_list<Field> fields, std::initializer_list<const char*> also) {
    std::vector<std::string> allowed;
    for (const auto& f : fields) allowed.emplace_back(f.key);
    for (const char* k : also) allowed.emplace_back(k);
    v.expect_map(allowed);
    for (const auto& f : fields) {
        if (!v.has(f.key)) continue;
        std::visit(
            [&](auto* target) {
                using T = std::remove_pointer_t<decltype(target)>;
                if constexpr (std::is_same_v<T, bool>) *target = v.get_bool(f.key, *target);
                else *target = v.get(f.key, *target);
            },
            f.target);
    }
}

namespace {
[[noreturn]] void fail_at(const YamlView& v, const std::string& key, const std::string& reason) {
    if (v.has(key)) v[key].fail(reason);
    v.fail_key(key, reason);
}
}  // namespace

void require_positive(const YamlView& v, const std::string& key, double value) {
    if (!(value > 0)) fail_at(v, key, "must be > 0, got " + format_number(value));
}

void require_range(const YamlView& v, const std::string& key, double value, double lo, double hi) {
    if (!(value >= lo && value <= hi))
        fail_at(v, key,
                "must be in [" + format_number(lo) + ", " + format_number(hi) + "], got " + format_number(value));
}

params::Value read_value(const YamlView& v, params::Kind kind, bool degrees) {
    using params::Kind;
    switch (kind) {
        case Kind::real:
            return degrees ? deg_to_rad(v.as_double()) : v.as_double();
        case Kind::integer:
            return v.as_int();
        case Kind::flag:
            return v.as_bool();
        case Kind::text:
        case Kind::choice:
            return v.as_string();
        case Kind::reals: {
            if (v.node().IsNull()) return std::vector<double>{};  // `key:` with nothing: an empty list
            std::vector<double> xs = v.as_doubles();
            if (degrees)
                for (double& x : xs) x = deg_to_rad(x);
            return xs;
        }
    }
    v.fail("unsupported value");
}

}  // namespace bvc3d::config
