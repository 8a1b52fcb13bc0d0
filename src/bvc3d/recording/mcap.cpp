// MCAP, read and written from the public format specification (no Debian package exists for it);
// compression through Debian's libzstd and liblz4, CRCs through zlib.
#include "bvc3d/recording/mcap.hpp"

#include <fcntl.h>
#include <lz4frame.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zlib.h>
#include <zstd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <map>
#include <mutex>

#include "bvc3d/core/error.hpp"
#include "bvc3d/recording/bag.hpp"
#include "bvc3d/recording/parsing.hpp"

namespace bvc3d::recording {

namespace fs = std::filesystem;

namespace {

using detail::ByteOrder;

constexpr std::uint8_t magic[8] = {0x89, 'M', 'C', 'A', 'P', 0x30, '\r', '\n'};
enum Op : std::uint8_t {
    op_header = 0x01,
    op_footer = 0x02,
    op_schema = 0x03,
    op_channel = 0x04,
    op_message = 0x05,
    op_chunk = 0x06,
    op_data_end = 0x0F,
};
// A chunk larger than this uncompressed is refused rather than allocated (a corrupt size).
constexpr std::uint64_t max_chunk_bytes = std::uint64_t{1} << 32;

std::uint32_t crc32_of(const std::uint8_t* p, std::size_t n, std::uint32_t crc = 0) {
    while (n > 0) {
        const auto step = static_cast<uInt>(std::min<std::size_t>(n, 1u << 30));
        crc = static_cast<std::uint32_t>(::crc32(crc, p, step));
        p += step;
        n -= step;
    }
    return crc;
}

// Reads the fields of one record's content, each checked against the content's end.
class Fields {
public:
    Fields(const std::uint8_t* p, std::uint64_t n, std::string what) : p_(p), n_(n), what_(std::move(what)) {}
    template <class T>
    T number() {
        need(sizeof(T));
        const T v = detail::load<T>(reinterpret_cast<const char*>(p_ + pos_), ByteOrder::little);
        pos_ += sizeof(T);
        return v;
    }
    std::string string() {
        const auto n = number<std::uint32_t>();
        need(n);
        std::string s(reinterpret_cast<const char*>(p_ + pos_), n);
        pos_ += n;
        return s;
    }
    // A uint32- or uint64-prefixed byte block: its start and size.
    template <class Length>
    std::pair<std::uint64_t, std::uint64_t> block() {
        const std::uint64_t n = number<Length>();
        need(n);
        const std::uint64_t at = pos_;
        pos_ += n;
        return {at, n};
    }
    std::uint64_t pos() const { return pos_; }
    std::uint64_t size() const { return n_; }

private:
    void need(std::uint64_t n) const {
        if (n > n_ - pos_)
            throw InputError(what_ + " claims " + std::to_string(n) + " bytes at its byte " + std::to_string(pos_) +
                             "; it has " + std::to_string(n_ - pos_) + " left (truncated or corrupt)");
    }
    const std::uint8_t* p_;
    std::uint64_t n_, pos_ = 0;
    std::string what_;
};

// The file, mapped read-only.
class MappedFile {
public:
    explicit MappedFile(const fs::path& file) {
        fd_ = ::open(file.c_str(), O_RDONLY | O_CLOEXEC);
        if (fd_ < 0) throw InputError(quoted_path(file) + ": cannot open (" + std::strerror(errno) + ")");
        struct stat st {};
        if (::fstat(fd_, &st) != 0 || !S_ISREG(st.st_mode)) {
            ::close(fd_);
            throw InputError(quoted_path(file) + " is not a file");
        }
        size_ = static_cast<std::uint64_t>(st.st_size);
        if (size_ > 0) {
            void* m = ::mmap(nullptr, size_, PROT_READ, MAP_PRIVATE, fd_, 0);
            if (m == MAP_FAILED) {
                ::close(fd_);
                throw InputError(quoted_path(file) + ": cannot map (" + std::strerror(errno) + ")");
            }
            data_ = static_cast<const std::uint8_t*>(m);
        }
    }
    ~MappedFile() {
        if (data_) ::munmap(const_cast<std::uint8_t*>(data_), size_);
        if (fd_ >= 0) ::close(fd_);
    }
    MappedFile(const MappedFile&) = delete;
    MappedFile& operator=(const MappedFile&) = delete;
    const std::uint8_t* data() const { return data_; }
    std::uint64_t size() const { return size_; }

private:
    int fd_ = -1;
    const std::uint8_t* data_ = nullptr;
    std::uint64_t size_ = 0;
};

struct Chunk {
    std::uint64_t offset = 0, size = 0;  // the compressed records in the file
    std::uint64_t uncompressed_size = 0;
    std::uint32_t crc = 0;
    McapCompression compression = McapCompression::none;
    mutable bool verified = false;  // its CRC was checked (when the file was indexed): not again
};

struct MessageRef {
    std::uint64_t log_time = 0;
    std::int64_t chunk = -1;             // -1: in the file itself
    std::uint64_t offset = 0, size = 0;  // of the message's data, in the file or the uncompressed chunk
};

struct Channel {
    std::string topic, type, encoding;
    std::vector<MessageRef> messages;
};

class McapBag : public BagReader {
public:
    explicit McapBag(const fs::path& file) : BagReader(file), file_(file) {
        index();
        collect_topics();
    }
    std::string format() const override { return "MCAP"; }

    std::vector<std::uint8_t> serialized(std::size_t t, std::size_t k) const override {
        const MessageRef& m = *topic_messages_[t][k];
        if (m.chunk < 0) return {file_.data() + m.offset, file_.data() + m.offset + m.size};
        const std::lock_guard lock(mutex_);
        if (cached_chunk_ != m.chunk) {
            cached_chunk_ = -1;
            cached_ = decompress(chunks_[static_cast<std::size_t>(m.chunk)], static_cast<std::size_t>(m.chunk));
            cached_chunk_ = m.chunk;
        }
        return {cached_.data() + m.offset, cached_.data() + m.offset + m.size};
    }

private:
    std::string here(std::uint64_t at) const { return quoted_path(path()) + ", byte " + std::to_string(at); }

    std::vector<std::uint8_t> decompress(const Chunk& c, std::size_t index) const {
        const std::string what = quoted_path(path()) + ", chunk " + std::to_string(index);
        // No allocation is trusted to a declared size alone: zstd and lz4 shrink real data a few times
        // (runs of zeros at most about a thousand times).
        if (c.uncompressed_size > max_chunk_bytes ||
            (c.compression != McapCompression::none && c.uncompressed_size > 1024 * c.size + (1u << 20)))
            throw InputError(what + ": an uncompressed size of " + std::to_string(c.uncompressed_size) +
                             " bytes from " + std::to_string(c.size) + " compressed is not believable (corrupt)");
        std::vector<std::uint8_t> out;
        const std::uint8_t* src = file_.data() + c.offset;
        switch (c.compression) {
            case McapCompression::none:
                if (c.size != c.uncompressed_size)
                    throw InputError(what + ": " + std::to_string(c.size) + " uncompressed bytes where " +
                                     std::to_string(c.uncompressed_size) + " are declared");
                out.assign(src, src + c.size);
                break;
            case McapCompression::zstd: {
                out.resize(c.uncompressed_size);
                const std::size_t n = ZSTD_decompress(out.data(), out.size(), src, c.size);
                if (ZSTD_isError(n))
                    throw InputError(what + ": zstd cannot decompress it (" + ZSTD_getErrorName(n) + ")");
                if (n != c.uncompressed_size)
                    throw InputError(what + ": decompresses to " + std::to_string(n) + " bytes where " +
                                     std::to_string(c.uncompressed_size) + " are declared");
                break;
            }
            case McapCompression::lz4: {
                out.resize(c.uncompressed_size);
                LZ4F_dctx* ctx = nullptr;
                if (LZ4F_isError(LZ4F_createDecompressionContext(&ctx, LZ4F_VERSION)))
                    throw std::runtime_error("lz4: no decompression context");
                std::size_t produced = 0, consumed = 0, hint = 1;
                while (hint != 0 && consumed < c.size) {
                    std::size_t dst = out.size() - produced, src_n = c.size - consumed;
                    hint = LZ4F_decompress(ctx, out.data() + produced, &dst, src + consumed, &src_n, nullptr);
                    if (LZ4F_isError(hint)) {
                        const std::string reason = LZ4F_getErrorName(hint);
                        LZ4F_freeDecompressionContext(ctx);
                        throw InputError(what + ": lz4 cannot decompress it (" + reason + ")");
                    }
                    produced += dst;
                    consumed += src_n;
                    if (dst == 0 && src_n == 0) break;  // no progress: the output is full
                }
                LZ4F_freeDecompressionContext(ctx);
                if (hint != 0 || produced != c.uncompressed_size)
                    throw InputError(what + ": decompresses to " + std::to_string(produced) + (hint != 0 ? "+" : "") +
                                     " bytes where " + std::to_string(c.uncompressed_size) + " are declared");
                break;
            }
        }
        if (c.crc != 0 && !c.verified) {
            const std::uint32_t crc = crc32_of(out.data(), out.size());
            if (crc != c.crc) {
                char text[64];
                std::snprintf(text, sizeof text, "CRC 0x%08x where the chunk declares 0x%08x", crc, c.crc);
                throw InputError(what + ": its records have " + text + " (corrupt)");
            }
            c.verified = true;
        }
        return out;
    }

    // The records of a block (the data section, or a chunk's records): schemas, channels, messages.
    void records(const std::uint8_t* base, std::uint64_t begin, std::uint64_t end, std::int64_t chunk) {
        std::uint64_t pos = begin;
        while (pos < end) {
            const auto where = [&] {
                return chunk < 0 ? here(pos)
                                 : quoted_path(path()) + ", chunk " + std::to_string(chunk) + ", record byte " +
                                       std::to_string(pos - begin);
            };
            if (end - pos < 9) throw InputError(where() + ": a record header is cut off (truncated)");
            const std::uint8_t op = base[pos];
            const auto length =
                detail::load<std::uint64_t>(reinterpret_cast<const char*>(base + pos + 1), ByteOrder::little);
            if (length > end - pos - 9)
                throw InputError(where() + ": a record (opcode " + std::to_string(op) + ") claims " +
                                 std::to_string(length) + " bytes; " + std::to_string(end - pos - 9) +
                                 " are left (truncated or corrupt)");
            const std::uint64_t content = pos + 9;
            if (chunk < 0 && op == op_footer) {
                footer_at_ = pos;
                return;
            }
            if (chunk < 0 && op == op_data_end) {
                check_data_crc(pos, content, length);
                summary_ = true;
            }
            if (!summary_ || chunk >= 0) record(op, base, content, length, chunk, where);
            pos = content + length;
        }
        if (chunk < 0) throw InputError(here(pos) + ": the file ends without a footer (truncated)");
    }

    void check_data_crc(std::uint64_t at, std::uint64_t content, std::uint64_t length) const {
        Fields f(file_.data() + content, length, here(at) + ": DataEnd");
        const auto crc = f.number<std::uint32_t>();
        if (crc == 0) return;
        const std::uint32_t actual = crc32_of(file_.data(), at);
        if (actual != crc) {
            char text[80];
            std::snprintf(text, sizeof text, "CRC 0x%08x where DataEnd declares 0x%08x", actual, crc);
            throw InputError(here(at) + ": the data section has " + text + " (corrupt)");
        }
    }

    template <class Where>
    void record(std::uint8_t op, const std::uint8_t* base, std::uint64_t content, std::uint64_t length,
                std::int64_t chunk, const Where& where) {
        Fields f(base + content, length, where());
        switch (op) {
            case op_schema: {
                const auto id = f.number<std::uint16_t>();
                schemas_[id] = f.string();  // the name; encoding and definition are not needed
                break;
            }
            case op_channel: {
                const auto id = f.number<std::uint16_t>();
                const auto schema = f.number<std::uint16_t>();
                Channel c;
                c.topic = f.string();
                c.encoding = f.string();
                const auto found = schemas_.find(schema);
                if (schema != 0 && found == schemas_.end())
                    throw InputError(where() + ": channel " + std::to_string(id) + " (" + c.topic + ") names schema " +
                                     std::to_string(schema) + ", which no record defined before it");
                c.type = found == schemas_.end() ? "" : found->second;
                if (!channels_.count(id)) channels_[id] = std::move(c);
                break;
            }
            case op_message: {
                const auto id = f.number<std::uint16_t>();
                f.number<std::uint32_t>();  // sequence
                MessageRef m;
                m.log_time = f.number<std::uint64_t>();
                f.number<std::uint64_t>();  // publish time
                m.chunk = chunk;
                m.offset = content + f.pos();
                m.size = length - f.pos();
                const auto c = channels_.find(id);
                if (c == channels_.end())
                    throw InputError(where() + ": a message on channel " + std::to_string(id) +
                                     ", which no record defined before it");
                c->second.messages.push_back(m);
                break;
            }
            case op_chunk: {
                if (chunk >= 0) throw InputError(where() + ": a chunk inside a chunk");
                f.number<std::uint64_t>();  // message start time
                f.number<std::uint64_t>();  // message end time
                Chunk c;
                c.uncompressed_size = f.number<std::uint64_t>();
                c.crc = f.number<std::uint32_t>();
                const std::string compression = f.string();
                if (compression.empty()) c.compression = McapCompression::none;
                else if (compression == "zstd") c.compression = McapCompression::zstd;
                else if (compression == "lz4") c.compression = McapCompression::lz4;
                else
                    throw InputError(where() + ": a chunk compressed with " + detail::quote_token(compression) +
                                     ", which is not one of zstd, lz4 or none");
                const auto [at, size] = f.block<std::uint64_t>();
                c.offset = content + at;
                c.size = size;
                chunks_.push_back(c);
                const auto index = static_cast<std::int64_t>(chunks_.size() - 1);
                const std::vector<std::uint8_t> records_of_chunk = decompress(c, chunks_.size() - 1);
                records(records_of_chunk.data(), 0, records_of_chunk.size(), index);
                break;
            }
            default:
                break;  // attachments, metadata, indexes, statistics: not needed
        }
    }

    void index() {
        const std::uint64_t n = file_.size();
        if (n < 8 || std::memcmp(file_.data(), magic, 8) != 0)
            throw InputError(quoted_path(path()) + ": not an MCAP file (bad magic at the start)");
        if (n < 8 + 9 || file_.data()[8] != op_header)
            throw InputError(quoted_path(path()) + ": the first record is not an MCAP header (truncated or corrupt)");
        records(file_.data(), 8, n, -1);
        const std::uint64_t footer_end =
            footer_at_ + 9 +
            detail::load<std::uint64_t>(reinterpret_cast<const char*>(file_.data() + footer_at_ + 1),
                                        ByteOrder::little);
        if (n - footer_end < 8 || std::memcmp(file_.data() + footer_end, magic, 8) != 0)
            throw InputError(quoted_path(path()) + ": no magic after the footer (truncated or corrupt)");
    }

    void collect_topics() {
        std::map<std::string, std::size_t> by_name;
        for (auto& [id, c] : channels_) {
            auto [it, fresh] = by_name.emplace(c.topic, topics_.size());
            if (fresh) {
                BagTopic t;
                t.name = c.topic;
                t.type = c.type;
                t.encoding = c.encoding == "cdr"    ? MessageEncoding::cdr
                             : c.encoding == "ros1" ? MessageEncoding::ros1
                                                    : MessageEncoding::unknown;
                t.encoding_name = c.encoding;
                topics_.push_back(t);
                topic_messages_.emplace_back();
            } else if (topics_[it->second].type != c.type || topics_[it->second].encoding_name != c.encoding) {
                throw InputError(quoted_path(path()) + ", topic '" + c.topic + "': channels of types " +
                                 topics_[it->second].type + " and " + c.type + " (or encodings) on one topic");
            }
            for (const auto& m : c.messages) topic_messages_[it->second].push_back(&m);
        }
        for (std::size_t t = 0; t < topics_.size(); ++t) {
            auto& refs = topic_messages_[t];
            std::stable_sort(refs.begin(), refs.end(),
                             [](const MessageRef* a, const MessageRef* b) { return a->log_time < b->log_time; });
            topics_[t].count = refs.size();
            if (!refs.empty()) {
                topics_[t].first = static_cast<double>(refs.front()->log_time) * 1e-9;
                topics_[t].last = static_cast<double>(refs.back()->log_time) * 1e-9;
            }
        }
    }

    MappedFile file_;
    std::map<std::uint16_t, std::string> schemas_;
    std::map<std::uint16_t, Channel> channels_;
    std::vector<Chunk> chunks_;
    std::vector<std::vector<const MessageRef*>> topic_messages_;
    std::uint64_t footer_at_ = 0;
    bool summary_ = false;  // past DataEnd: the summary repeats schemas and channels
    mutable std::mutex mutex_;
    mutable std::int64_t cached_chunk_ = -1;
    mutable std::vector<std::uint8_t> cached_;
};

// ---- Writing ----

void put_u16(std::string& s, std::uint16_t v) { detail::store(s, v, ByteOrder::little); }
void put_u32(std::string& s, std::uint32_t v) { detail::store(s, v, ByteOrder::little); }
void put_u64(std::string& s, std::uint64_t v) { detail::store(s, v, ByteOrder::little); }
void put_string(std::string& s, const std::string& v) {
    put_u32(s, static_cast<std::uint32_t>(v.size()));
    s += v;
}

constexpr std::size_t chunk_target = 4u << 20;

}  // namespace

std::unique_ptr<BagReader> open_mcap(const fs::path& file) { return std::make_unique<McapBag>(file); }

McapWriter::McapWriter(const fs::path& file, McapCompression compression) : file_(file), compression_(compression) {
    std::string start(reinterpret_cast<const char*>(magic), 8);
    file_.write(start);
    data_crc_ = crc32_of(magic, 8);
    std::string header;
    put_string(header, "ros2");
    put_string(header, "bvc3d");
    record(op_header, header);
}

McapWriter::~McapWriter() = default;

void McapWriter::record(std::uint8_t op, const std::string& content) {
    std::string r(1, static_cast<char>(op));
    put_u64(r, content.size());
    r += content;
    data_crc_ = crc32_of(reinterpret_cast<const std::uint8_t*>(r.data()), r.size(), data_crc_);
    file_.write(r);
}

std::uint16_t McapWriter::add_channel(const std::string& topic, const std::string& type,
                                      const std::string& definition) {
    const std::uint16_t schema = next_schema_++;
    std::string s;
    put_u16(s, schema);
    put_string(s, type);
    put_string(s, "ros2msg");
    put_string(s, definition);  // the data: a uint32-prefixed byte block
    record(op_schema, s);
    const std::uint16_t id = next_channel_++;
    std::string c;
    put_u16(c, id);
    put_u16(c, schema);
    put_string(c, topic);
    put_string(c, "cdr");
    put_u32(c, 0);  // metadata: an empty map
    record(op_channel, c);
    sequence_.push_back(0);
    return id;
}

void McapWriter::write(std::uint16_t channel, std::uint64_t log_time_ns, const std::vector<std::uint8_t>& cdr) {
    if (chunk_.empty()) chunk_start_ = log_time_ns;
    chunk_start_ = std::min(chunk_start_, log_time_ns);
    chunk_end_ = std::max(chunk_end_, log_time_ns);
    std::string m;
    put_u16(m, channel);
    put_u32(m, sequence_.at(channel)++);
    put_u64(m, log_time_ns);
    put_u64(m, log_time_ns);
    m.append(reinterpret_cast<const char*>(cdr.data()), cdr.size());
    chunk_ += static_cast<char>(op_message);
    put_u64(chunk_, m.size());
    chunk_ += m;
    if (chunk_.size() >= chunk_target) flush_chunk();
}

void McapWriter::flush_chunk() {
    if (chunk_.empty()) return;
    std::string packed;
    const char* name = "";
    if (compression_ == McapCompression::zstd) {
        packed.resize(ZSTD_compressBound(chunk_.size()));
        const std::size_t n = ZSTD_compress(packed.data(), packed.size(), chunk_.data(), chunk_.size(), 3);
        if (ZSTD_isError(n)) throw std::runtime_error(std::string("zstd: ") + ZSTD_getErrorName(n));
        packed.resize(n);
        name = "zstd";
    } else if (compression_ == McapCompression::lz4) {
        packed.resize(LZ4F_compressFrameBound(chunk_.size(), nullptr));
        const std::size_t n = LZ4F_compressFrame(packed.data(), packed.size(), chunk_.data(), chunk_.size(), nullptr);
        if (LZ4F_isError(n)) throw std::runtime_error(std::string("lz4: ") + LZ4F_getErrorName(n));
        packed.resize(n);
        name = "lz4";
    } else {
        packed = chunk_;
    }
    std::string c;
    put_u64(c, chunk_start_);
    put_u64(c, chunk_end_);
    put_u64(c, chunk_.size());
    put_u32(c, crc32_of(reinterpret_cast<const std::uint8_t*>(chunk_.data()), chunk_.size()));
    put_string(c, name);
    put_u64(c, packed.size());
    c += packed;
    record(op_chunk, c);
    chunk_.clear();
    chunk_end_ = 0;
}

void McapWriter::commit() {
    flush_chunk();
    std::string end;
    put_u32(end, data_crc_);  // of everything before the DataEnd record
    std::string r(1, static_cast<char>(op_data_end));
    put_u64(r, end.size());
    r += end;
    file_.write(r);
    std::string footer;
    put_u64(footer, 0);  // no summary section
    put_u64(footer, 0);  // no summary offsets
    put_u32(footer, 0);  // no summary CRC
    std::string f(1, static_cast<char>(op_footer));
    put_u64(f, footer.size());
    f += footer;
    file_.write(f);
    file_.write(std::string(reinterpret_cast<const char*>(magic), 8));
    file_.commit();
}

const std::string& ros2_definition(const std::string& type) {
    static const std::string header =
        "================================================================================\n"
        "MSG: std_msgs/Header\n"
        "builtin_interfaces/Time stamp\n"
        "string frame_id\n";
    static const std::string pose =
        "================================================================================\n"
        "MSG: geometry_msgs/Point\nfloat64 x\nfloat64 y\nfloat64 z\n"
        "================================================================================\n"
        "MSG: geometry_msgs/Quaternion\nfloat64 x 0\nfloat64 y 0\nfloat64 z 0\nfloat64 w 1\n";
    static const std::map<std::string, std::string> definitions{
        {"sensor_msgs/msg/PointCloud2",
         "std_msgs/Header header\nuint32 height\nuint32 width\nPointField[] fields\nbool is_bigendian\n"
         "uint32 point_step\nuint32 row_step\nuint8[] data\nbool is_dense\n" +
             header +
             "================================================================================\n"
             "MSG: sensor_msgs/PointField\n"
             "uint8 INT8=1\nuint8 UINT8=2\nuint8 INT16=3\nuint8 UINT16=4\nuint8 INT32=5\nuint8 UINT32=6\n"
             "uint8 FLOAT32=7\nuint8 FLOAT64=8\nstring name\nuint32 offset\nuint8 datatype\nuint32 count\n"},
        {"nav_msgs/msg/Odometry",
         "std_msgs/Header header\nstring child_frame_id\ngeometry_msgs/PoseWithCovariance pose\n"
         "geometry_msgs/TwistWithCovariance twist\n" +
             header +
             "================================================================================\n"
             "MSG: geometry_msgs/PoseWithCovariance\nPose pose\nfloat64[36] covariance\n"
             "================================================================================\n"
             "MSG: geometry_msgs/Pose\nPoint position\nQuaternion orientation\n" +
             pose +
             "================================================================================\n"
             "MSG: geometry_msgs/TwistWithCovariance\nTwist twist\nfloat64[36] covariance\n"
             "================================================================================\n"
             "MSG: geometry_msgs/Twist\nVector3 linear\nVector3 angular\n"
             "================================================================================\n"
             "MSG: geometry_msgs/Vector3\nfloat64 x\nfloat64 y\nfloat64 z\n"},
        {"tf2_msgs/msg/TFMessage",
         "geometry_msgs/TransformStamped[] transforms\n"
         "================================================================================\n"
         "MSG: geometry_msgs/TransformStamped\nstd_msgs/Header header\nstring child_frame_id\nTransform transform\n" +
             header +
             "================================================================================\n"
             "MSG: geometry_msgs/Transform\nVector3 translation\nQuaternion rotation\n"
             "================================================================================\n"
             "MSG: geometry_msgs/Vector3\nfloat64 x\nfloat64 y\nfloat64 z\n"
             "================================================================================\n"
             "MSG: geometry_msgs/Quaternion\nfloat64 x 0\nfloat64 y 0\nfloat64 z 0\nfloat64 w 1\n"}};
    const auto found = definitions.find(type);
    if (found == definitions.end()) throw std::logic_error("no ROS 2 definition for " + type);
    return found->second;
}

}  // namespace bvc3d::recording
