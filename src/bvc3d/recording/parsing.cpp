#include "bvc3d/recording/parsing.hpp"

#include <charconv>
#include <cmath>

#include "bvc3d/recording/file_io.hpp"

namespace bvc3d::recording::detail {

namespace {

bool is_space(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; }

template <class T>
std::optional<T> parse_whole(std::string_view token) {
    if (token.size() > 1 && token.front() == '+' && token[1] != '-') token.remove_prefix(1);
    T value{};
    const auto [end, error] = std::from_chars(token.data(), token.data() + token.size(), value);
    if (error != std::errc() || end != token.data() + token.size() || token.empty()) return std::nullopt;
    return value;
}

template <class T>
void append_chars(std::string& out, T value) {
    char buffer[32];
    const auto result = std::to_chars(buffer, buffer + sizeof buffer, value);
    out.append(buffer, result.ptr);
}

}  // namespace

bool LineCursor::next(std::string_view& line) {
    if (offset_ >= text_.size()) return false;
    const std::size_t newline = text_.find('\n', offset_);
    const std::size_t stop = newline == std::string_view::npos ? text_.size() : newline;
    line = text_.substr(offset_, stop - offset_);
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    offset_ = newline == std::string_view::npos ? text_.size() : newline + 1;
    ++next_line_;
    return true;
}

std::string_view trim(std::string_view s) {
    while (!s.empty() && is_space(s.front())) s.remove_prefix(1);
    while (!s.empty() && is_space(s.back())) s.remove_suffix(1);
    return s;
}

bool is_blank_or_comment(std::string_view line) {
    const std::string_view content = trim(line);
    return content.empty() || content.front() == '#';
}

void split(std::string_view line, Separators separators, std::vector<std::string_view>& tokens) {
    tokens.clear();
    const bool commas = separators == Separators::whitespace_and_commas;
    const auto is_separator = [commas](char c) { return is_space(c) || (commas && c == ','); };
    std::size_t i = 0;
    while (i < line.size()) {
        while (i < line.size() && is_separator(line[i])) ++i;
        const std::size_t start = i;
        while (i < line.size() && !is_separator(line[i])) ++i;
        if (i > start) tokens.push_back(line.substr(start, i - start));
    }
}

std::optional<double> parse_double(std::string_view token) { return parse_whole<double>(token); }
std::optional<std::uint64_t> parse_uint(std::string_view token) { return parse_whole<std::uint64_t>(token); }
std::optional<std::int64_t> parse_int(std::string_view token) { return parse_whole<std::int64_t>(token); }

std::vector<NumberLine> read_number_lines(const std::filesystem::path& file, std::string_view text) {
    std::vector<NumberLine> lines;
    LineCursor cursor(text);
    std::string_view line;
    std::vector<std::string_view> tokens;
    while (cursor.next(line)) {
        if (is_blank_or_comment(line)) continue;
        split(line, Separators::whitespace_and_commas, tokens);
        NumberLine numbers{cursor.line_number(), {}};
        for (const std::string_view token : tokens) {
            const auto value = parse_double(token);
            if (!value) throw input_error(file, line_ref(cursor.line_number()), "bad number " + quote_token(token));
            if (!std::isfinite(*value))
                throw input_error(file, line_ref(cursor.line_number()),
                                  "value " + quote_token(token) + " is not finite");
            numbers.values.push_back(*value);
        }
        lines.push_back(std::move(numbers));
    }
    return lines;
}

std::string quote_token(std::string_view token) {
    constexpr std::size_t max_shown = 40;
    std::string out = "'";
    for (std::size_t i = 0; i < token.size() && i < max_shown; ++i) {
        const auto c = static_cast<unsigned char>(token[i]);
        out += (c >= 0x20 && c < 0x7f) ? static_cast<char>(c) : '?';
    }
    if (token.size() > max_shown) out += "...";
    return out + "'";
}

void append_number(std::string& out, double value) { append_chars(out, value); }
void append_number(std::string& out, float value) { append_chars(out, value); }
void append_number(std::string& out, std::uint64_t value) { append_chars(out, value); }

std::optional<std::uint64_t> checked_mul(std::uint64_t a, std::uint64_t b) {
    std::uint64_t product = 0;
    if (__builtin_mul_overflow(a, b, &product)) return std::nullopt;
    return product;
}

std::optional<std::uint64_t> checked_add(std::uint64_t a, std::uint64_t b) {
    std::uint64_t sum = 0;
    if (__builtin_add_overflow(a, b, &sum)) return std::nullopt;
    return sum;
}

}  // namespace bvc3d::recording::detail
