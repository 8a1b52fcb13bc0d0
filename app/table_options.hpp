#pragma once
// Options made from a parameter table (core/params.hpp) by one call: --KEY for each key asked for
// (underscores as dashes, or a name given), its help the table's description with the value's
// limits or choices, the default shown when asked; a key in radians also as --KEY-deg in degrees.
// Given values are set through the table, so they are checked as a YAML file's are; a refused one is
// an InputError naming the option and the reason.
// Takes: a table and a command. Gives: the options, and the values given set on a struct.
#include <CLI/CLI.hpp>

#include <charconv>
#include <deque>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "bvc3d/core/angles.hpp"
#include "bvc3d/core/error.hpp"
#include "bvc3d/core/params.hpp"
#include "cli_common.hpp"

namespace bvc3d::cli {

// "--key-name" for the table key "key_name".
std::string option_name(const std::string& key);
// The value of option `flag` for a field of `kind`: a number, a whole number, true/false, text, or
// comma-separated numbers; InputError naming `flag` for anything else.
params::Value option_value(params::Kind kind, const std::string& text, const std::string& flag);
// What --help shows for a value of this kind: FLOAT, INT, BOOL, TEXT, LIST.
std::string value_type_name(params::Kind kind);
// "(> 0)", "(in [0, 1])", "(rate_maps or means)": what a field takes, for a help text.
std::string accepted_text(params::Kind kind, const params::Limits& limits, const std::vector<std::string>& choices);

template <class S>
class TableOptions {
public:
    explicit TableOptions(const params::Table<S>& table) : table_(table) {}
    TableOptions(const TableOptions&) = delete;  // the options hold the addresses of the values
    TableOptions& operator=(const TableOptions&) = delete;

    // Adds an option for each of `keys` (every key of the table when empty) to `cmd`; `defaults`, when
    // given, shows each one's default; `names` gives other option names to keys (key -> "--flag").
    // Returns the options added, in the order of `keys`.
    std::vector<CLI::Option*> add_to(CLI::App& cmd, std::vector<std::string> keys = {}, const S* defaults = nullptr,
                                     const std::map<std::string, std::string>& names = {}) {
        if (keys.empty()) keys = table_.keys();
        std::vector<CLI::Option*> added;
        for (const auto& key : keys) {
            const params::Field<S>* f = table_.find(key);
            if (!f) throw std::logic_error("TableOptions: the " + table_.what() + " table has no key " + key);
            const auto named = names.find(key);
            const std::string flag = named != names.end() ? named->second : option_name(key);
            std::string help = f->doc + " " + accepted_text(f->kind, f->limits, f->choices);
            if (defaults) help += " [" + params::to_text(f->get(*defaults)) + "]";
            Given& g = given_.emplace_back(Given{f, flag, {}, false});
            added.push_back(cmd.add_option(flag, g.text, help)->type_name(value_type_name(f->kind)));
            if (f->radians) {
                Given& deg = given_.emplace_back(Given{f, flag + "-deg", {}, true});
                added.push_back(cmd.add_option(deg.flag, deg.text, "As " + flag + ", in degrees")
                                    ->type_name(value_type_name(f->kind))
                                    ->excludes(added.back()));
            }
        }
        return added;
    }

    // Whether the option of `key` (or its degrees) was given.
    bool given(const std::string& key) const {
        for (const auto& g : given_)
            if (g.field->key == key && g.text) return true;
        return false;
    }

    // The values given, set on `s` through the table (InputError naming the option when one is refused).
    void apply(S& s) const {
        for (const auto& g : given_) {
            if (!g.text) continue;
            params::Value v = option_value(g.field->kind, *g.text, g.flag);
            if (g.degrees) v = deg_to_rad(std::get<double>(v));
            try {
                table_.set(s, *g.field, v);
            } catch (const params::ParamError& e) {
                throw InputError(g.flag + ": " + e.reason());
            }
        }
    }

private:
    struct Given {
        const params::Field<S>* field;
        std::string flag;
        std::optional<std::string> text;
        bool degrees;
    };
    const params::Table<S>& table_;
    std::deque<Given> given_;  // stable addresses for CLI11
};

}  // namespace bvc3d::cli
