#include "bvc3d/recording/pcd.hpp"

#include <lzf.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "bvc3d/core/atomic_file.hpp"
#include "bvc3d/recording/cloud_builder.hpp"
#include "bvc3d/recording/file_io.hpp"
#include "bvc3d/recording/parsing.hpp"

namespace bvc3d::recording {

namespace fs = std::filesystem;
using namespace detail;

namespace {

// LZF codes at most 264 repeated bytes in a 3-byte back reference: no valid block unpacks to
// more than 88 times its size. Checked before trusting a header's size for an allocation.
constexpr std::uint64_t max_lzf_expansion = 88;

enum class PcdData { ascii, binary, binary_compressed };

// One header line: the values after its keyword, and its line number (0 when absent).
struct HeaderEntry {
    std::vector<std::string_view> values;
    std::size_t line = 0;
};

struct RawHeader {
    HeaderEntry version, fields, size, type, count, width, height, viewpoint, points, data;
    std::size_t data_offset = 0;  // first byte after the DATA line

    HeaderEntry* entry(std::string_view keyword) {
        if (keyword == "VERSION") return &version;
        if (keyword == "FIELDS") return &fields;
        if (keyword == "SIZE") return &size;
        if (keyword == "TYPE") return &type;
        if (keyword == "COUNT") return &count;
        if (keyword == "WIDTH") return &width;
        if (keyword == "HEIGHT") return &height;
        if (keyword == "VIEWPOINT") return &viewpoint;
        if (keyword == "POINTS") return &points;
        if (keyword == "DATA") return &data;
        return nullptr;
    }
};

struct PcdField {
    std::string_view name;
    std::uint64_t size = 0;    // bytes per value
    char type = 'F';           // I, U or F
    std::uint64_t count = 1;   // values per point
    std::uint64_t offset = 0;  // bytes before this field in one point record
};

struct PcdHeader {
    std::vector<PcdField> fields;
    std::array<std::size_t, 3> xyz{};  // indices of x, y, z in `fields`
    std::uint64_t points = 0;
    std::uint64_t point_bytes = 0;  // one point record in binary data
    std::uint64_t data_bytes = 0;   // points · point_bytes
    PcdData data = PcdData::ascii;
    std::size_t data_offset = 0;
    std::size_t data_line = 0;
};

// ---- Header ----

void check_version(const fs::path& file, const HeaderEntry& version) {
    if (version.values.size() != 1 || (version.values[0] != "0.7" && version.values[0] != ".7"))
        throw input_error(file, line_ref(version.line),
                          "unsupported PCD version " + quote_token(version.values.empty() ? "" : version.values[0]) +
                              ": only 0.7 is read");
}

RawHeader read_raw_header(const fs::path& file, std::string_view bytes) {
    RawHeader raw;
    LineCursor lines(bytes);
    std::string_view line;
    std::vector<std::string_view> tokens;
    bool seen_entry = false;
    while (lines.next(line)) {
        if (is_blank_or_comment(line)) continue;
        split(line, Separators::whitespace, tokens);
        HeaderEntry* entry = raw.entry(tokens.front());
        if (entry == nullptr && !seen_entry)
            throw input_error(file, line_ref(lines.line_number()),
                              "not a PCD file: the header starts with " + quote_token(tokens.front()));
        if (entry == nullptr)
            throw input_error(file, line_ref(lines.line_number()),
                              "unknown header entry " + quote_token(tokens.front()));
        if (entry->line != 0)
            throw input_error(
                file, line_ref(lines.line_number()),
                "second " + std::string(tokens.front()) + " line (first on " + line_ref(entry->line) + ")");
        entry->values.assign(tokens.begin() + 1, tokens.end());
        entry->line = lines.line_number();
        seen_entry = true;
        if (entry == &raw.version) check_version(file, raw.version);  // before other versions' entries confuse us
        if (entry == &raw.data) {
            raw.data_offset = lines.offset();
            return raw;
        }
    }
    throw input_error(file, seen_entry ? "header has no DATA line" : "not a PCD file: no header");
}

const HeaderEntry& required(const fs::path& file, const HeaderEntry& entry, std::string_view keyword) {
    if (entry.line == 0) throw input_error(file, "header has no " + std::string(keyword) + " line");
    return entry;
}

std::uint64_t single_count(const fs::path& file, const HeaderEntry& entry, std::string_view keyword) {
    if (entry.values.size() != 1)
        throw input_error(file, line_ref(entry.line),
                          std::string(keyword) + " takes one value, found " + std::to_string(entry.values.size()));
    const auto value = parse_uint(entry.values.front());
    if (!value)
        throw input_error(file, line_ref(entry.line),
                          "bad " + std::string(keyword) + " value " + quote_token(entry.values.front()) +
                              ": expected a whole number");
    return *value;
}

// SIZE, TYPE and COUNT give one entry per field.
void check_one_per_field(const fs::path& file, const HeaderEntry& entry, std::string_view keyword,
                         const HeaderEntry& fields) {
    if (entry.line != 0 && entry.values.size() != fields.values.size())
        throw input_error(file, line_ref(entry.line),
                          std::string(keyword) + " has " + std::to_string(entry.values.size()) +
                              " entries but FIELDS (" + line_ref(fields.line) + ") has " +
                              std::to_string(fields.values.size()));
}

PcdField parse_field(const fs::path& file, const RawHeader& raw, std::size_t i) {
    PcdField field;
    field.name = raw.fields.values[i];
    const std::string name = quote_token(field.name);
    const auto size = parse_uint(raw.size.values[i]);
    if (!size || (*size != 1 && *size != 2 && *size != 4 && *size != 8))
        throw input_error(
            file, line_ref(raw.size.line),
            "SIZE of field " + name + " is " + quote_token(raw.size.values[i]) + ": expected 1, 2, 4 or 8");
    field.size = *size;
    const std::string_view type = raw.type.values[i];
    if (type != "I" && type != "U" && type != "F")
        throw input_error(file, line_ref(raw.type.line),
                          "TYPE of field " + name + " is " + quote_token(type) + ": expected I, U or F");
    field.type = type.front();
    if (raw.count.line != 0) {
        const auto count = parse_uint(raw.count.values[i]);
        if (!count || *count == 0)
            throw input_error(file, line_ref(raw.count.line),
                              "COUNT of field " + name + " is " + quote_token(raw.count.values[i]) +
                                  ": expected a whole number of at least 1");
        field.count = *count;
    }
    return field;
}

// Fields with their byte offsets in a point record; returns the record's size.
std::uint64_t parse_fields(const fs::path& file, const RawHeader& raw, std::vector<PcdField>& fields) {
    if (raw.fields.values.empty()) throw input_error(file, line_ref(raw.fields.line), "FIELDS names no field");
    check_one_per_field(file, raw.size, "SIZE", raw.fields);
    check_one_per_field(file, raw.type, "TYPE", raw.fields);
    check_one_per_field(file, raw.count, "COUNT", raw.fields);
    std::uint64_t offset = 0;
    for (std::size_t i = 0; i < raw.fields.values.size(); ++i) {
        PcdField field = parse_field(file, raw, i);
        field.offset = offset;
        const auto bytes = checked_mul(field.size, field.count);
        const auto next = bytes ? checked_add(offset, *bytes) : std::nullopt;
        if (!next) throw input_error(file, line_ref(raw.count.line), "point record too large: COUNT overflows");
        offset = *next;
        fields.push_back(field);
    }
    return offset;
}

std::size_t find_coordinate(const fs::path& file, const RawHeader& raw, const std::vector<PcdField>& fields,
                            std::string_view name) {
    const auto named = [name](const PcdField& f) { return f.name == name; };
    const auto found = std::find_if(fields.begin(), fields.end(), named);
    if (found == fields.end())
        throw input_error(file, line_ref(raw.fields.line),
                          "missing field '" + std::string(name) + "': x, y and z are required");
    if (std::count_if(fields.begin(), fields.end(), named) > 1)
        throw input_error(file, line_ref(raw.fields.line), "field '" + std::string(name) + "' appears twice");
    if (found->type != 'F' || (found->size != 4 && found->size != 8))
        throw input_error(file, line_ref(raw.type.line),
                          "field '" + std::string(name) + "' is TYPE " + found->type + " SIZE " +
                              std::to_string(found->size) + ": x, y and z must be float (TYPE F, SIZE 4 or 8)");
    if (found->count != 1)
        throw input_error(file, line_ref(raw.count.line),
                          "field '" + std::string(name) + "' has COUNT " + std::to_string(found->count) +
                              ": x, y and z take one value each");
    return static_cast<std::size_t>(found - fields.begin());
}

std::uint64_t parse_points(const fs::path& file, const RawHeader& raw) {
    const std::uint64_t width = single_count(file, required(file, raw.width, "WIDTH"), "WIDTH");
    const std::uint64_t height = single_count(file, required(file, raw.height, "HEIGHT"), "HEIGHT");
    const auto product = checked_mul(width, height);
    if (!product) throw input_error(file, line_ref(raw.height.line), "WIDTH * HEIGHT is too large");
    if (raw.points.line == 0) return *product;  // POINTS is redundant; WIDTH and HEIGHT say it
    const std::uint64_t points = single_count(file, raw.points, "POINTS");
    if (points != *product)
        throw input_error(file, line_ref(raw.points.line),
                          "POINTS " + std::to_string(points) +
                              " does not equal WIDTH * HEIGHT = " + std::to_string(width) + " * " +
                              std::to_string(height) + " = " + std::to_string(*product));
    return points;
}

PcdData parse_data(const fs::path& file, const HeaderEntry& data) {
    const std::string_view value = data.values.size() == 1 ? data.values[0] : std::string_view();
    if (value == "ascii") return PcdData::ascii;
    if (value == "binary") return PcdData::binary;
    if (value == "binary_compressed") return PcdData::binary_compressed;
    throw input_error(file, line_ref(data.line),
                      "unknown DATA encoding " + quote_token(value) + ": expected ascii, binary or binary_compressed");
}

PcdHeader parse_pcd_header(const fs::path& file, std::string_view bytes) {
    const RawHeader raw = read_raw_header(file, bytes);
    required(file, raw.fields, "FIELDS");
    required(file, raw.size, "SIZE");
    required(file, raw.type, "TYPE");
    PcdHeader header;
    header.point_bytes = parse_fields(file, raw, header.fields);
    for (std::size_t axis = 0; axis < 3; ++axis)
        header.xyz[axis] = find_coordinate(file, raw, header.fields, std::string_view("xyz").substr(axis, 1));
    header.points = parse_points(file, raw);
    const auto data_bytes = checked_mul(header.points, header.point_bytes);
    if (!data_bytes) throw input_error(file, line_ref(raw.points.line), "too many points for the point record size");
    header.data_bytes = *data_bytes;
    header.data = parse_data(file, raw.data);
    header.data_offset = raw.data_offset;
    header.data_line = raw.data.line;
    return header;
}

// ---- Data ----

// Which field a value of an ascii line belongs to, for error messages.
std::string_view field_of_value(const PcdHeader& header, std::size_t value) {
    for (const PcdField& field : header.fields) {
        if (field.name == "_") continue;
        if (value < field.count) return field.name;
        value -= field.count;
    }
    return {};
}

PointCloud read_ascii(const fs::path& file, std::string_view bytes, const PcdHeader& header) {
    // PCL writes no values for "_" padding fields in ascii.
    std::array<std::size_t, 3> xyz_value{};
    std::size_t values_per_point = 0;
    for (std::size_t f = 0; f < header.fields.size(); ++f) {
        for (std::size_t axis = 0; axis < 3; ++axis)
            if (header.xyz[axis] == f) xyz_value[axis] = values_per_point;
        if (header.fields[f].name != "_") values_per_point += static_cast<std::size_t>(header.fields[f].count);
    }
    // A point line holds at least one character per value: no reservation beyond the file's size.
    const std::size_t most_points = (bytes.size() - header.data_offset) / values_per_point + 1;
    CloudBuilder cloud(std::min<std::uint64_t>(header.points, most_points));
    LineCursor lines(bytes, header.data_offset, header.data_line + 1);
    std::string_view line;
    std::vector<std::string_view> tokens;
    std::vector<double> values;
    std::uint64_t point = 0;
    while (lines.next(line)) {
        if (trim(line).empty()) continue;
        const std::string where = line_ref(lines.line_number());
        if (point == header.points)
            throw input_error(
                file, where,
                "trailing data after the " + std::to_string(header.points) + " points the header declares");
        split(line, Separators::whitespace, tokens);
        if (tokens.size() != values_per_point)
            throw input_error(file, where,
                              "expected " + std::to_string(values_per_point) + " values for point " +
                                  std::to_string(point) + ", found " + std::to_string(tokens.size()));
        values.clear();
        for (std::size_t v = 0; v < tokens.size(); ++v) {
            const auto value = parse_double(tokens[v]);
            if (!value)
                throw input_error(
                    file, where,
                    "bad number " + quote_token(tokens[v]) + " in field " + quote_token(field_of_value(header, v)));
            values.push_back(*value);
        }
        const auto coordinate = [&](std::size_t axis) {
            return as_stored(values[xyz_value[axis]], header.fields[header.xyz[axis]].size);
        };
        cloud.add(coordinate(0), coordinate(1), coordinate(2));
        ++point;
    }
    if (point < header.points)
        throw input_error(file, "truncated: the header declares " + std::to_string(header.points) +
                                    " points but the data has " + std::to_string(point) + " lines");
    return std::move(cloud).finish(file);
}

// The point data must be exactly as long as the header says; `found` bytes follow `header`.
void check_data_length(const fs::path& file, std::uint64_t found, std::uint64_t expected, std::string_view what,
                       std::string_view header = "the header") {
    if (found < expected)
        throw input_error(file, "truncated: " + std::string(what) + " needs " + std::to_string(expected) +
                                    " bytes but only " + std::to_string(found) + " follow " + std::string(header));
    if (found > expected)
        throw input_error(file, "trailing data: " + std::to_string(found - expected) + " bytes after the " +
                                    std::to_string(expected) + " bytes of " + std::string(what));
}

std::string describe_points(const PcdHeader& header) {
    return std::to_string(header.points) + " points of " + std::to_string(header.point_bytes) + " bytes";
}

PointCloud read_binary(const fs::path& file, std::string_view bytes, const PcdHeader& header) {
    check_data_length(file, bytes.size() - header.data_offset, header.data_bytes, describe_points(header));
    CoordinateColumn columns[3];
    for (std::size_t axis = 0; axis < 3; ++axis) {
        const PcdField& field = header.fields[header.xyz[axis]];
        columns[axis] = {header.data_offset + field.offset, header.point_bytes, field.size};
    }
    return gather_points(file, bytes, columns, header.points, ByteOrder::little);
}

// The LZF block unpacked: each field's values for all points, one field after the other.
std::string decompress_block(const fs::path& file, std::string_view body, const PcdHeader& header) {
    if (body.size() < 8)
        throw input_error(file, "truncated: binary_compressed data needs an 8-byte size header, found " +
                                    std::to_string(body.size()) + " bytes");
    const std::uint64_t compressed = load<std::uint32_t>(body.data(), ByteOrder::little);
    const std::uint64_t uncompressed = load<std::uint32_t>(body.data() + 4, ByteOrder::little);
    if (uncompressed != header.data_bytes)
        throw input_error(file, "compressed size mismatch: the block unpacks to " + std::to_string(uncompressed) +
                                    " bytes but the header declares " + describe_points(header) + " = " +
                                    std::to_string(header.data_bytes) + " bytes");
    check_data_length(file, body.size() - 8, compressed, "the compressed block", "its size header");
    if (uncompressed > max_lzf_expansion * compressed)
        throw input_error(file, "compressed size mismatch: " + std::to_string(compressed) +
                                    " bytes of LZF data cannot unpack to " + std::to_string(uncompressed) + " bytes");
    std::string block(static_cast<std::size_t>(uncompressed), '\0');
    const unsigned unpacked = lzf_decompress(body.data() + 8, static_cast<unsigned>(compressed), block.data(),
                                             static_cast<unsigned>(uncompressed));
    if (unpacked != uncompressed)
        throw input_error(file, "LZF decompression failed: corrupt compressed data (unpacked " +
                                    std::to_string(unpacked) + " of " + std::to_string(uncompressed) + " bytes)");
    return block;
}

PointCloud read_compressed(const fs::path& file, std::string_view bytes, const PcdHeader& header) {
    const std::string_view body = bytes.substr(header.data_offset);
    if (header.data_bytes == 0) return CloudBuilder(0).finish(file);  // no points: "empty scan"
    const std::string block = decompress_block(file, body, header);
    CoordinateColumn columns[3];
    for (std::size_t axis = 0; axis < 3; ++axis) {
        const PcdField& field = header.fields[header.xyz[axis]];
        columns[axis] = {field.offset * header.points, field.size, field.size};
    }
    return gather_points(file, block, columns, header.points, ByteOrder::little);
}

// ---- Writing ----

std::string header_text(std::size_t points, PcdEncoding encoding, PcdPrecision precision) {
    const std::string size = precision == PcdPrecision::f4 ? "4" : "8";
    const std::string n = std::to_string(points);
    const char* data = encoding == PcdEncoding::ascii    ? "ascii"
                       : encoding == PcdEncoding::binary ? "binary"
                                                         : "binary_compressed";
    return "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\nFIELDS x y z\nSIZE " + size + " " + size + " " +
           size + "\nTYPE F F F\nCOUNT 1 1 1\nWIDTH " + n + "\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS " + n +
           "\nDATA " + data + "\n";
}

// Field after field: all x, then all y, then all z (binary_compressed's layout).
template <class T>
std::string by_field(const std::vector<double>& xyz) {
    std::string out;
    out.reserve(xyz.size() * sizeof(T));
    for (std::size_t axis = 0; axis < 3; ++axis)
        for (std::size_t i = axis; i < xyz.size(); i += 3) store<T>(out, narrow_to<T>(xyz[i]), ByteOrder::little);
    return out;
}

void append_compressed(const fs::path& file, std::string& out, const std::string& block) {
    if (block.size() > 0xffffffffu) throw input_error(file, "cloud too large for binary_compressed PCD (over 4 GiB)");
    // Incompressible data grows by one byte in 32, plus a little.
    std::string packed(block.size() + block.size() / 16 + 64, '\0');
    const unsigned packed_size =
        block.empty() ? 0
                      : lzf_compress(block.data(), static_cast<unsigned>(block.size()), packed.data(),
                                     static_cast<unsigned>(std::min<std::size_t>(packed.size(), 0xffffffffu)));
    if (!block.empty() && packed_size == 0) throw input_error(file, "LZF compression failed");
    store<std::uint32_t>(out, packed_size, ByteOrder::little);
    store<std::uint32_t>(out, static_cast<std::uint32_t>(block.size()), ByteOrder::little);
    out.append(packed.data(), packed_size);
}

template <class T>
void append_points(const fs::path& file, std::string& out, const PointCloud& cloud, PcdEncoding encoding) {
    switch (encoding) {
        case PcdEncoding::ascii:
            append_text_points<T>(out, cloud.xyz);
            break;
        case PcdEncoding::binary:
            append_binary_points<T>(out, cloud.xyz, ByteOrder::little);
            break;
        case PcdEncoding::binary_compressed:
            append_compressed(file, out, by_field<T>(cloud.xyz));
            break;
    }
}

}  // namespace

PointCloud read_pcd(const fs::path& file) {
    const std::string bytes = read_file(file);
    const PcdHeader header = parse_pcd_header(file, bytes);
    switch (header.data) {
        case PcdData::ascii:
            return read_ascii(file, bytes, header);
        case PcdData::binary:
            return read_binary(file, bytes, header);
        case PcdData::binary_compressed:
            return read_compressed(file, bytes, header);
    }
    throw input_error(file, "unknown DATA encoding");
}

void write_pcd(const fs::path& file, const PointCloud& cloud, PcdEncoding encoding, PcdPrecision precision) {
    check_cloud_shape(file, cloud);
    std::string out = header_text(cloud.size(), encoding, precision);
    if (precision == PcdPrecision::f4) append_points<float>(file, out, cloud, encoding);
    else append_points<double>(file, out, cloud, encoding);
    write_file_atomically(file, out);
}

}  // namespace bvc3d::recording
