#include "bvc3d/recording/ply.hpp"

#include <algorithm>
#include <array>
#include <cstdint>
#include <optional>
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

enum class Scalar { int8, uint8, int16, uint16, int32, uint32, float32, float64 };

std::optional<Scalar> scalar_named(std::string_view name) {
    if (name == "char" || name == "int8") return Scalar::int8;
    if (name == "uchar" || name == "uint8") return Scalar::uint8;
    if (name == "short" || name == "int16") return Scalar::int16;
    if (name == "ushort" || name == "uint16") return Scalar::uint16;
    if (name == "int" || name == "int32") return Scalar::int32;
    if (name == "uint" || name == "uint32") return Scalar::uint32;
    if (name == "float" || name == "float32") return Scalar::float32;
    if (name == "double" || name == "float64") return Scalar::float64;
    return std::nullopt;
}

std::uint64_t size_of(Scalar type) {
    switch (type) {
        case Scalar::int8:
        case Scalar::uint8:
            return 1;
        case Scalar::int16:
        case Scalar::uint16:
            return 2;
        case Scalar::int32:
        case Scalar::uint32:
        case Scalar::float32:
            return 4;
        case Scalar::float64:
            return 8;
    }
    return 0;
}

bool is_integer(Scalar type) { return type != Scalar::float32 && type != Scalar::float64; }

// A list length as stored: any integer type, possibly signed (and then possibly negative).
std::int64_t load_length(const char* bytes, Scalar type, ByteOrder order) {
    switch (type) {
        case Scalar::int8:
            return load<std::int8_t>(bytes, order);
        case Scalar::uint8:
            return load<std::uint8_t>(bytes, order);
        case Scalar::int16:
            return load<std::int16_t>(bytes, order);
        case Scalar::uint16:
            return load<std::uint16_t>(bytes, order);
        case Scalar::int32:
            return load<std::int32_t>(bytes, order);
        case Scalar::uint32:
            return load<std::uint32_t>(bytes, order);
        default:
            return -1;  // the header allows only integer list lengths
    }
}

struct PlyProperty {
    std::string_view name;
    std::string_view type_name;     // as written, for messages
    Scalar type = Scalar::float32;  // of a scalar, or of a list's items
    bool is_list = false;
    Scalar length_type = Scalar::uint8;
};

struct PlyElement {
    std::string_view name;
    std::uint64_t count = 0;
    std::vector<PlyProperty> properties;
    std::size_t line = 0;

    bool has_lists() const {
        return std::any_of(properties.begin(), properties.end(), [](const PlyProperty& p) { return p.is_list; });
    }
};

struct PlyHeader {
    PlyEncoding encoding = PlyEncoding::ascii;
    std::vector<PlyElement> elements;
    std::size_t vertex = 0;            // index of the vertex element
    std::array<std::size_t, 3> xyz{};  // indices of x, y, z among its properties
    std::size_t data_offset = 0;
    std::size_t end_header_line = 0;
};

// "vertex 12", "face 3": an element instance, for messages.
std::string instance_ref(const PlyElement& element, std::uint64_t i) {
    return std::string(element.name) + " " + std::to_string(i);
}

// "8 vertices", "12 'face' elements".
std::string describe_count(const PlyElement& element, std::uint64_t n) {
    if (element.name == "vertex") return std::to_string(n) + (n == 1 ? " vertex" : " vertices");
    return std::to_string(n) + " " + quote_token(element.name) + " elements";
}

// ---- Header ----

PlyEncoding parse_format(const fs::path& file, const std::string& where, const std::vector<std::string_view>& tokens) {
    if (tokens.size() != 3) throw input_error(file, where, "bad format line: expected 'format <encoding> 1.0'");
    if (tokens[2] != "1.0")
        throw input_error(file, where, "unsupported PLY version " + quote_token(tokens[2]) + ": only 1.0 is read");
    if (tokens[1] == "ascii") return PlyEncoding::ascii;
    if (tokens[1] == "binary_little_endian") return PlyEncoding::binary_little_endian;
    if (tokens[1] == "binary_big_endian") return PlyEncoding::binary_big_endian;
    throw input_error(
        file, where,
        "unknown PLY format " + quote_token(tokens[1]) + ": expected ascii, binary_little_endian or binary_big_endian");
}

PlyElement parse_element(const fs::path& file, const std::string& where, const std::vector<std::string_view>& tokens) {
    if (tokens.size() != 3) throw input_error(file, where, "bad element line: expected 'element <name> <count>'");
    const auto count = parse_uint(tokens[2]);
    if (!count) throw input_error(file, where, "bad element count " + quote_token(tokens[2]));
    return {tokens[1], *count, {}, 0};
}

Scalar scalar_type(const fs::path& file, const std::string& where, std::string_view name) {
    const auto type = scalar_named(name);
    if (!type) throw input_error(file, where, "unknown property type " + quote_token(name));
    return *type;
}

PlyProperty parse_property(const fs::path& file, const std::string& where,
                           const std::vector<std::string_view>& tokens) {
    PlyProperty property;
    if (tokens.size() == 5 && tokens[1] == "list") {
        property.is_list = true;
        property.length_type = scalar_type(file, where, tokens[2]);
        if (!is_integer(property.length_type))
            throw input_error(file, where, "list length type " + quote_token(tokens[2]) + " is not an integer type");
        property.type = scalar_type(file, where, tokens[3]);
        property.type_name = tokens[3];
        property.name = tokens[4];
    } else if (tokens.size() == 3 && tokens[1] != "list") {
        property.type = scalar_type(file, where, tokens[1]);
        property.type_name = tokens[1];
        property.name = tokens[2];
    } else {
        throw input_error(file, where,
                          "bad property line: expected 'property <type> <name>' or "
                          "'property list <length type> <item type> <name>'");
    }
    return property;
}

void add_property(const fs::path& file, const std::string& where, PlyHeader& header, PlyProperty property) {
    if (header.elements.empty()) throw input_error(file, where, "property before any element");
    PlyElement& element = header.elements.back();
    for (const PlyProperty& other : element.properties)
        if (other.name == property.name)
            throw input_error(
                file, where,
                "property " + quote_token(property.name) + " appears twice in element " + quote_token(element.name));
    element.properties.push_back(property);
}

std::size_t find_coordinate(const fs::path& file, const PlyElement& vertex, std::string_view name) {
    const auto found = std::find_if(vertex.properties.begin(), vertex.properties.end(),
                                    [name](const PlyProperty& p) { return p.name == name; });
    const std::string where = line_ref(vertex.line);
    if (found == vertex.properties.end())
        throw input_error(file, where, "vertex element has no '" + std::string(name) + "' property");
    if (found->is_list || (found->type != Scalar::float32 && found->type != Scalar::float64))
        throw input_error(file, where,
                          "vertex property '" + std::string(name) + "' is of type " +
                              (found->is_list ? "list" : quote_token(found->type_name)) +
                              ": x, y and z must be float or double");
    return static_cast<std::size_t>(found - vertex.properties.begin());
}

// The vertex element and its x, y, z, once the header is complete.
void find_vertices(const fs::path& file, PlyHeader& header) {
    std::optional<std::size_t> vertex;
    for (std::size_t e = 0; e < header.elements.size(); ++e) {
        if (header.elements[e].name != "vertex") continue;
        if (vertex) throw input_error(file, line_ref(header.elements[e].line), "second vertex element");
        vertex = e;
    }
    if (!vertex) throw input_error(file, "header has no vertex element");
    header.vertex = *vertex;
    for (std::size_t axis = 0; axis < 3; ++axis)
        header.xyz[axis] = find_coordinate(file, header.elements[*vertex], std::string_view("xyz").substr(axis, 1));
}

PlyHeader parse_ply_header(const fs::path& file, std::string_view bytes) {
    LineCursor lines(bytes);
    std::string_view line;
    if (!lines.next(line) || trim(line) != "ply")
        throw input_error(file, line_ref(1),
                          "not a PLY file: the first line is " + quote_token(line) + ", expected 'ply'");
    PlyHeader header;
    std::size_t format_line = 0;
    std::vector<std::string_view> tokens;
    while (lines.next(line)) {
        split(line, Separators::whitespace, tokens);
        if (tokens.empty() || tokens[0] == "comment" || tokens[0] == "obj_info") continue;
        const std::string where = line_ref(lines.line_number());
        if (tokens[0] == "format") {
            if (format_line != 0)
                throw input_error(file, where, "second format line (first on " + line_ref(format_line) + ")");
            header.encoding = parse_format(file, where, tokens);
            format_line = lines.line_number();
        } else if (tokens[0] == "element") {
            header.elements.push_back(parse_element(file, where, tokens));
            header.elements.back().line = lines.line_number();
        } else if (tokens[0] == "property") {
            add_property(file, where, header, parse_property(file, where, tokens));
        } else if (tokens[0] == "end_header") {
            if (format_line == 0) throw input_error(file, "header has no format line");
            find_vertices(file, header);
            header.data_offset = lines.offset();
            header.end_header_line = lines.line_number();
            return header;
        } else {
            // A number where a keyword should be: data, so end_header was left out.
            const bool looks_like_data = parse_double(tokens[0]).has_value();
            throw input_error(
                file, where,
                "unknown header line " + quote_token(tokens[0]) + (looks_like_data ? " (is end_header missing?)" : ""));
        }
    }
    throw input_error(file, "header has no end_header line");
}

InputError truncated(const fs::path& file, const PlyElement& element, std::uint64_t instance) {
    return input_error(file, "truncated: the header claims " + describe_count(element, element.count) +
                                 " but the data ends at " + instance_ref(element, instance));
}

// ---- ascii data ----

bool next_content_line(LineCursor& lines, std::string_view& line) {
    while (lines.next(line))
        if (!trim(line).empty()) return true;
    return false;
}

// The values of one instance; a list's place holds its length. Checks every token is a number.
void parse_instance(const fs::path& file, const std::string& where, const std::vector<std::string_view>& tokens,
                    const PlyElement& element, std::uint64_t instance, std::vector<double>& values) {
    values.clear();
    std::size_t next = 0;
    const auto too_few = [&] {
        return input_error(file, where, "too few values for " + instance_ref(element, instance));
    };
    const auto number = [&](std::string_view token) {
        const auto value = parse_double(token);
        if (!value)
            throw input_error(file, where,
                              "bad number " + quote_token(token) + " in " + instance_ref(element, instance));
        return *value;
    };
    for (const PlyProperty& property : element.properties) {
        if (next >= tokens.size()) throw too_few();
        if (!property.is_list) {
            values.push_back(number(tokens[next++]));
            continue;
        }
        const auto length = parse_uint(tokens[next]);
        if (!length)
            throw input_error(
                file, where, "bad list length " + quote_token(tokens[next]) + " in " + instance_ref(element, instance));
        values.push_back(static_cast<double>(*length));
        ++next;
        if (*length > tokens.size() - next) throw too_few();
        for (std::uint64_t k = 0; k < *length; ++k) number(tokens[next++]);
    }
    if (next != tokens.size())
        throw input_error(file, where,
                          "too many values for " + instance_ref(element, instance) + ": " +
                              std::to_string(tokens.size()) + " given, its properties take " + std::to_string(next));
}

PointCloud read_ascii(const fs::path& file, std::string_view bytes, const PlyHeader& header) {
    const PlyElement& vertex = header.elements[header.vertex];
    // A vertex line holds at least one character per property: no reservation beyond the file.
    const std::uint64_t most_vertices = (bytes.size() - header.data_offset) / vertex.properties.size() + 1;
    CloudBuilder cloud(std::min(vertex.count, most_vertices));
    LineCursor lines(bytes, header.data_offset, header.end_header_line + 1);
    std::string_view line;
    std::vector<std::string_view> tokens;
    std::vector<double> values;
    for (std::size_t e = 0; e < header.elements.size(); ++e) {
        const PlyElement& element = header.elements[e];
        for (std::uint64_t i = 0; i < element.count; ++i) {
            if (!next_content_line(lines, line)) throw truncated(file, element, i);
            split(line, Separators::whitespace, tokens);
            parse_instance(file, line_ref(lines.line_number()), tokens, element, i, values);
            if (e != header.vertex) continue;
            const auto coordinate = [&](std::size_t axis) {
                const std::size_t p = header.xyz[axis];
                return as_stored(values[p], size_of(element.properties[p].type));
            };
            cloud.add(coordinate(0), coordinate(1), coordinate(2));
        }
    }
    if (next_content_line(lines, line))
        throw input_error(file, line_ref(lines.line_number()), "trailing data after the last element");
    return std::move(cloud).finish(file);
}

// ---- binary data ----

// An element without lists: fixed-size records, bounds checked once for all of them.
std::size_t read_fixed_element(const fs::path& file, std::string_view bytes, std::size_t pos, const PlyHeader& header,
                               std::size_t e, ByteOrder order, std::optional<PointCloud>& cloud) {
    const PlyElement& element = header.elements[e];
    std::vector<std::uint64_t> offsets;
    std::uint64_t record = 0;
    for (const PlyProperty& property : element.properties) {
        offsets.push_back(record);
        record += size_of(property.type);
    }
    const auto need = checked_mul(element.count, record);
    const std::uint64_t remaining = bytes.size() - pos;
    if (!need || *need > remaining)
        throw input_error(file, "truncated: the header claims " + describe_count(element, element.count) + " of " +
                                    std::to_string(record) + " bytes but only " + std::to_string(remaining) +
                                    " bytes remain");
    if (e == header.vertex) {
        CoordinateColumn columns[3];
        for (std::size_t axis = 0; axis < 3; ++axis) {
            const std::size_t p = header.xyz[axis];
            columns[axis] = {pos + offsets[p], record, size_of(element.properties[p].type)};
        }
        cloud = gather_points(file, bytes, columns, element.count, order);
    }
    return pos + static_cast<std::size_t>(*need);
}

// An element with list properties: walked instance by instance, every length checked.
std::size_t read_variable_element(const fs::path& file, std::string_view bytes, std::size_t pos,
                                  const PlyHeader& header, std::size_t e, ByteOrder order,
                                  std::optional<PointCloud>& cloud) {
    const PlyElement& element = header.elements[e];
    const bool is_vertex = e == header.vertex;
    CloudBuilder vertices(is_vertex ? std::min<std::uint64_t>(element.count, bytes.size() - pos) : 0);
    std::array<double, 3> xyz{};
    for (std::uint64_t i = 0; i < element.count; ++i) {
        for (std::size_t p = 0; p < element.properties.size(); ++p) {
            const PlyProperty& property = element.properties[p];
            std::uint64_t bytes_left = bytes.size() - pos;
            if (!property.is_list) {
                if (size_of(property.type) > bytes_left) throw truncated(file, element, i);
                for (std::size_t axis = 0; axis < 3; ++axis)
                    if (is_vertex && header.xyz[axis] == p)
                        xyz[axis] = load_coordinate(bytes.data() + pos, size_of(property.type), order);
                pos += size_of(property.type);
                continue;
            }
            if (size_of(property.length_type) > bytes_left) throw truncated(file, element, i);
            const std::int64_t length = load_length(bytes.data() + pos, property.length_type, order);
            if (length < 0)
                throw input_error(file, instance_ref(element, i), "negative list length " + std::to_string(length));
            pos += size_of(property.length_type);
            bytes_left = bytes.size() - pos;
            const auto items = checked_mul(static_cast<std::uint64_t>(length), size_of(property.type));
            if (!items || *items > bytes_left) throw truncated(file, element, i);
            pos += static_cast<std::size_t>(*items);
        }
        if (is_vertex) vertices.add(xyz[0], xyz[1], xyz[2]);
    }
    if (is_vertex) cloud = std::move(vertices).finish(file);
    return pos;
}

PointCloud read_binary(const fs::path& file, std::string_view bytes, const PlyHeader& header) {
    const ByteOrder order = header.encoding == PlyEncoding::binary_big_endian ? ByteOrder::big : ByteOrder::little;
    std::optional<PointCloud> cloud;
    std::size_t pos = header.data_offset;
    for (std::size_t e = 0; e < header.elements.size(); ++e)
        pos = header.elements[e].has_lists() ? read_variable_element(file, bytes, pos, header, e, order, cloud)
                                             : read_fixed_element(file, bytes, pos, header, e, order, cloud);
    if (pos != bytes.size())
        throw input_error(file,
                          "trailing data: " + std::to_string(bytes.size() - pos) + " bytes after the last element");
    return std::move(*cloud);
}

// ---- Writing ----

std::string header_text(std::size_t vertices, PlyEncoding encoding, PlyPrecision precision) {
    const char* format = encoding == PlyEncoding::ascii                  ? "ascii"
                         : encoding == PlyEncoding::binary_little_endian ? "binary_little_endian"
                                                                         : "binary_big_endian";
    const std::string type = precision == PlyPrecision::float32 ? "float" : "double";
    return std::string("ply\nformat ") + format + " 1.0\ncomment bvc3d point cloud\nelement vertex " +
           std::to_string(vertices) + "\nproperty " + type + " x\nproperty " + type + " y\nproperty " + type +
           " z\nend_header\n";
}

}  // namespace

PointCloud read_ply(const fs::path& file) {
    const std::string bytes = read_file(file);
    const PlyHeader header = parse_ply_header(file, bytes);
    return header.encoding == PlyEncoding::ascii ? read_ascii(file, bytes, header) : read_binary(file, bytes, header);
}

void write_ply(const fs::path& file, const PointCloud& cloud, PlyEncoding encoding, PlyPrecision precision) {
    check_cloud_shape(file, cloud);
    std::string out = header_text(cloud.size(), encoding, precision);
    const ByteOrder order = encoding == PlyEncoding::binary_big_endian ? ByteOrder::big : ByteOrder::little;
    const bool as_float = precision == PlyPrecision::float32;
    if (encoding == PlyEncoding::ascii && as_float) append_text_points<float>(out, cloud.xyz);
    else if (encoding == PlyEncoding::ascii) append_text_points<double>(out, cloud.xyz);
    else if (as_float) append_binary_points<float>(out, cloud.xyz, order);
    else append_binary_points<double>(out, cloud.xyz, order);
    write_file_atomically(file, out);
}

}  // namespace bvc3d::recording
