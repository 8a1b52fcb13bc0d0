#pragma once
// CSV as every bvc3d table is written: numbers as the shortest text that reads back to the same
// double (format_number: exact, "nan" and "inf" as such), whole numbers as integers, flags as 0 and
// 1, text quoted only when it holds a comma, a quote or a line break, an absent value (an empty
// std::optional) as an empty field.
// Takes: a stream and rows of fields. Gives: the text, one line per row.
#include <charconv>
#include <concepts>
#include <optional>
#include <ostream>
#include <string>
#include <string_view>

#include "bvc3d/core/format.hpp"

namespace bvc3d {

// `text` as one CSV field: as it is, or quoted (quotes doubled) when it holds a comma, a quote or a
// line break.
inline std::string csv_text(std::string_view text) {
    if (text.find_first_of(",\"\n\r") == std::string_view::npos) return std::string(text);
    std::string out = "\"";
    for (const char c : text) out += c == '"' ? std::string("\"\"") : std::string(1, c);
    return out + "\"";
}

class CsvWriter {
public:
    explicit CsvWriter(std::ostream& out) : out_(out) {}

    // A whole row (a header is a row of names): each field as field() writes it, then the line's end.
    template <class... Fields>
    CsvWriter& row(const Fields&... fields) {
        (field(fields), ...);
        return end_row();
    }
    // One field of the row being written (a separator before all but its first).
    CsvWriter& field(double v) { return put(format_number(v)); }
    CsvWriter& field(bool v) { return put(v ? "1" : "0"); }
    CsvWriter& field(std::string_view text) { return put(csv_text(text)); }
    CsvWriter& field(const std::string& text) { return field(std::string_view(text)); }
    CsvWriter& field(const char* text) { return field(std::string_view(text)); }
    template <std::integral I>
    requires(!std::same_as<I, bool>) CsvWriter& field(I v) {
        char buf[24];
        return put(std::string_view(buf, static_cast<std::size_t>(std::to_chars(buf, buf + sizeof buf, v).ptr - buf)));
    }
    template <class T>
    CsvWriter& field(const std::optional<T>& v) {
        return v ? field(*v) : put("");
    }
    // Ends the row (a row with no field is an empty line).
    CsvWriter& end_row() {
        out_ << '\n';
        first_ = true;
        return *this;
    }

private:
    CsvWriter& put(std::string_view text) {
        if (!first_) out_ << ',';
        out_ << text;
        first_ = false;
        return *this;
    }

    std::ostream& out_;
    bool first_ = true;
};

}  // namespace bvc3d
