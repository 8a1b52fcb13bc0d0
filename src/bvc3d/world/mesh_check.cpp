#include "bvc3d/world/mesh_check.hpp"

#include <algorithm>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "bvc3d/core/error.hpp"

namespace bvc3d {

namespace {

[[noreturn]] void bad(const std::string& why) { throw InputError(why); }

std::string lower(std::string s) {
    for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return s;
}

// Whitespace-separated tokens of one line.
std::vector<std::string_view> tokens_of(std::string_view line) {
    std::vector<std::string_view> out;
    std::size_t i = 0;
    while (i < line.size()) {
        while (i < line.size() && std::isspace(static_cast<unsigned char>(line[i]))) ++i;
        const std::size_t start = i;
        while (i < line.size() && !std::isspace(static_cast<unsigned char>(line[i]))) ++i;
        if (i > start) out.push_back(line.substr(start, i - start));
    }
    return out;
}

bool parse_real(std::string_view t, double& v) {
    if (!t.empty() && t.front() == '+') t.remove_prefix(1);
    const auto r = std::from_chars(t.data(), t.data() + t.size(), v);
    return !t.empty() && r.ec == std::errc() && r.ptr == t.data() + t.size();
}

bool parse_integer(std::string_view t, long long& v) {
    if (!t.empty() && t.front() == '+') t.remove_prefix(1);
    const auto r = std::from_chars(t.data(), t.data() + t.size(), v);
    return !t.empty() && r.ec == std::errc() && r.ptr == t.data() + t.size();
}

std::string quoted(std::string_view t) {
    std::string s(t.substr(0, 40));
    for (char& c : s)
        if (static_cast<unsigned char>(c) < 0x20 || static_cast<unsigned char>(c) >= 0x7f) c = '?';
    return "'" + s + (t.size() > 40 ? "...'" : "'");
}

// A value for a message: whole numbers without decimals.
std::string number_text(double v) {
    if (v == std::floor(v) && std::abs(v) < 1e18) return std::to_string(static_cast<long long>(v));
    return std::to_string(v);
}

// ---- PLY ----

enum class PlyType { i8, u8, i16, u16, i32, u32, f32, f64 };

bool ply_type(std::string_view name, PlyType& t) {
    static const std::pair<const char*, PlyType> names[] = {
        {"char", PlyType::i8},   {"int8", PlyType::i8},     {"uchar", PlyType::u8},   {"uint8", PlyType::u8},
        {"short", PlyType::i16}, {"int16", PlyType::i16},   {"ushort", PlyType::u16}, {"uint16", PlyType::u16},
        {"int", PlyType::i32},   {"int32", PlyType::i32},   {"uint", PlyType::u32},   {"uint32", PlyType::u32},
        {"float", PlyType::f32}, {"float32", PlyType::f32}, {"double", PlyType::f64}, {"float64", PlyType::f64}};
    for (const auto& [n, type] : names)
        if (name == n) {
            t = type;
            return true;
        }
    return false;
}

std::size_t ply_size(PlyType t) {
    switch (t) {
        case PlyType::i8:
        case PlyType::u8:
            return 1;
        case PlyType::i16:
        case PlyType::u16:
            return 2;
        case PlyType::i32:
        case PlyType::u32:
        case PlyType::f32:
            return 4;
        case PlyType::f64:
            return 8;
    }
    return 1;
}

bool ply_integer(PlyType t) { return t != PlyType::f32 && t != PlyType::f64; }

struct PlyProperty {
    std::string name;
    bool list = false;
    PlyType count_type = PlyType::u8, type = PlyType::f32;
};

struct PlyElement {
    std::string name;
    std::uint64_t count = 0;
    std::vector<PlyProperty> properties;
};

bool is_face_index(const PlyElement& e, const PlyProperty& p) {
    return e.name == "face" && p.list && (p.name == "vertex_indices" || p.name == "vertex_index");
}

// A binary value as a double (integers exactly up to 2^53, far beyond any count here).
double load_binary(const char* p, PlyType t, bool big) {
    char raw[8];
    const std::size_t n = ply_size(t);
    std::memcpy(raw, p, n);
    if (big == (std::endian::native == std::endian::little)) std::reverse(raw, raw + n);
    switch (t) {
        case PlyType::i8:
            return static_cast<double>(static_cast<std::int8_t>(raw[0]));
        case PlyType::u8:
            return static_cast<double>(static_cast<std::uint8_t>(raw[0]));
        case PlyType::i16: {
            std::int16_t v;
            std::memcpy(&v, raw, 2);
            return v;
        }
        case PlyType::u16: {
            std::uint16_t v;
            std::memcpy(&v, raw, 2);
            return v;
        }
        case PlyType::i32: {
            std::int32_t v;
            std::memcpy(&v, raw, 4);
            return v;
        }
        case PlyType::u32: {
            std::uint32_t v;
            std::memcpy(&v, raw, 4);
            return v;
        }
        case PlyType::f32: {
            float v;
            std::memcpy(&v, raw, 4);
            return v;
        }
        case PlyType::f64: {
            double v;
            std::memcpy(&v, raw, 8);
            return v;
        }
    }
    return 0;
}

// Reads PLY data values one by one (ascii tokens or binary), saying where it ran out.
class PlyData {
public:
    PlyData(std::string_view data, int format) : data_(data), format_(format) {}
    bool next(PlyType t, double& v) {
        if (format_ == 0) {
            while (pos_ < data_.size() && std::isspace(static_cast<unsigned char>(data_[pos_]))) ++pos_;
            if (pos_ >= data_.size()) return false;
            const std::size_t start = pos_;
            while (pos_ < data_.size() && !std::isspace(static_cast<unsigned char>(data_[pos_]))) ++pos_;
            const auto token = data_.substr(start, pos_ - start);
            if (!parse_real(token, v)) bad("the value " + quoted(token) + " is not a number");
            return true;
        }
        const std::size_t n = ply_size(t);
        if (data_.size() - pos_ < n) return false;
        v = load_binary(data_.data() + pos_, t, format_ == 2);
        pos_ += n;
        return true;
    }
    bool rest_is_empty() const {
        if (format_ != 0) return pos_ == data_.size();
        for (std::size_t i = pos_; i < data_.size(); ++i)
            if (!std::isspace(static_cast<unsigned char>(data_[i]))) return false;
        return true;
    }

private:
    std::string_view data_;
    std::size_t pos_ = 0;
    int format_;  // 0 ascii, 1 binary little-endian, 2 binary big-endian
};

std::string declared(const std::vector<PlyElement>& elements) {
    std::string s;
    for (const auto& e : elements) s += (s.empty() ? "" : ", ") + std::to_string(e.count) + " " + e.name + "(s)";
    return s;
}

void check_ply(std::string_view bytes) {
    const auto end_header = bytes.find("end_header");
    if (bytes.substr(0, 3) != "ply" || end_header == std::string_view::npos)
        bad("is not a PLY file (no 'ply' ... 'end_header' header)");
    std::size_t data_at = bytes.find('\n', end_header);
    data_at = data_at == std::string_view::npos ? bytes.size() : data_at + 1;
    int format = -1;
    std::vector<PlyElement> elements;
    std::size_t line_no = 0;
    for (std::size_t at = 0; at < end_header;) {
        std::size_t nl = bytes.find('\n', at);
        if (nl == std::string_view::npos || nl > end_header) nl = end_header;
        const auto words = tokens_of(bytes.substr(at, nl - at));
        at = nl + 1;
        ++line_no;
        const std::string where = "header line " + std::to_string(line_no) + ": ";
        if (words.empty() || words[0] == "comment" || words[0] == "obj_info" || (line_no == 1 && words[0] == "ply"))
            continue;
        if (words[0] == "format") {
            if (words.size() != 3) bad(where + "expected 'format <encoding> 1.0'");
            if (words[1] == "ascii") format = 0;
            else if (words[1] == "binary_little_endian") format = 1;
            else if (words[1] == "binary_big_endian") format = 2;
            else bad(where + "unknown encoding " + quoted(words[1]));
        } else if (words[0] == "element") {
            long long count = 0;
            if (words.size() != 3 || !parse_integer(words[2], count) || count < 0)
                bad(where + "expected 'element <name> <count>' with a count >= 0");
            elements.push_back({std::string(words[1]), static_cast<std::uint64_t>(count), {}});
        } else if (words[0] == "property") {
            if (elements.empty()) bad(where + "a property before any element");
            PlyProperty p;
            if (words.size() == 5 && words[1] == "list") {
                p.list = true;
                if (!ply_type(words[2], p.count_type) || !ply_integer(p.count_type) || !ply_type(words[3], p.type))
                    bad(where + "unknown or unusable types in a list property");
                p.name = words[4];
            } else if (words.size() == 3) {
                if (!ply_type(words[1], p.type)) bad(where + "unknown property type " + quoted(words[1]));
                p.name = words[2];
            } else {
                bad(where + "expected 'property <type> <name>' or 'property list <count type> <type> <name>'");
            }
            elements.back().properties.push_back(p);
        } else {
            bad(where + "unknown header keyword " + quoted(words[0]));
        }
    }
    if (format < 0) bad("the header has no 'format' line");
    std::uint64_t vertices = 0;
    for (const auto& e : elements)
        if (e.name == "vertex") vertices = e.count;
    // Before walking: binary data can be checked against its least possible size at once (and a
    // header claiming billions of elements is refused without walking them).
    if (format != 0) {
        long double least = 0;
        for (const auto& e : elements) {
            std::size_t record = 0;
            for (const auto& p : e.properties) record += p.list ? ply_size(p.count_type) : ply_size(p.type);
            least += static_cast<long double>(record) * e.count;
        }
        if (least > static_cast<long double>(bytes.size() - data_at))
            bad("is truncated: the header declares " + declared(elements) + ", at least " +
                std::to_string(static_cast<unsigned long long>(least)) + " bytes of data, but the file holds " +
                std::to_string(bytes.size() - data_at));
    } else {
        // Every ascii value takes at least two bytes (a digit and a separator).
        long double least = 0;
        for (const auto& e : elements) least += static_cast<long double>(e.properties.size()) * e.count;
        if (least * 2 > static_cast<long double>(bytes.size() - data_at) + 1)
            bad("is truncated: the header declares " + declared(elements) + ", more values than the data can hold");
    }
    PlyData data(bytes.substr(data_at), format);
    for (const auto& e : elements)
        for (std::uint64_t i = 0; i < e.count && !e.properties.empty(); ++i)  // no properties: no data to walk
            for (const auto& p : e.properties) {
                const auto short_of = [&] {
                    bad("is truncated: the header declares " + declared(elements) + ", but the data ends in " + e.name +
                        " " + std::to_string(i) + " (property '" + p.name + "')");
                };
                double v = 0;
                std::uint64_t n = 1;
                if (p.list) {
                    if (!data.next(p.count_type, v)) short_of();
                    if (!(v >= 0) || v != std::floor(v) || v > 1e6)
                        bad(e.name + " " + std::to_string(i) + ": the list '" + p.name + "' has an impossible length");
                    n = static_cast<std::uint64_t>(v);
                }
                for (std::uint64_t k = 0; k < n; ++k) {
                    if (!data.next(p.type, v)) short_of();
                    if (is_face_index(e, p) && !(v >= 0 && v < static_cast<double>(vertices) && v == std::floor(v)))
                        bad("face " + std::to_string(i) + " refers to vertex " + number_text(v) + ", but there are " +
                            std::to_string(vertices) + " vertices");
                }
            }
    if (!data.rest_is_empty()) bad("has data after the " + declared(elements) + " its header declares");
}

// ---- OBJ ----

void check_obj(std::string_view bytes) {
    std::uint64_t vertices = 0, texcoords = 0, normals = 0;
    std::size_t line_no = 0;
    struct FaceRef {
        std::size_t line;
        long long index;
        std::uint64_t defined;  // vertices defined before the face
        char kind;              // 'v', 't', 'n'
    };
    std::vector<FaceRef> deferred;  // positive references: checked against the whole file's counts
    for (std::size_t at = 0; at < bytes.size();) {
        std::size_t nl = bytes.find('\n', at);
        if (nl == std::string_view::npos) nl = bytes.size();
        std::string_view line = bytes.substr(at, nl - at);
        at = nl + 1;
        ++line_no;
        if (const auto hash = line.find('#'); hash != std::string_view::npos) line = line.substr(0, hash);
        const auto w = tokens_of(line);
        if (w.empty()) continue;
        const std::string where = "line " + std::to_string(line_no) + ": ";
        const auto numbers = [&](std::size_t least, const char* what) {
            if (w.size() < least + 1)
                bad(where + what + " needs " + std::to_string(least) + " numbers, got " + std::to_string(w.size() - 1));
            for (std::size_t i = 1; i < w.size(); ++i) {
                double v = 0;
                if (!parse_real(w[i], v)) bad(where + quoted(w[i]) + " is not a number");
                if (!std::isfinite(v)) bad(where + "a value is not finite");
            }
        };
        if (w[0] == "v") {
            numbers(3, "a vertex");
            ++vertices;
        } else if (w[0] == "vt") {
            numbers(1, "a texture coordinate");
            ++texcoords;
        } else if (w[0] == "vn") {
            numbers(3, "a normal");
            ++normals;
        } else if (w[0] == "f") {
            if (w.size() < 4) bad(where + "a face needs at least 3 vertices, got " + std::to_string(w.size() - 1));
            for (std::size_t i = 1; i < w.size(); ++i) {
                // v, v/t, v//n or v/t/n
                std::string_view ref = w[i];
                char kinds[3] = {'v', 't', 'n'};
                for (int part = 0; part < 3; ++part) {
                    const auto slash = ref.find('/');
                    const std::string_view item = ref.substr(0, slash);
                    if (!item.empty() || part == 0) {
                        long long index = 0;
                        if (!parse_integer(item, index) || index == 0)
                            bad(where + "the face corner " + quoted(w[i]) + " is not a valid vertex reference");
                        const std::uint64_t defined = kinds[part] == 'v'   ? vertices
                                                      : kinds[part] == 't' ? texcoords
                                                                           : normals;
                        if (index < 0 && static_cast<std::uint64_t>(-index) > defined)
                            bad(where + "the face corner " + quoted(w[i]) + " refers back past the first " +
                                (kinds[part] == 'v'   ? "vertex"
                                 : kinds[part] == 't' ? "texture coordinate"
                                                      : "normal"));
                        if (index > 0) deferred.push_back({line_no, index, defined, kinds[part]});
                    }
                    if (slash == std::string_view::npos) break;
                    ref = ref.substr(slash + 1);
                    if (part == 2) bad(where + "the face corner " + quoted(w[i]) + " has too many parts");
                }
            }
        }
        // Other statements (o, g, s, usemtl, mtllib, l, p, ...) carry no geometry to check.
    }
    for (const auto& r : deferred) {
        const std::uint64_t total = r.kind == 'v' ? vertices : r.kind == 't' ? texcoords : normals;
        if (static_cast<std::uint64_t>(r.index) > total)
            bad("line " + std::to_string(r.line) + ": a face refers to " +
                (r.kind == 'v'   ? "vertex "
                 : r.kind == 't' ? "texture coordinate "
                                 : "normal ") +
                std::to_string(r.index) + ", but the file has " + std::to_string(total));
    }
}

// ---- STL ----

void check_ascii_stl(std::string_view bytes) {
    std::vector<std::string_view> t;
    std::size_t line_no = 0;
    std::vector<std::size_t> lines;
    for (std::size_t at = 0; at < bytes.size();) {
        std::size_t nl = bytes.find('\n', at);
        if (nl == std::string_view::npos) nl = bytes.size();
        ++line_no;
        const auto words = tokens_of(bytes.substr(at, nl - at));
        // The name after solid/endsolid is free text.
        const std::size_t keep = !words.empty() && (words[0] == "solid" || words[0] == "endsolid") ? 1 : words.size();
        for (std::size_t i = 0; i < keep; ++i) {
            t.push_back(words[i]);
            lines.push_back(line_no);
        }
        at = nl + 1;
    }
    std::size_t i = 0;
    const auto where = [&] { return "line " + std::to_string(i < lines.size() ? lines[i] : line_no) + ": "; };
    const auto expect = [&](std::string_view word) {
        if (i >= t.size()) bad("is truncated: the ASCII STL ends before '" + std::string(word) + "' (no 'endsolid')");
        if (lower(std::string(t[i])) != word)
            bad(where() + "expected '" + std::string(word) + "', got " + quoted(t[i]));
        ++i;
    };
    const auto number = [&] {
        double v = 0;
        if (i >= t.size()) bad("is truncated: the ASCII STL ends inside a facet (no 'endsolid')");
        if (!parse_real(t[i], v) || !std::isfinite(v)) bad(where() + quoted(t[i]) + " is not a finite number");
        ++i;
    };
    std::size_t facets = 0;
    while (i < t.size()) {
        expect("solid");
        for (;;) {
            if (i >= t.size()) bad("is truncated: the ASCII STL ends without 'endsolid'");
            const std::string word = lower(std::string(t[i]));
            if (word == "endsolid") {
                ++i;
                break;
            }
            expect("facet");
            expect("normal");
            number(), number(), number();
            expect("outer");
            expect("loop");
            for (int k = 0; k < 3; ++k) {
                expect("vertex");
                number(), number(), number();
            }
            expect("endloop");
            expect("endfacet");
            ++facets;
        }
    }
    if (facets == 0) bad("holds no facets");
}

// The triangle count of a binary STL header (little-endian uint32 at byte 80).
std::uint32_t stl_count(std::string_view bytes) {
    const auto* b = reinterpret_cast<const unsigned char*>(bytes.data() + 80);
    return static_cast<std::uint32_t>(b[0]) | static_cast<std::uint32_t>(b[1]) << 8 |
           static_cast<std::uint32_t>(b[2]) << 16 | static_cast<std::uint32_t>(b[3]) << 24;
}

void check_stl(std::string_view bytes) {
    if (bytes.size() >= 84) {
        if (bytes.size() == 84 + 50ull * stl_count(bytes)) return;  // a consistent binary STL
    }
    std::size_t first = 0;
    while (first < bytes.size() && std::isspace(static_cast<unsigned char>(bytes[first]))) ++first;
    if (lower(std::string(bytes.substr(first, 5))) == "solid" && bytes.find("facet") != std::string_view::npos) {
        check_ascii_stl(bytes.substr(first));
        return;
    }
    if (bytes.size() < 84) bad("is too short for a binary STL (84-byte header) and is not an ASCII STL");
    const std::uint32_t n = stl_count(bytes);
    bad("is not a consistent binary STL: its header declares " + std::to_string(n) + " triangles (" +
        std::to_string(84 + 50ull * n) + " bytes), but the file has " + std::to_string(bytes.size()) + " bytes");
}

}  // namespace

void check_mesh_file(const std::filesystem::path& path, std::string_view bytes) {
    const std::string ext = lower(path.extension().string());
    if (ext == ".ply") check_ply(bytes);
    else if (ext == ".obj") check_obj(bytes);
    else if (ext == ".stl") check_stl(bytes);
}

}  // namespace bvc3d
