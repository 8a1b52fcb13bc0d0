#pragma once
// A thin, validating view over yaml-cpp nodes: every error names the file, the key path and the
// reason, and unknown keys are rejected. All YAML mappings of bvc3d are written with it.
#include <yaml-cpp/yaml.h>

#include <cstdint>
#include <functional>
#include <initializer_list>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "bvc3d/core/angles.hpp"
#include "bvc3d/core/error.hpp"
#include "bvc3d/core/params.hpp"

namespace bvc3d::config {

class YamlView {
public:
    YamlView(YAML::Node node, std::string file, std::string path = "")
        : node_(std::move(node)), file_(std::move(file)), path_(std::move(path)) {}

    // Parse a file or a string (`name` is what error messages call it).
    static YamlView load_file(const std::string& file);
    static YamlView load_string(const std::string& text, const std::string& name);

    const YAML::Node& node() const { return node_; }
    const std::string& file() const { return file_; }
    const std::string& path() const { return path_; }
    std::string directory() const;  // the file's folder, for relative paths inside it

    bool is_map() const { return node_.IsMap(); }
    bool is_sequence() const { return node_.IsSequence(); }
    bool is_scalar() const { return node_.IsScalar(); }
    bool has(const std::string& key) const { return node_.IsMap() && node_[key].IsDefined(); }

    [[noreturn]] void fail(const std::string& reason) const;
    [[noreturn]] void fail_key(const std::string& key, const std::string& reason) const;

    // This node must be a map whose keys are all in `allowed`.
    void expect_map(std::initializer_list<const char*> allowed) const;
    void expect_map(const std::vector<std::string>& allowed) const;

    YamlView operator[](const std::string& key) const;  // fails if missing
    YamlView at(std::size_t i) const;
    std::size_t size() const;               // of a sequence (fails if not one)
    std::vector<std::string> keys() const;  // of a map, in file order

    double as_double() const;  // finite number
    long long as_int() const;
    std::uint64_t as_uint64() const;  // decimal digits only: 0 .. 2^64 - 1 (seeds)
    bool as_bool() const;
    std::string as_string() const;
    std::vector<double> as_doubles(std::optional<std::size_t> n = std::nullopt) const;

    // Optional members with a default.
    double get(const std::string& key, double fallback) const;
    int get(const std::string& key, int fallback) const;
    std::string get(const std::string& key, const std::string& fallback) const;
    std::string get(const std::string& key, const char* fallback) const { return get(key, std::string(fallback)); }
    bool get_bool(const std::string& key, bool fallback) const;

    std::string child_path(const std::string& key) const { return path_.empty() ? key : path_ + "." + key; }

private:
    std::string location() const;  // " (line L)" when known
    YAML::Node node_;
    std::string file_, path_;
};

// A path written in the YAML file of `v`: relative to that file's folder when such a file exists there;
// anything else (absolute paths, preset names) as it is.
std::string path_in_file(const YamlView& v, const std::string& path);

// One optional member of a mapping and the field it fills.
struct Field {
    const char* key;
    std::variant<double*, int*, std::string*, bool*> target;
};

// Fills each field whose key is present (checking its type) and rejects any key that is neither a
// field nor in `also` (keys the caller reads itself). One table per struct: every key written once.
void read_fields(const YamlView& v, std::initializer_list<Field> fields, std::initializer_list<const char*> also = {});

// Number checks with the standard message.
void require_positive(const YamlView& v, const std::string& key, double value);
void require_range(const YamlView& v, const std::string& key, double value, double lo, double hi);

// The value of a table field at `v` (the field's own key, or `<key>_deg` in degrees for angles).
params::Value read_value(const YamlView& v, params::Kind kind, bool degrees);

// Runs `check` (a struct's validate()) and reports a ParamError at the line of the key it names.
template <class F>
void check_at(const YamlView& v, F&& check) {
    try {
        check();
    } catch (const params::ParamError& e) {
        if (v.has(e.key())) v[e.key()].fail(e.reason());
        if (v.has(e.key() + "_deg")) v[e.key() + "_deg"].fail(e.reason());
        v.fail(e.what());
    }
}

// Fills `s` from the keys of mapping `v` that name fields of `table` (each value checked against the
// field's kind and limits; angles also as `<key>_deg`), then validates the whole struct. Keys in
// `also` are the caller's to read; any other key is an error.
template <class S>
void read_table(const YamlView& v, S& s, const params::Table<S>& table, const std::vector<std::string>& also) {
    std::vector<std::string> allowed;
    for (const auto& f : table.fields()) {
        allowed.push_back(f.key);
        if (f.radians) allowed.push_back(f.key + "_deg");
    }
    allowed.insert(allowed.end(), also.begin(), also.end());
    v.expect_map(allowed);
    for (const auto& f : table.fields()) {
        const std::string deg = f.key + "_deg";
        if (f.radians && v.has(f.key) && v.has(deg)) v.fail("give '" + f.key + "' (rad) or '" + deg + "', not both");
        const bool in_degrees = f.radians && v.has(deg);
        if (!v.has(f.key) && !in_degrees) continue;
        const YamlView at = v[in_degrees ? deg : f.key];
        try {
            table.set(s, f, read_value(at, f.kind, in_degrees));
        } catch (const params::ParamError& e) {
            at.fail(e.reason());
        }
    }
    check_at(v, [&] { s.validate(); });
}
template <class S>
void read_table(const YamlView& v, S& s, const params::Table<S>& table, std::initializer_list<const char*> also = {}) {
    read_table(v, s, table, std::vector<std::string>(also.begin(), also.end()));
}

}  // namespace bvc3d::config
