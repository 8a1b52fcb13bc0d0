#include "table_options.hpp"

#include <charconv>

namespace bvc3d::cli {

std::string option_name(const std::string& key) {
    std::string flag = "--" + key;
    for (char& c : flag)
        if (c == '_') c = '-';
    return flag;
}

params::Value option_value(params::Kind kind, const std::string& text, const std::string& flag) {
    switch (kind) {
        case params::Kind::real:
            return parse_number(text, flag);
        case params::Kind::integer: {
            long long v = 0;
            const auto* end = text.data() + text.size();
            const auto r = std::from_chars(text.data(), end, v);
            if (text.empty() || r.ec != std::errc() || r.ptr != end)
                throw InputError(flag + " '" + text + "' is not a whole number");
            return v;
        }
        case params::Kind::flag:
            if (text == "true" || text == "1") return true;
            if (text == "false" || text == "0") return false;
            throw InputError(flag + " '" + text + "' is not true or false");
        case params::Kind::text:
        case params::Kind::choice:
            return text;
        case params::Kind::reals: {
            std::vector<double> values;
            for (const auto& item : split_commas(text, EmptyItems::keep)) values.push_back(parse_number(item, flag));
            return values;
        }
    }
    return text;
}

std::string value_type_name(params::Kind kind) {
    switch (kind) {
        case params::Kind::real:
            return "FLOAT";
        case params::Kind::integer:
            return "INT";
        case params::Kind::flag:
            return "BOOL";
        case params::Kind::text:
        case params::Kind::choice:
            return "TEXT";
        case params::Kind::reals:
            return "LIST";
    }
    return "TEXT";
}

std::string accepted_text(params::Kind kind, const params::Limits& limits, const std::vector<std::string>& choices) {
    switch (kind) {
        case params::Kind::real:
        case params::Kind::integer:
            return "(" + std::string(kind == params::Kind::integer ? "a whole number " : "") + limits.describe() + ")";
        case params::Kind::flag:
            return "(true or false)";
        case params::Kind::text:
            return "";
        case params::Kind::choice: {
            std::string list;
            for (std::size_t i = 0; i < choices.size(); ++i)
                list += (i == 0 ? "" : i + 1 == choices.size() ? " or " : ", ") + choices[i];
            return "(" + list + ")";
        }
        case params::Kind::reals:
            return "(comma-separated, each " + limits.describe() + ")";
    }
    return "";
}

}  // namespace bvc3d::cli
