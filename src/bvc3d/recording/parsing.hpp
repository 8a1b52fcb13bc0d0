#pragma once
// Internal to the recording stage: the text and binary pieces every reader and writer shares.
// Takes: bytes and text. Gives: lines with their numbers, tokens, numbers parsed strictly (the
// whole token or nothing), numbers formatted to round-trip, byte-order-aware loads and stores,
// and overflow-checked sizes.
#include <algorithm>
#include <array>
#include <bit>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

namespace bvc3d::recording::detail {

// ---- Text ----

// Walks `text` line by line ('\n' ends a line; a '\r' before it is dropped), counting lines from
// `first_line`. `offset()` is the byte just after the last line returned.
class LineCursor {
public:
    explicit LineCursor(std::string_view text, std::size_t offset = 0, std::size_t first_line = 1)
        : text_(text), offset_(offset), next_line_(first_line) {}
    bool next(std::string_view& line);
    std::size_t line_number() const { return next_line_ - 1; }  // of the last line returned
    std::size_t offset() const { return offset_; }
    bool at_end() const { return offset_ >= text_.size(); }

private:
    std::string_view text_;
    std::size_t offset_;
    std::size_t next_line_;
};

std::string_view trim(std::string_view s);
// Blank, or a comment: the first non-blank character is '#'.
bool is_blank_or_comment(std::string_view line);

enum class Separators { whitespace, whitespace_and_commas };
// Splits `line` into `tokens` (cleared first). With commas, "1, 2,3," gives 1 2 3: commas count
// as whitespace, so a trailing comma is harmless.
void split(std::string_view line, Separators separators, std::vector<std::string_view>& tokens);

// The whole token as a number, or nothing. Accepts a leading '+', "nan" and "inf" (finiteness is
// the caller's business).
std::optional<double> parse_double(std::string_view token);
std::optional<std::uint64_t> parse_uint(std::string_view token);
std::optional<std::int64_t> parse_int(std::string_view token);

// The numbers of each data line of a text file (blank lines and '#' comments skipped), split at
// whitespace and commas. A token that is not a number, or a NaN/inf, is an InputError naming
// `file`, the line and the token.
struct NumberLine {
    std::size_t line = 0;
    std::vector<double> values;
};
std::vector<NumberLine> read_number_lines(const std::filesystem::path& file, std::string_view text);

// A token for an error message: quoted, at most 40 characters, non-printable bytes as '?'.
std::string quote_token(std::string_view token);

// Shortest text that reads back to exactly the same value.
void append_number(std::string& out, double value);
void append_number(std::string& out, float value);
void append_number(std::string& out, std::uint64_t value);

// ---- Binary ----

enum class ByteOrder { little, big };

template <class T>
T load(const char* bytes, ByteOrder order) {
    static_assert(std::is_arithmetic_v<T>);
    std::array<char, sizeof(T)> raw;
    std::memcpy(raw.data(), bytes, sizeof(T));
    if ((order == ByteOrder::little) != (std::endian::native == std::endian::little))
        std::reverse(raw.begin(), raw.end());
    T value;
    std::memcpy(&value, raw.data(), sizeof(T));
    return value;
}

template <class T>
void store(std::string& out, T value, ByteOrder order) {
    static_assert(std::is_arithmetic_v<T>);
    std::array<char, sizeof(T)> raw;
    std::memcpy(raw.data(), &value, sizeof(T));
    if ((order == ByteOrder::little) != (std::endian::native == std::endian::little))
        std::reverse(raw.begin(), raw.end());
    out.append(raw.data(), raw.size());
}

// The float nearest `value`; beyond float's range, ±infinity (a plain cast would be undefined).
inline float narrow_to_float(double value) {
    constexpr double largest = 3.4028234663852886e38;  // FLT_MAX
    if (value > largest) return std::numeric_limits<float>::infinity();
    if (value < -largest) return -std::numeric_limits<float>::infinity();
    return static_cast<float>(value);
}

// `value` as a float (narrowed as above) or as a double (unchanged).
template <class T>
T narrow_to(double value) {
    if constexpr (std::is_same_v<T, float>) return narrow_to_float(value);
    else return value;
}

// a·b and a+b, or nothing on overflow: sizes claimed by a header must not wrap around.
std::optional<std::uint64_t> checked_mul(std::uint64_t a, std::uint64_t b);
std::optional<std::uint64_t> checked_add(std::uint64_t a, std::uint64_t b);

}  // namespace bvc3d::recording::detail
