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
#include <limits>
#include <map>
#include <mutex>
#include <optional>
#include <tuple>

#include "bvc3d/core/error.hpp"
#include "bvc3d/core/memory.hpp"
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
    op_message_index = 0x07,
    op_chunk_index = 0x08,
    op_statistics = 0x0B,
    op_summary_offset = 0x0E,
    op_data_end = 0x0F,
};

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
    mutable bool verified = false;  // its CRC was checked: not again
};

struct MessageRef {
    std::uint64_t log_time = 0;
    std::int64_t chunk = -1;   // -1: in the file itself
    std::uint64_t record = 0;  // where its Message record starts, in the file or the uncompressed chunk
};

struct Channel {
    std::string topic, type, encoding;
    std::vector<MessageRef> messages;
};

// A Chunk record's fields (after its two times): sizes, CRC, compression and where its records are.
Chunk chunk_fields(Fields& f, std::uint64_t content, const std::string& where) {
    Chunk c;
    c.uncompressed_size = f.number<std::uint64_t>();
    c.crc = f.number<std::uint32_t>();
    const std::string compression = f.string();
    if (compression.empty()) c.compression = McapCompression::none;
    else if (compression == "zstd") c.compression = McapCompression::zstd;
    else if (compression == "lz4") c.compression = McapCompression::lz4;
    else
        throw InputError(where + ": a chunk compressed with " + detail::quote_token(compression) +
                         ", which is not one of zstd, lz4 or none");
    const auto [at, size] = f.block<std::uint64_t>();
    c.offset = content + at;
    c.size = size;
    return c;
}

// The index of a file with a summary: per chunk, where it is and where its message indexes are.
struct ChunkIndex {
    std::uint64_t start = 0, length = 0;                                   // the Chunk record (opcode included)
    std::vector<std::pair<std::uint16_t, std::uint64_t>> message_indexes;  // channel, Message Index offset
};

// Room for more decompressed bytes, up to the declared size: the buffer grows with what the data
// really holds (doubling from 1 MB), so a corrupt declared size costs nothing until data fills it.
void grow(std::vector<std::uint8_t>& out, std::size_t produced, std::uint64_t declared) {
    if (produced < out.size() || out.size() >= declared) return;
    out.resize(
        static_cast<std::size_t>(std::min<std::uint64_t>(declared, std::max<std::size_t>(out.size() * 2, 1u << 20))));
}

class McapBag : public BagReader {
public:
    explicit McapBag(const fs::path& file) : BagReader(file), file_(file) {
        open();
        collect_topics();
    }
    std::string format() const override { return "MCAP"; }

    std::vector<std::uint8_t> serialized(std::size_t t, std::size_t k) const override {
        const auto& [channel, m] = topic_messages_[t][k];
        if (m->chunk < 0) return message_data(file_.data(), file_.size(), m->record, channel, *m, here(m->record));
        const std::lock_guard lock(mutex_);
        if (cached_chunk_ != m->chunk) {
            cached_chunk_ = -1;
            cached_ = decompress(chunks_[static_cast<std::size_t>(m->chunk)], static_cast<std::size_t>(m->chunk));
            cached_chunk_ = m->chunk;
        }
        return message_data(
            cached_.data(), cached_.size(), m->record, channel, *m,
            quoted_path(path()) + ", chunk " + std::to_string(m->chunk) + ", record byte " + std::to_string(m->record));
    }

private:
    std::string here(std::uint64_t at) const { return quoted_path(path()) + ", byte " + std::to_string(at); }

    // The data of the Message record at `at` of `base`, which the index says is `m` on `channel`.
    static std::vector<std::uint8_t> message_data(const std::uint8_t* base, std::uint64_t n, std::uint64_t at,
                                                  std::uint16_t channel, const MessageRef& m,
                                                  const std::string& where) {
        if (at > n || n - at < 9 || base[at] != op_message)
            throw InputError(where + ": no Message record where the index points (corrupt)");
        const auto length =
            detail::load<std::uint64_t>(reinterpret_cast<const char*>(base + at + 1), ByteOrder::little);
        if (length > n - at - 9) throw InputError(where + ": the Message record is cut off (truncated or corrupt)");
        Fields f(base + at + 9, length, where);
        const auto id = f.number<std::uint16_t>();
        f.number<std::uint32_t>();  // sequence
        const auto log_time = f.number<std::uint64_t>();
        f.number<std::uint64_t>();  // publish time
        if (id != channel || log_time != m.log_time)
            throw InputError(where + ": the Message record (channel " + std::to_string(id) + ", log time " +
                             std::to_string(log_time) + ") is not the one the index names (channel " +
                             std::to_string(channel) + ", log time " + std::to_string(m.log_time) + ")");
        const std::uint8_t* data = base + at + 9 + f.pos();
        return {data, data + (length - f.pos())};
    }

    std::vector<std::uint8_t> decompress(const Chunk& c, std::size_t index) const {
        const std::string what = quoted_path(path()) + ", chunk " + std::to_string(index);
        // The chunk declares its uncompressed size: the buffer grows up to that size (if the machine has
        // the memory) as the data fills it, and data that decompresses to more or less is refused. No
        // ratio is assumed: zstd packs 4 MB of zeros into ~150 bytes.
        if (c.uncompressed_size > std::numeric_limits<std::size_t>::max() / 2)
            throw InputError(what + ": an uncompressed size of " + std::to_string(c.uncompressed_size) +
                             " bytes is not believable (corrupt)");
        check_memory(static_cast<double>(c.uncompressed_size),
                     what + " (" + std::to_string(c.size) + " bytes compressed)",
                     "the chunk's declared uncompressed size is corrupt, or the machine is too small for it");
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
                // A frame that names its own size must name the declared one (checked before allocating).
                const unsigned long long framed = ZSTD_getFrameContentSize(src, c.size);
                if (framed != ZSTD_CONTENTSIZE_UNKNOWN && framed != ZSTD_CONTENTSIZE_ERROR &&
                    framed != c.uncompressed_size)
                    throw InputError(what + ": its zstd frame holds " + std::to_string(framed) + " bytes where " +
                                     std::to_string(c.uncompressed_size) + " are declared");
                std::unique_ptr<ZSTD_DStream, std::size_t (*)(ZSTD_DStream*)> z(ZSTD_createDStream(), ZSTD_freeDStream);
                ZSTD_initDStream(z.get());
                ZSTD_inBuffer in{src, c.size, 0};
                std::size_t produced = 0, left = 1;
                for (;;) {
                    grow(out, produced, c.uncompressed_size);
                    ZSTD_outBuffer o{out.data(), out.size(), produced};
                    const std::size_t before = in.pos;
                    left = ZSTD_decompressStream(z.get(), &o, &in);
                    if (ZSTD_isError(left))
                        throw InputError(what + ": zstd cannot decompress it (" + ZSTD_getErrorName(left) + ")");
                    const bool progress = o.pos > produced || in.pos > before;
                    produced = o.pos;
                    if ((left == 0 && in.pos == in.size) || !progress) break;
                }
                if (left != 0 || in.pos != in.size || produced != c.uncompressed_size)
                    throw InputError(what + ": decompresses to " + std::to_string(produced) +
                                     (in.pos != in.size ? "+" : "") + " bytes where " +
                                     std::to_string(c.uncompressed_size) + " are declared");
                break;
            }
            case McapCompression::lz4: {
                LZ4F_dctx* ctx = nullptr;
                if (LZ4F_isError(LZ4F_createDecompressionContext(&ctx, LZ4F_VERSION)))
                    throw std::runtime_error("lz4: no decompression context");
                std::size_t produced = 0, consumed = 0, hint = 1;
                while (hint != 0 && consumed < c.size) {
                    grow(out, produced, c.uncompressed_size);
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
                out.resize(produced);
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

    // The record at `pos` of a block ending at `end`: its opcode and content length, or nullopt when
    // the block ends inside it.
    static std::optional<std::pair<std::uint8_t, std::uint64_t>> record_at(const std::uint8_t* base, std::uint64_t pos,
                                                                           std::uint64_t end) {
        if (end - pos < 9) return std::nullopt;
        const auto length =
            detail::load<std::uint64_t>(reinterpret_cast<const char*>(base + pos + 1), ByteOrder::little);
        if (length > end - pos - 9) return std::nullopt;
        return std::make_pair(base[pos], length);
    }

    void open() {
        const std::uint64_t n = file_.size();
        if (n < 8 || std::memcmp(file_.data(), magic, 8) != 0)
            throw InputError(quoted_path(path()) + ": not an MCAP file (bad magic at the start)");
        if (n < 8 + 9 || file_.data()[8] != op_header)
            throw InputError(quoted_path(path()) + ": the first record is not an MCAP header (truncated or corrupt)");
        constexpr std::uint64_t footer_size = 9 + 20;
        const std::uint8_t* end = file_.data() + n;
        const bool finished = n >= 8 + 9 + footer_size + 8 && std::memcmp(end - 8, magic, 8) == 0 &&
                              end[-8 - std::int64_t{footer_size}] == op_footer;
        if (!finished) return scan_unfinished();
        const std::uint64_t footer_at = n - 8 - footer_size;
        Fields f(file_.data() + footer_at + 9, 20, here(footer_at) + ": Footer");
        const auto summary_start = f.number<std::uint64_t>();
        const auto summary_offset_start = f.number<std::uint64_t>();
        const auto summary_crc = f.number<std::uint32_t>();
        if (summary_start == 0) {
            scan(footer_at);
            return;
        }
        if (summary_start < 8 + 9 || summary_start > footer_at ||
            (summary_offset_start != 0 && (summary_offset_start < summary_start || summary_offset_start > footer_at)))
            throw InputError(here(footer_at) + ": the Footer's summary offsets (" + std::to_string(summary_start) +
                             ", " + std::to_string(summary_offset_start) + ") are outside the file (corrupt)");
        if (summary_crc != 0) {
            const std::uint32_t actual = crc32_of(file_.data() + summary_start, footer_at + 9 + 16 - summary_start);
            if (actual != summary_crc) {
                char text[80];
                std::snprintf(text, sizeof text, "CRC 0x%08x where the Footer declares 0x%08x", actual, summary_crc);
                throw InputError(here(summary_start) + ": the summary has " + text + " (corrupt)");
            }
        }
        if (!read_index(summary_start, summary_offset_start != 0 ? summary_offset_start : footer_at)) {
            // The summary does not index every message (no chunk indexes, or messages outside chunks):
            // the data section is read from its start, and the summary's channels are kept.
            for (auto& [id, c] : channels_) c.messages.clear();
            chunks_.clear();
            scan(footer_at);
        }
    }

    // A file that does not end with a Footer (a recording that stopped before it was closed): every
    // complete record up to where it ends, with a warning.
    void scan_unfinished() {
        const std::uint64_t stop = scan(file_.size(), true);
        std::size_t messages = 0;
        for (const auto& [id, c] : channels_) messages += c.messages.size();
        const std::string what =
            quoted_path(path()) + " has no footer: it ends at byte " + std::to_string(file_.size()) +
            (stop < file_.size() ? " inside a record (truncated)" : "") + " (a recording that did not finish?)";
        if (messages == 0) throw InputError(what + " and holds no complete message");
        std::fprintf(stderr, "bvc3d: warning: %s; read by a linear scan: %zu messages in the first %llu bytes\n",
                     what.c_str(), messages, static_cast<unsigned long long>(stop));
    }

    // The records of the data section from its start up to the Footer at `footer_at` (or, `unfinished`,
    // up to the first record the file cuts off). Returns where it stopped.
    std::uint64_t scan(std::uint64_t footer_at, bool unfinished = false) {
        std::uint64_t pos = 8;
        bool summary = false;  // past DataEnd: only schemas and channels are read (the summary repeats them)
        while (pos < footer_at) {
            const auto r = record_at(file_.data(), pos, footer_at);
            if (!r) {
                if (unfinished) return pos;
                throw InputError(here(pos) + ": a record is cut off before the footer (truncated or corrupt)");
            }
            const auto [op, length] = *r;
            if (op == op_footer) return pos;
            if (op == op_data_end) {
                check_data_crc(pos, pos + 9, length);
                summary = true;
            }
            if (!summary || op == op_schema || op == op_channel) {
                const auto where = [&] { return here(pos); };
                record(op, file_.data(), pos + 9, length, -1, pos, where);
            }
            pos += 9 + length;
        }
        return pos;
    }

    // The records of one decompressed chunk.
    void scan_chunk(const std::vector<std::uint8_t>& records, std::int64_t chunk) {
        std::uint64_t pos = 0;
        while (pos < records.size()) {
            const auto where = [&] {
                return quoted_path(path()) + ", chunk " + std::to_string(chunk) + ", record byte " +
                       std::to_string(pos);
            };
            const auto r = record_at(records.data(), pos, records.size());
            if (!r) throw InputError(where() + ": a record is cut off at the chunk's end (corrupt)");
            record(r->first, records.data(), pos + 9, r->second, chunk, pos, where);
            pos += 9 + r->second;
        }
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

    // One record: schemas, channels and messages are kept; a chunk is decompressed and read; the
    // rest (attachments, metadata, indexes, statistics) are not needed.
    template <class Where>
    void record(std::uint8_t op, const std::uint8_t* base, std::uint64_t content, std::uint64_t length,
                std::int64_t chunk, std::uint64_t at, const Where& where) {
        Fields f(base + content, length, where());
        switch (op) {
            case op_schema:
                return schema(f, where());
            case op_channel:
                return channel(f, where());
            case op_message: {
                const auto id = f.number<std::uint16_t>();
                f.number<std::uint32_t>();  // sequence
                MessageRef m;
                m.log_time = f.number<std::uint64_t>();
                f.number<std::uint64_t>();  // publish time
                m.chunk = chunk;
                m.record = at;
                const auto c = channels_.find(id);
                if (c == channels_.end())
                    throw InputError(where() + ": a message on channel " + std::to_string(id) +
                                     ", which no record defined before it");
                c->second.messages.push_back(m);
                return;
            }
            case op_chunk: {
                if (chunk >= 0) throw InputError(where() + ": a chunk inside a chunk");
                f.number<std::uint64_t>();  // message start time
                f.number<std::uint64_t>();  // message end time
                chunks_.push_back(chunk_fields(f, content, where()));
                const auto index = static_cast<std::int64_t>(chunks_.size() - 1);
                scan_chunk(decompress(chunks_.back(), chunks_.size() - 1), index);
                return;
            }
            default:
                return;
        }
    }

    // Schema id 0 is reserved (it means "no schema"): a schema record may not take it.
    void schema(Fields& f, const std::string& where) {
        const auto id = f.number<std::uint16_t>();
        if (id == 0) throw InputError(where + ": a schema with id 0, which MCAP reserves for 'no schema'");
        std::string name = f.string();  // encoding and definition are not needed
        schemas_.emplace(id, std::move(name));
    }

    void channel(Fields& f, const std::string& where) {
        const auto id = f.number<std::uint16_t>();
        const auto schema = f.number<std::uint16_t>();
        Channel c;
        c.topic = f.string();
        c.encoding = f.string();
        const auto found = schemas_.find(schema);
        if (schema != 0 && found == schemas_.end())
            throw InputError(where + ": channel " + std::to_string(id) + " (" + c.topic + ") names schema " +
                             std::to_string(schema) + ", which no record defined before it");
        c.type = schema == 0 ? "(no schema)" : found->second;  // schema 0: the channel has no schema
        channels_.emplace(id, std::move(c));
    }

    // The summary section [begin, end): schemas, channels, statistics and chunk indexes. Then each
    // chunk's message indexes give its messages without decompressing it. False when the summary does
    // not index every message (no chunk indexes, or fewer indexed messages than its statistics count).
    bool read_index(std::uint64_t begin, std::uint64_t end) {
        std::vector<ChunkIndex> indexes;
        std::optional<std::uint64_t> message_count;
        for (std::uint64_t pos = begin; pos < end;) {
            const auto r = record_at(file_.data(), pos, end);
            if (!r) throw InputError(here(pos) + ": a summary record is cut off (corrupt)");
            const auto [op, length] = *r;
            Fields f(file_.data() + pos + 9, length, here(pos));
            if (op == op_schema) schema(f, here(pos));
            else if (op == op_channel) channel(f, here(pos));
            else if (op == op_statistics) message_count = f.number<std::uint64_t>();
            else if (op == op_chunk_index) {
                ChunkIndex c;
                f.number<std::uint64_t>();  // message start time
                f.number<std::uint64_t>();  // message end time
                c.start = f.number<std::uint64_t>();
                c.length = f.number<std::uint64_t>();
                const auto [at, size] = f.block<std::uint32_t>();
                Fields map(file_.data() + pos + 9 + at, size, here(pos) + ": the chunk index's message index offsets");
                while (map.pos() < map.size()) {
                    const auto channel = map.number<std::uint16_t>();
                    c.message_indexes.emplace_back(channel, map.number<std::uint64_t>());
                }
                indexes.push_back(std::move(c));
            }
            pos += 9 + length;
        }
        if (indexes.empty()) return false;
        std::size_t indexed = 0;
        for (const ChunkIndex& c : indexes) indexed += chunk_from_index(c);
        return !message_count || *message_count == indexed;
    }

    // A chunk that a chunk index names: its fields, and its messages from its message indexes (or, if
    // it has none, from its records). Returns how many messages it holds.
    std::size_t chunk_from_index(const ChunkIndex& index) {
        const std::string where = here(index.start) + " (a chunk index points here)";
        const auto r = index.start < file_.size() ? record_at(file_.data(), index.start, file_.size()) : std::nullopt;
        if (!r || r->first != op_chunk || 9 + r->second != index.length)
            throw InputError(where + ": no Chunk record of " + std::to_string(index.length) + " bytes (corrupt)");
        Fields f(file_.data() + index.start + 9, r->second, where);
        f.number<std::uint64_t>();
        f.number<std::uint64_t>();
        chunks_.push_back(chunk_fields(f, index.start + 9, where));
        const auto chunk = static_cast<std::int64_t>(chunks_.size() - 1);
        std::size_t count = 0;
        for (const auto& c : channels_) count += c.second.messages.size();
        if (index.message_indexes.empty()) {
            scan_chunk(decompress(chunks_.back(), chunks_.size() - 1), chunk);
        } else {
            for (const auto& [id, at] : index.message_indexes) {
                const std::string mi =
                    here(at) + " (a message index of the chunk at byte " + std::to_string(index.start) + ")";
                const auto m = at < file_.size() ? record_at(file_.data(), at, file_.size()) : std::nullopt;
                if (!m || m->first != op_message_index)
                    throw InputError(mi + ": no Message Index record there (corrupt)");
                Fields e(file_.data() + at + 9, m->second, mi);
                if (e.number<std::uint16_t>() != id)
                    throw InputError(mi + ": it indexes another channel than the chunk index says (corrupt)");
                const auto channel = channels_.find(id);
                if (channel == channels_.end())
                    throw InputError(mi + ": channel " + std::to_string(id) + ", which the summary does not define");
                const auto [start, size] = e.block<std::uint32_t>();
                if (size % 16 != 0) throw InputError(mi + ": its entries are not 16 bytes each (corrupt)");
                Fields entries(file_.data() + at + 9 + start, size, mi);
                while (entries.pos() < size) {
                    MessageRef ref;
                    ref.log_time = entries.number<std::uint64_t>();
                    ref.record = entries.number<std::uint64_t>();
                    ref.chunk = chunk;
                    channel->second.messages.push_back(ref);
                }
            }
        }
        std::size_t after = 0;
        for (const auto& c : channels_) after += c.second.messages.size();
        return after - count;
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
            for (const auto& m : c.messages) topic_messages_[it->second].emplace_back(id, &m);
        }
        for (std::size_t t = 0; t < topics_.size(); ++t) {
            auto& refs = topic_messages_[t];
            // Log-time order; equal times in the file's order.
            std::stable_sort(refs.begin(), refs.end(), [](const auto& a, const auto& b) {
                return std::tie(a.second->log_time, a.second->chunk, a.second->record) <
                       std::tie(b.second->log_time, b.second->chunk, b.second->record);
            });
            topics_[t].count = refs.size();
            if (!refs.empty()) {
                topics_[t].first = static_cast<double>(refs.front().second->log_time) * 1e-9;
                topics_[t].last = static_cast<double>(refs.back().second->log_time) * 1e-9;
            }
        }
    }

    MappedFile file_;
    std::map<std::uint16_t, std::string> schemas_;
    std::map<std::uint16_t, Channel> channels_;
    std::vector<Chunk> chunks_;
    std::vector<std::vector<std::pair<std::uint16_t, const MessageRef*>>> topic_messages_;  // channel, message
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
std::string framed(std::uint8_t op, const std::string& content) {
    std::string r(1, static_cast<char>(op));
    put_u64(r, content.size());
    return r + content;
}

constexpr std::size_t chunk_target = 4u << 20;

}  // namespace

std::unique_ptr<BagReader> open_mcap(const fs::path& file) { return std::make_unique<McapBag>(file); }

McapWriter::McapWriter(const fs::path& file, McapCompression compression) : file_(file), compression_(compression) {
    emit(std::string(reinterpret_cast<const char*>(magic), 8));
    std::string header;
    put_string(header, "ros2");
    put_string(header, "bvc3d");
    emit(framed(op_header, header));
}

McapWriter::~McapWriter() = default;

void McapWriter::emit(const std::string& bytes) {
    crc_ = crc32_of(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size(), crc_);
    file_.write(bytes);
    written_ += bytes.size();
}

std::uint16_t McapWriter::add_channel(const std::string& topic, const std::string& type, const std::string& definition,
                                      const std::map<std::string, std::string>& metadata) {
    const auto schema = static_cast<std::uint16_t>(schemas_.size() + 1);  // 0 means "no schema"
    std::string s;
    put_u16(s, schema);
    put_string(s, type);
    put_string(s, "ros2msg");
    put_string(s, definition);  // the data: a uint32-prefixed byte block
    schemas_.push_back(framed(op_schema, s));
    emit(schemas_.back());
    const auto id = static_cast<std::uint16_t>(channels_.size());
    std::string c;
    put_u16(c, id);
    put_u16(c, schema);
    put_string(c, topic);
    put_string(c, "cdr");
    std::string map;
    for (const auto& [key, value] : metadata) {
        put_string(map, key);
        put_string(map, value);
    }
    put_string(c, map);  // a Map<string, string>: its byte length, then the pairs
    channels_.push_back(framed(op_channel, c));
    emit(channels_.back());
    counts_.push_back(0);
    chunk_messages_.emplace_back();
    return id;
}

void McapWriter::write(std::uint16_t channel, std::uint64_t log_time_ns, const std::vector<std::uint8_t>& cdr) {
    if (chunk_.empty()) chunk_start_ = chunk_end_ = log_time_ns;
    chunk_start_ = std::min(chunk_start_, log_time_ns);
    chunk_end_ = std::max(chunk_end_, log_time_ns);
    if (messages_ == 0) start_ = end_ = log_time_ns;
    start_ = std::min(start_, log_time_ns);
    end_ = std::max(end_, log_time_ns);
    std::string m;
    put_u16(m, channel);
    put_u32(m, static_cast<std::uint32_t>(counts_.at(channel)++));
    put_u64(m, log_time_ns);
    put_u64(m, log_time_ns);
    m.append(reinterpret_cast<const char*>(cdr.data()), cdr.size());
    chunk_messages_[channel].emplace_back(log_time_ns, chunk_.size());
    chunk_ += framed(op_message, m);
    ++messages_;
    if (chunk_.size() >= chunk_target) flush_chunk();
}

// The chunk, then one Message Index per channel in it; the summary gets its Chunk Index.
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
    const std::uint64_t chunk_at = written_;
    emit(framed(op_chunk, c));
    const std::uint64_t chunk_length = written_ - chunk_at;
    std::string offsets;
    for (std::size_t channel = 0; channel < chunk_messages_.size(); ++channel) {
        auto& entries = chunk_messages_[channel];
        if (entries.empty()) continue;
        put_u16(offsets, static_cast<std::uint16_t>(channel));
        put_u64(offsets, written_);
        std::string index, list;
        put_u16(index, static_cast<std::uint16_t>(channel));
        for (const auto& [time, offset] : entries) {
            put_u64(list, time);
            put_u64(list, offset);
        }
        put_string(index, list);
        emit(framed(op_message_index, index));
        entries.clear();
    }
    std::string ci;
    put_u64(ci, chunk_start_);
    put_u64(ci, chunk_end_);
    put_u64(ci, chunk_at);
    put_u64(ci, chunk_length);
    put_string(ci, offsets);
    put_u64(ci, written_ - chunk_at - chunk_length);  // the message indexes' bytes
    put_string(ci, name);
    put_u64(ci, packed.size());
    put_u64(ci, chunk_.size());
    chunk_indexes_.push_back(framed(op_chunk_index, ci));
    chunk_.clear();
}

// DataEnd, then the summary (schemas, channels, statistics, chunk indexes; each group listed in the
// Summary Offset section) and the Footer, whose CRC covers the summary up to itself.
void McapWriter::commit() {
    flush_chunk();
    std::string end;
    put_u32(end, crc_);  // of everything before the DataEnd record
    emit(framed(op_data_end, end));
    const std::uint64_t summary_start = written_;
    crc_ = 0;
    std::string statistics;
    put_u64(statistics, messages_);
    put_u16(statistics, static_cast<std::uint16_t>(schemas_.size()));
    put_u32(statistics, static_cast<std::uint32_t>(channels_.size()));
    put_u32(statistics, 0);  // attachments
    put_u32(statistics, 0);  // metadata
    put_u32(statistics, static_cast<std::uint32_t>(chunk_indexes_.size()));
    put_u64(statistics, messages_ ? start_ : 0);
    put_u64(statistics, messages_ ? end_ : 0);
    std::string counts;
    for (std::size_t channel = 0; channel < counts_.size(); ++channel) {
        put_u16(counts, static_cast<std::uint16_t>(channel));
        put_u64(counts, counts_[channel]);
    }
    put_string(statistics, counts);
    const std::vector<std::pair<std::uint8_t, std::vector<std::string>>> groups{
        {op_schema, schemas_},
        {op_channel, channels_},
        {op_statistics, {framed(op_statistics, statistics)}},
        {op_chunk_index, chunk_indexes_}};
    std::string offsets;
    for (const auto& [op, records] : groups) {
        if (records.empty()) continue;
        const std::uint64_t start = written_;
        for (const auto& r : records) emit(r);
        std::string o(1, static_cast<char>(op));
        put_u64(o, start);
        put_u64(o, written_ - start);
        offsets += framed(op_summary_offset, o);
    }
    const std::uint64_t summary_offset_start = written_;
    emit(offsets);
    std::string footer;
    put_u64(footer, summary_start);
    put_u64(footer, summary_offset_start);
    std::string f = framed(op_footer, footer + std::string(4, '\0'));
    f.resize(f.size() - 4);
    emit(f);
    std::string crc;
    put_u32(crc, crc_);  // of the summary, its offsets and the Footer up to this field
    file_.write(crc + std::string(reinterpret_cast<const char*>(magic), 8));
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
