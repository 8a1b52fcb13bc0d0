// A ROS 1 bag is "#ROSBAG V2.0\n" and then records: a uint32 header length, the header (fields, each a
// uint32 length and "name=value"), a uint32 data length and the data. A chunk record's data is more
// records (connections and messages), compressed or not; the index records after a chunk give, per
// message, its offset in the chunk's uncompressed data.
#include "bvc3d/recording/ros1_framing.hpp"

#include <bzlib.h>
#include <roslz4/lz4s.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "bvc3d/core/error.hpp"
#include "bvc3d/recording/bag.hpp"
#include "bvc3d/recording/parsing.hpp"

namespace bvc3d::recording::ros1 {

namespace {

constexpr char op_message = 0x02, op_bag_header = 0x03, op_index = 0x04, op_chunk = 0x05, op_chunk_info = 0x06,
               op_connection = 0x07;
// A compressed chunk's claimed size is bounded before it is allocated: 1 GiB, and 1024 × its compressed
// bytes + 1 MiB (lz4 and bzip2 do not expand further on real data).
constexpr std::uint64_t max_chunk_bytes = std::uint64_t{1} << 30;

// A little-endian number at byte `at` of `bytes` (the readers' shared binary load).
template <class T>
T little_endian(const std::string& bytes, std::size_t at) {
    return detail::load<T>(bytes.data() + at, detail::ByteOrder::little);
}

// Where a fault is: "'<file>', byte N: why" or "'<file>', chunk at byte C, byte N of its uncompressed data: why".
class Faults {
public:
    Faults(std::string before, std::string after) : before_(std::move(before)), after_(std::move(after)) {}
    [[noreturn]] void at(std::uint64_t byte, const std::string& why) const {
        throw InputError(before_ + "byte " + std::to_string(byte) + after_ + ": " + why +
                         " (not a readable ROS 1 bag: truncated or corrupt)");
    }

private:
    std::string before_, after_;
};

// The bytes walked: the file, read where asked, or a chunk's uncompressed data, held whole.
class FileBytes {
public:
    explicit FileBytes(const std::filesystem::path& file) : in_(file, std::ios::binary) {
        in_.seekg(0, std::ios::end);
        size_ = static_cast<std::uint64_t>(in_.tellg());
    }
    std::uint64_t size() const { return size_; }
    std::string read(std::uint64_t at, std::uint64_t n) {  // [at, at + n) lies in the file: the caller checked
        std::string out(n, '\0');
        in_.clear();
        in_.seekg(static_cast<std::streamoff>(at));
        in_.read(out.data(), static_cast<std::streamsize>(n));
        return out;
    }

private:
    std::ifstream in_;
    std::uint64_t size_ = 0;
};

struct MemoryBytes {
    const std::string& bytes;
    std::uint64_t size() const { return bytes.size(); }
    std::string read(std::uint64_t at, std::uint64_t n) const { return bytes.substr(at, n); }
};

// Fields: each a uint32 length and "name=value", filling `bytes` exactly.
std::map<std::string, std::string> fields_of(const std::string& bytes, std::uint64_t at, const Faults& fault) {
    std::map<std::string, std::string> fields;
    for (std::size_t f = 0; f < bytes.size();) {
        if (bytes.size() - f < 4) fault.at(at + f, "a header field's length is cut off");
        const auto n = little_endian<std::uint32_t>(bytes, f);
        if (n > bytes.size() - f - 4) fault.at(at + f, "a header field claims " + std::to_string(n) + " bytes");
        const std::string field = bytes.substr(f + 4, n);
        const auto eq = field.find('=');
        fields[field.substr(0, eq)] = eq == std::string::npos ? "" : field.substr(eq + 1);
        f += 4 + n;
    }
    return fields;
}

// One record: where it starts, its header's fields, where its data lies and how long it is.
struct Record {
    std::uint64_t start = 0;
    std::map<std::string, std::string> fields;
    std::uint64_t data_at = 0;
    std::uint32_t data_length = 0;

    std::string text(const std::string& name) const {
        const auto f = fields.find(name);
        return f == fields.end() ? "" : f->second;
    }
    char op() const {
        const std::string v = text("op");
        return v.size() == 1 ? v[0] : '\0';
    }
    // A little-endian number field, or nothing when it is absent or of another width (the library
    // refuses those itself).
    template <class T>
    std::optional<T> number(const std::string& name) const {
        const std::string v = text(name);
        if (v.size() != sizeof(T)) return std::nullopt;
        return little_endian<T>(v, 0);
    }
};

template <class Bytes>
Record record_at(Bytes& bytes, std::uint64_t at, const Faults& fault) {
    const std::uint64_t size = bytes.size();
    const auto length_at = [&](std::uint64_t pos) {
        if (pos > size || size - pos < 4) fault.at(pos, "a record is cut off");
        return little_endian<std::uint32_t>(bytes.read(pos, 4), 0);
    };
    Record r;
    r.start = at;
    const std::uint32_t header_length = length_at(at);
    if (header_length > size - at - 4)
        fault.at(at, "a record header claims " + std::to_string(header_length) + " bytes");
    r.fields = fields_of(bytes.read(at + 4, header_length), at + 4, fault);
    const std::uint64_t data_length_at = at + 4 + header_length;
    r.data_length = length_at(data_length_at);
    r.data_at = data_length_at + 4;
    if (r.data_length > size - r.data_at)
        fault.at(data_length_at, "a record's data claims " + std::to_string(r.data_length) + " bytes");
    if (r.op() == op_connection) fields_of(bytes.read(r.data_at, r.data_length), r.data_at, fault);
    return r;
}

// Every record from `from` to the end, in order.
template <class Bytes, class Visit>
void walk(Bytes& bytes, std::uint64_t from, const Faults& fault, Visit&& visit) {
    for (std::uint64_t at = from; at < bytes.size();) {
        const Record r = record_at(bytes, at, fault);
        visit(r);
        at = r.data_at + r.data_length;
    }
}

// A chunk's data as the library will hold it: uncompressed, of the size its header claims.
std::string uncompressed(FileBytes& file, const Record& chunk, const Faults& fault) {
    const std::string compression = chunk.text("compression");
    const auto size = chunk.number<std::uint32_t>("size");
    if (!size) fault.at(chunk.start, "a chunk has no 4-byte 'size' field");
    std::string raw = file.read(chunk.data_at, chunk.data_length);
    if (compression == "none") {
        if (*size != chunk.data_length)
            fault.at(chunk.start, "an uncompressed chunk claims " + std::to_string(*size) + " bytes and holds " +
                                      std::to_string(chunk.data_length));
        return raw;
    }
    if (*size > max_chunk_bytes || *size > 1024 * std::uint64_t{chunk.data_length} + (1u << 20))
        fault.at(chunk.start, "a chunk claims " + std::to_string(*size) + " bytes uncompressed from " +
                                  std::to_string(chunk.data_length));
    if (compression != "lz4" && compression != "bz2")
        fault.at(chunk.start, "a chunk's compression '" + compression + "' is none of none, lz4, bz2");
    std::string out(*size, '\0');
    unsigned int out_length = *size;
    const bool decoded =
        compression == "lz4"
            ? roslz4_buffToBuffDecompress(raw.data(), chunk.data_length, out.data(), &out_length) == ROSLZ4_OK
            : BZ2_bzBuffToBuffDecompress(out.data(), &out_length, raw.data(), chunk.data_length, 0, 0) == BZ_OK;
    if (!decoded) fault.at(chunk.data_at, "a chunk's " + compression + " data cannot be decompressed");
    if (out_length != *size)
        fault.at(chunk.data_at, "a chunk decompresses to " + std::to_string(out_length) + " bytes, not the " +
                                    std::to_string(*size) + " its header claims");
    return out;
}

// Where the message records of a chunk's data start.
std::vector<std::uint64_t> message_starts(const std::string& data, const Faults& fault) {
    MemoryBytes bytes{data};
    std::vector<std::uint64_t> starts;
    walk(bytes, 0, fault, [&](const Record& r) {
        if (r.op() == op_message) starts.push_back(r.start);
    });
    return starts;
}

// An index record (version 1: entries of a time, 8 bytes, and an offset, 4) names messages of the chunk
// before it: each offset must be where one of its message records starts.
void check_index(FileBytes& file, const Record& index, const std::vector<std::uint64_t>& messages,
                 const Faults& fault) {
    const auto count = index.number<std::uint32_t>("count");
    if (!count || index.number<std::uint32_t>("ver") != 1u) return;  // the library refuses these itself
    if (std::uint64_t{*count} * 12 > index.data_length)
        fault.at(index.start, "an index record claims " + std::to_string(*count) + " entries in " +
                                  std::to_string(index.data_length) + " bytes");
    const std::string entries = file.read(index.data_at, std::uint64_t{*count} * 12);
    for (std::uint32_t i = 0; i < *count; ++i) {
        const auto offset = little_endian<std::uint32_t>(entries, 12 * std::size_t{i} + 8);
        if (!std::binary_search(messages.begin(), messages.end(), offset))
            fault.at(index.data_at + 12 * std::uint64_t{i} + 8,
                     "the index points at byte " + std::to_string(offset) +
                         " of the chunk before it, where no message record starts");
    }
}

}  // namespace

void check_framing(const std::filesystem::path& file) {
    FileBytes bytes(file);
    // Older ROS 1 bags start "#ROSRECORD V1.2" (or V1.1): a format the storage library does not read.
    const std::string start = bytes.read(0, std::min<std::uint64_t>(bytes.size(), 20));
    for (const char* magic : {"#ROSRECORD V", "#ROSBAG V"})
        if (start.rfind(magic, 0) == 0 && start.rfind("#ROSBAG V2.0\n", 0) != 0) {
            const std::string rest = start.substr(std::strlen(magic));
            const std::string version = rest.substr(0, rest.find_first_not_of("0123456789."));
            throw InputError(quoted_path(file) + ": ROS 1 bag format " + version +
                             " is not supported (bvc3d reads format 2.0; `rosbag filter IN OUT True` rewrites it "
                             "as 2.0)");
        }
    if (bytes.size() < 13 || bytes.read(0, 13) != "#ROSBAG V2.0\n")
        throw InputError(quoted_path(file) + ": not a ROS 1 bag (no '#ROSBAG V2.0' at its start)");
    const Faults fault(quoted_path(file) + ", ", "");
    std::vector<std::uint64_t> starts, chunks;       // where records start; where chunk records do
    std::vector<std::uint64_t> index_at, chunks_at;  // where the header and the chunk infos say they are
    std::vector<std::uint64_t> messages;             // where messages start in the last chunk's uncompressed data
    walk(bytes, 13, fault, [&](const Record& r) {
        starts.push_back(r.start);
        switch (r.op()) {
            case op_bag_header:
                if (const auto at = r.number<std::uint64_t>("index_pos")) index_at.push_back(*at);
                break;
            case op_chunk_info:
                if (const auto at = r.number<std::uint64_t>("chunk_pos")) chunks_at.push_back(*at);
                break;
            case op_chunk: {
                chunks.push_back(r.start);
                const Faults in_chunk(quoted_path(file) + ", chunk at byte " + std::to_string(r.start) + ", ",
                                      " of its uncompressed data");
                messages = message_starts(uncompressed(bytes, r, fault), in_chunk);
                break;
            }
            case op_index:
                check_index(bytes, r, messages, fault);
                break;
            default:
                break;
        }
    });
    for (const std::uint64_t at : index_at)
        if (at != bytes.size() && !std::binary_search(starts.begin(), starts.end(), at))
            fault.at(at, "the bag's header points its index at byte " + std::to_string(at) + ", where no record is");
    for (const std::uint64_t at : chunks_at)
        if (!std::binary_search(chunks.begin(), chunks.end(), at))
            fault.at(at, "the bag's index points at byte " + std::to_string(at) + ", where no chunk starts");
}

}  // namespace bvc3d::recording::ros1
