#pragma once
// Parameter tables. Each parameter struct lists its keys once — the kind of value, its limits and
// a one-line description — and everything that handles parameters reads that list: validation,
// YAML reading and writing (config stage), canonical text for fingerprints and the Python
// bindings. The struct's default member values are the defaults (the paper's); nothing else
// repeats them.
#include <cstddef>
#include <functional>
#include <limits>
#include <string>
#include <string_view>
#include <utility>
#include <variant>
#include <vector>

#include "bvc3d/core/error.hpp"

namespace bvc3d::params {

// A refused parameter value. `what` names the struct ("BVC layer"), `key` the field.
class ParamError : public InputError {
public:
    ParamError(const std::string& what, std::string key, std::string reason)
        : InputError(what + ": " + key + " " + reason), key_(std::move(key)), reason_(std::move(reason)) {}
    const std::string& key() const { return key_; }
    const std::string& reason() const { return reason_; }  // e.g. "must be > 0, got -1"

private:
    std::string key_, reason_;
};

using Value = std::variant<double, long long, bool, std::string, std::vector<double>>;

enum class Kind { real, integer, flag, text, choice, reals };

// Bounds on a number, or on each number of a list. Numbers must also be finite.
struct Limits {
    double lo = -std::numeric_limits<double>::infinity();
    double hi = std::numeric_limits<double>::infinity();
    bool lo_open = false, hi_open = false;

    bool contains(double v) const;
    std::string describe() const;  // "> 0", ">= 1", "in [0, 1)", "finite"
};
inline Limits finite() { return {}; }
inline Limits above(double lo) { return {lo, std::numeric_limits<double>::infinity(), true, false}; }
inline Limits at_least(double lo) { return {lo, std::numeric_limits<double>::infinity(), false, false}; }
inline Limits closed(double lo, double hi) { return {lo, hi, false, false}; }
inline Limits closed_open(double lo, double hi) { return {lo, hi, false, true}; }  // [lo, hi)
inline Limits open_closed(double lo, double hi) { return {lo, hi, true, false}; }  // (lo, hi]

template <class S>
struct Field {
    std::string key;
    std::string doc;
    Kind kind = Kind::real;
    Limits limits;                     // real, integer, reals (each element)
    std::vector<std::string> choices;  // choice: the accepted names
    bool radians = false;              // an angle: YAML also accepts `<key>_deg` in degrees
    std::size_t min_size = 0, max_size = std::numeric_limits<std::size_t>::max();  // reals
    std::function<Value(const S&)> get;
    std::function<void(S&, const Value&)> set;
    // Canonical text (yaml_lines) leaves the key out while it holds its default: a key added after
    // trial files were written keeps their text, hence their fingerprints, unchanged.
    bool quiet_default = false;

    Field& in_radians() {
        radians = true;
        return *this;
    }
    Field& quiet_at_default() {
        quiet_default = true;
        return *this;
    }
    Field& sizes(std::size_t lo, std::size_t hi) {
        min_size = lo;
        max_size = hi;
        return *this;
    }
};

// What is wrong with `v` for a field of this kind and limits, or "" if nothing.
std::string problem(Kind kind, const Limits& limits, const std::vector<std::string>& choices, std::size_t min_size,
                    std::size_t max_size, const Value& v);
// A value as configuration text: shortest round-trip numbers, true/false, [a, b, c].
std::string to_text(const Value& v);

template <class S>
class Table {
public:
    Table(std::string what, std::vector<Field<S>> fields) : what_(std::move(what)), fields_(std::move(fields)) {}

    const std::string& what() const { return what_; }
    const std::vector<Field<S>>& fields() const { return fields_; }
    std::vector<std::string> keys() const {
        std::vector<std::string> out;
        for (const auto& f : fields_) out.push_back(f.key);
        return out;
    }
    const Field<S>* find(std::string_view key) const {
        for (const auto& f : fields_)
            if (f.key == key) return &f;
        return nullptr;
    }
    // Sets one field after checking the value (ParamError naming the key otherwise).
    void set(S& s, const Field<S>& f, const Value& v) const {
        if (const std::string why = problem(f.kind, f.limits, f.choices, f.min_size, f.max_size, v); !why.empty())
            throw ParamError(what_, f.key, why);
        f.set(s, v);
    }
    // Every field within its limits, or ParamError for the first that is not.
    void check(const S& s) const {
        for (const auto& f : fields_)
            if (const std::string why = problem(f.kind, f.limits, f.choices, f.min_size, f.max_size, f.get(s));
                !why.empty())
                throw ParamError(what_, f.key, why);
    }
    [[noreturn]] void fail(const std::string& key, const std::string& reason) const {
        throw ParamError(what_, key, reason);
    }

private:
    std::string what_;
    std::vector<Field<S>> fields_;
};

// Field builders from data members.
template <class S>
Field<S> real(const char* key, double S::*m, Limits limits, const char* doc) {
    return {key,
            doc,
            Kind::real,
            limits,
            {},
            false,
            0,
            0,
            [m](const S& s) { return Value(s.*m); },
            [m](S& s, const Value& v) { s.*m = std::get<double>(v); },
            false};
}
template <class S>
Field<S> integer(const char* key, int S::*m, Limits limits, const char* doc) {
    return {key,
            doc,
            Kind::integer,
            limits,
            {},
            false,
            0,
            0,
            [m](const S& s) { return Value(static_cast<long long>(s.*m)); },
            [m](S& s, const Value& v) { s.*m = static_cast<int>(std::get<long long>(v)); },
            false};
}
template <class S>
Field<S> flag(const char* key, bool S::*m, const char* doc) {
    return {key,
            doc,
            Kind::flag,
            {},
            {},
            false,
            0,
            0,
            [m](const S& s) { return Value(s.*m); },
            [m](S& s, const Value& v) { s.*m = std::get<bool>(v); },
            false};
}
template <class S>
Field<S> text(const char* key, std::string S::*m, const char* doc) {
    return {key,
            doc,
            Kind::text,
            {},
            {},
            false,
            0,
            0,
            [m](const S& s) { return Value(s.*m); },
            [m](S& s, const Value& v) { s.*m = std::get<std::string>(v); },
            false};
}
template <class S>
Field<S> reals(const char* key, std::vector<double> S::*m, Limits each, const char* doc) {
    return {key,
            doc,
            Kind::reals,
            each,
            {},
            false,
            0,
            std::numeric_limits<std::size_t>::max(),
            [m](const S& s) { return Value(s.*m); },
            [m](S& s, const Value& v) { s.*m = std::get<std::vector<double>>(v); },
            false};
}
// An enum member with its names, in the order the enum's values are listed.
template <class S, class E>
Field<S> choice(const char* key, E S::*m, std::vector<std::pair<E, std::string>> names, const char* doc) {
    std::vector<std::string> choices;
    for (const auto& n : names) choices.push_back(n.second);
    return {key,
            doc,
            Kind::choice,
            {},
            choices,
            false,
            0,
            0,
            [m, names](const S& s) {
                for (const auto& [e, n] : names)
                    if (e == s.*m) return Value(n);
                return Value(std::string("?"));
            },
            [m, names](S& s, const Value& v) {
                for (const auto& [e, n] : names)
                    if (n == std::get<std::string>(v)) s.*m = e;
            },
            false};
}

}  // namespace bvc3d::params

namespace bvc3d::params {

// The struct as YAML lines `<indent>key: value`, in the table's order (reads back to the same
// values); a quiet_at_default key holding the struct's default is left out.
template <class S>
std::string yaml_lines(const Table<S>& table, const S& s, const std::string& indent) {
    std::string out;
    for (const auto& f : table.fields()) {
        const Value v = f.get(s);
        if (f.quiet_default && v == f.get(S{})) continue;
        out += indent + f.key + ": " + to_text(v) + "\n";
    }
    return out;
}

// YAML for people to read and edit (what `bvc3d config` prints): `key: value` lines with each key's
// description as a comment, the comments lined up, long lists wrapped. Values are written as
// yaml_lines writes them (shortest round-trip numbers; text quoted only where YAML needs it), so the
// text reads back to the same values.
class CommentedYaml {
public:
    void comment(const std::string& indent, const std::string& text);  // a line of its own: `# text`
    // `key:` opening a nested mapping.
    void section(const std::string& indent, const std::string& key, const std::string& doc = "");
    // `key: value`; `value` is YAML text (see scalar()).
    void line(const std::string& indent, const std::string& key, const std::string& value, const std::string& doc);
    template <class S>
    void fields(const Table<S>& table, const S& s, const std::string& indent) {
        for (const auto& f : table.fields())
            line(indent, f.key, f.kind == Kind::text ? scalar(to_text(f.get(s))) : to_text(f.get(s)), f.doc);
    }
    // Text as a YAML scalar: as it is when YAML reads it back unchanged, else double-quoted.
    static std::string scalar(const std::string& text);
    std::string str() const;

private:
    struct Entry {
        std::string text, doc, indent;  // text: the line(s) without the comment
    };
    std::vector<Entry> entries_;
};

}  // namespace bvc3d::params
