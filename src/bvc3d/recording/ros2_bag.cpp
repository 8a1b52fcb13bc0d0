// ROS 2 bags: a folder with metadata.yaml (yaml-cpp) and its storage files, SQLite `.db3` (Debian's
// libsqlite3: rosbag2's tables `topics` and `messages`) or `.mcap` (mcap.cpp). A bag split into
// several files reads as one, the files in the order metadata.yaml lists them. rosbag2's zstd
// compression is undone through Debian's libzstd: FILE mode (each storage file one zstd stream,
// decompressed to a temporary file) and MESSAGE mode (each message's data one zstd frame). A folder
// without metadata.yaml, or a bare storage file, is read from its storage files alone, as
// `ros2 bag reindex` would rebuild the metadata.
#include <sqlite3.h>
#include <unistd.h>
#include <yaml-cpp/yaml.h>
#include <zstd.h>

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <map>
#include <mutex>
#include <regex>

#include "bvc3d/core/error.hpp"
#include "bvc3d/core/memory.hpp"
#include "bvc3d/recording/bag.hpp"

namespace bvc3d::recording {

namespace fs = std::filesystem;

namespace {

class SqliteBag : public BagReader {
public:
    explicit SqliteBag(const fs::path& file) : BagReader(file) {
        std::error_code ec;
        if (!fs::is_regular_file(file, ec)) throw InputError(quoted_path(file) + " does not exist or is not a file");
        sqlite3* db = nullptr;
        const int opened = sqlite3_open_v2(file.c_str(), &db, SQLITE_OPEN_READONLY | SQLITE_OPEN_NOMUTEX, nullptr);
        db_.reset(db);  // closed whatever happens next (even when opening failed: SQLite gives a handle then too)
        if (opened != SQLITE_OK) fail("cannot open it");
        std::map<std::int64_t, std::size_t> by_id;
        {
            Statement s(*this, "SELECT id, name, type, serialization_format FROM topics ORDER BY id");
            while (s.step()) {
                BagTopic t;
                t.name = s.text(1);
                t.type = s.text(2);
                t.encoding_name = s.text(3);
                t.encoding = t.encoding_name == "cdr" ? MessageEncoding::cdr : MessageEncoding::unknown;
                by_id[sqlite3_column_int64(s.get(), 0)] = topics_.size();
                topics_.push_back(t);
                rows_.emplace_back();
            }
        }
        Statement s(*this, "SELECT id, topic_id, timestamp FROM messages ORDER BY timestamp, id");
        while (s.step()) {
            const std::int64_t topic = sqlite3_column_int64(s.get(), 1);
            const auto found = by_id.find(topic);
            if (found == by_id.end())
                throw InputError(quoted_path(file) + ": message row " +
                                 std::to_string(sqlite3_column_int64(s.get(), 0)) + " names topic id " +
                                 std::to_string(topic) + ", which the topics table lacks");
            BagTopic& t = topics_[found->second];
            const double time = static_cast<double>(sqlite3_column_int64(s.get(), 2)) * 1e-9;
            if (t.count == 0) t.first = time;
            t.last = time;
            ++t.count;
            rows_[found->second].push_back(sqlite3_column_int64(s.get(), 0));
        }
        select_ = std::make_unique<Statement>(*this, "SELECT data FROM messages WHERE id = ?");
    }
    std::string format() const override { return "ROS 2 bag (sqlite3)"; }

    std::vector<std::uint8_t> serialized(std::size_t t, std::size_t k) const override {
        const std::lock_guard lock(mutex_);
        sqlite3_stmt* s = select_->get();
        sqlite3_reset(s);
        sqlite3_bind_int64(s, 1, rows_[t][k]);
        if (!select_->step()) throw InputError("its row is gone from the messages table");
        const auto* p = static_cast<const std::uint8_t*>(sqlite3_column_blob(s, 0));
        const int n = sqlite3_column_bytes(s, 0);
        std::vector<std::uint8_t> out(p, p + n);
        sqlite3_reset(s);
        return out;
    }

private:
    [[noreturn]] void fail(const std::string& what) const {
        throw InputError(quoted_path(path()) + ": " + what +
                         " (SQLite: " + (db_ ? sqlite3_errmsg(db_.get()) : "out of memory") + ")");
    }

    class Statement {
    public:
        Statement(const SqliteBag& bag, const char* sql) : bag_(bag) {
            if (sqlite3_prepare_v2(bag.db_.get(), sql, -1, &s_, nullptr) != SQLITE_OK)
                bag.fail("not a ROS 2 bag's database");
        }
        ~Statement() { sqlite3_finalize(s_); }
        Statement(const Statement&) = delete;
        Statement& operator=(const Statement&) = delete;
        bool step() {
            const int rc = sqlite3_step(s_);
            if (rc == SQLITE_ROW) return true;
            if (rc == SQLITE_DONE) return false;
            bag_.fail("cannot read it");
        }
        std::string text(int column) const {
            const auto* p = sqlite3_column_text(s_, column);
            return p ? reinterpret_cast<const char*>(p) : "";
        }
        sqlite3_stmt* get() const { return s_; }

    private:
        const SqliteBag& bag_;
        sqlite3_stmt* s_ = nullptr;
    };

    // Declared first: closed last, after the statements (a constructor that throws closes it too).
    std::unique_ptr<sqlite3, int (*)(sqlite3*)> db_{nullptr, sqlite3_close};
    std::vector<std::vector<std::int64_t>> rows_;  // per topic, the message rows in time order
    std::unique_ptr<Statement> select_;
    mutable std::mutex mutex_;
};

// A storage file decompressed (rosbag2's FILE compression) into a temporary file, removed with it.
class DecompressedFile {
public:
    explicit DecompressedFile(const fs::path& compressed) {
        std::ifstream in(compressed, std::ios::binary);
        if (!in) throw InputError(quoted_path(compressed) + ": cannot open it");
        const std::string name = compressed.stem().filename().string();  // x_0.db3.zstd -> x_0.db3
        path_ = fs::temp_directory_path() / ("bvc3d-" + std::to_string(::getpid()) + "-" +
                                             std::to_string(reinterpret_cast<std::uintptr_t>(this)) + "-" + name);
        std::ofstream out(path_, std::ios::binary | std::ios::trunc);
        if (!out) throw InputError("cannot write the temporary file " + quoted_path(path_));
        std::unique_ptr<ZSTD_DStream, std::size_t (*)(ZSTD_DStream*)> z(ZSTD_createDStream(), ZSTD_freeDStream);
        ZSTD_initDStream(z.get());
        std::vector<char> src(ZSTD_DStreamInSize()), dst(ZSTD_DStreamOutSize());
        std::size_t last = 0;
        bool any = false;
        while (in.read(src.data(), static_cast<std::streamsize>(src.size())) || in.gcount() > 0) {
            ZSTD_inBuffer input{src.data(), static_cast<std::size_t>(in.gcount()), 0};
            any = true;
            while (input.pos < input.size) {
                ZSTD_outBuffer output{dst.data(), dst.size(), 0};
                last = ZSTD_decompressStream(z.get(), &output, &input);
                if (ZSTD_isError(last))
                    throw InputError(quoted_path(compressed) + ": zstd cannot decompress it (" +
                                     ZSTD_getErrorName(last) + "), though metadata.yaml says it is compressed");
                out.write(dst.data(), static_cast<std::streamsize>(output.pos));
            }
        }
        if (!any || last != 0) throw InputError(quoted_path(compressed) + ": its zstd stream is cut off (truncated)");
        if (!out.flush()) throw InputError("cannot write the temporary file " + quoted_path(path_));
    }
    ~DecompressedFile() {
        std::error_code ec;
        fs::remove(path_, ec);
    }
    DecompressedFile(const DecompressedFile&) = delete;
    DecompressedFile& operator=(const DecompressedFile&) = delete;
    const fs::path& path() const { return path_; }

private:
    fs::path path_;
};

// One zstd frame (a message of a MESSAGE-compressed bag), decompressed.
std::vector<std::uint8_t> zstd_frame(const std::vector<std::uint8_t>& frame) {
    const unsigned long long size = ZSTD_getFrameContentSize(frame.data(), frame.size());
    if (size == ZSTD_CONTENTSIZE_ERROR) throw InputError("its data is not a zstd frame (compression_mode: message)");
    std::vector<std::uint8_t> out;
    if (size != ZSTD_CONTENTSIZE_UNKNOWN) {
        check_memory(static_cast<double>(size), "a message of " + std::to_string(size) + " bytes", "it is corrupt");
        out.resize(size);
        const std::size_t n = ZSTD_decompress(out.data(), out.size(), frame.data(), frame.size());
        if (ZSTD_isError(n) || n != size)
            throw InputError(std::string("zstd cannot decompress it (") +
                             (ZSTD_isError(n) ? ZSTD_getErrorName(n) : "a size other than its frame declares") + ")");
        return out;
    }
    std::unique_ptr<ZSTD_DStream, std::size_t (*)(ZSTD_DStream*)> z(ZSTD_createDStream(), ZSTD_freeDStream);
    ZSTD_initDStream(z.get());
    ZSTD_inBuffer input{frame.data(), frame.size(), 0};
    std::vector<std::uint8_t> chunk(ZSTD_DStreamOutSize());
    std::size_t last = 1;
    while (input.pos < input.size || last != 0) {
        ZSTD_outBuffer output{chunk.data(), chunk.size(), 0};
        last = ZSTD_decompressStream(z.get(), &output, &input);
        if (ZSTD_isError(last))
            throw InputError(std::string("zstd cannot decompress it (") + ZSTD_getErrorName(last) + ")");
        out.insert(out.end(), chunk.begin(), chunk.begin() + static_cast<std::ptrdiff_t>(output.pos));
        if (output.pos == 0 && input.pos == input.size) break;
        if (out.size() > (std::size_t{1} << 20) && out.size() % (std::size_t{1} << 26) < chunk.size())
            check_memory(static_cast<double>(out.size()) * 2, "a zstd-compressed message", "it is corrupt");
    }
    if (last != 0) throw InputError("its zstd frame is cut off (truncated)");
    return out;
}

// Several storage files read as one bag: a topic's messages are those of each file in turn. A topic
// is read as CDR only when its storage and metadata.yaml (if any) both say cdr; any other format
// either names is listed, and refused when the topic is read.
class SplitBag : public BagReader {
public:
    SplitBag(const fs::path& folder, std::string storage, std::vector<std::unique_ptr<BagReader>> parts,
             const std::map<std::string, std::string>& formats = {}, bool zstd_messages = false,
             std::vector<std::unique_ptr<DecompressedFile>> temporaries = {})
        : BagReader(folder),
          temporaries_(std::move(temporaries)),
          storage_(std::move(storage)),
          parts_(std::move(parts)),
          zstd_messages_(zstd_messages) {
        std::map<std::string, std::size_t> by_name;
        for (std::size_t p = 0; p < parts_.size(); ++p) {
            const auto& topics = parts_[p]->topics();
            for (std::size_t t = 0; t < topics.size(); ++t) {
                auto [it, fresh] = by_name.emplace(topics[t].name, topics_.size());
                if (fresh) {
                    topics_.push_back(topics[t]);
                    topics_.back().count = 0;
                    where_.emplace_back();
                }
                BagTopic& mine = topics_[it->second];
                if (topics[t].count > 0) {
                    if (mine.count == 0) mine.first = topics[t].first;
                    mine.last = topics[t].last;
                }
                for (std::size_t k = 0; k < topics[t].count; ++k) where_[it->second].push_back({p, t, k});
                mine.count += topics[t].count;
            }
        }
        for (BagTopic& t : topics_) {
            const auto named = formats.find(t.name);
            if (named != formats.end() && named->second != "cdr" && t.encoding_name == "cdr") {
                t.encoding_name = named->second;
                t.encoding = MessageEncoding::unknown;
            }
            if (t.encoding_name != "cdr") t.encoding = MessageEncoding::unknown;
        }
    }
    std::string format() const override {
        return "ROS 2 bag (" + storage_ + (zstd_messages_ ? ", messages compressed with zstd" : "") + ")";
    }

    std::vector<std::uint8_t> serialized(std::size_t t, std::size_t k) const override {
        const Place& w = where_[t][k];
        auto bytes = parts_[w.part]->serialized(w.topic, w.index);
        return zstd_messages_ ? zstd_frame(bytes) : bytes;
    }

private:
    struct Place {
        std::size_t part, topic, index;
    };
    std::vector<std::unique_ptr<DecompressedFile>> temporaries_;  // first: removed after the parts close
    std::string storage_;
    std::vector<std::unique_ptr<BagReader>> parts_;
    std::vector<std::vector<Place>> where_;
    bool zstd_messages_;
};

// The storage files of a folder without metadata.yaml, in rosbag2's order (<name>_<n>, by n).
std::vector<fs::path> storage_files(const fs::path& folder) {
    std::vector<std::pair<std::pair<long long, std::string>, fs::path>> found;
    std::vector<std::string> compressed;
    const std::regex numbered(R"(.*_(\d+))");
    for (const auto& e : fs::directory_iterator(folder)) {
        const std::string ext = e.path().extension().string(), stem = e.path().stem().string();
        if (ext == ".zstd") compressed.push_back(e.path().filename().string());
        if (!e.is_regular_file() || (ext != ".db3" && ext != ".mcap")) continue;
        std::smatch m;
        const long long n = std::regex_match(stem, m, numbered) ? std::stoll(m[1].str().substr(0, 15)) : -1;
        found.push_back({{n, e.path().filename().string()}, e.path()});
    }
    if (found.empty())
        throw InputError(quoted_path(folder) + " is a folder without metadata.yaml and without .db3 or .mcap files: " +
                         (compressed.empty() ? "not a ROS 2 bag"
                                             : "its storage ('" + compressed.front() +
                                                   "', ...) is compressed, and only metadata.yaml says how"));
    std::sort(found.begin(), found.end());
    std::vector<fs::path> files;
    for (const auto& f : found) files.push_back(f.second);
    return files;
}

}  // namespace

std::unique_ptr<BagReader> open_ros2_storage(const fs::path& file) {
    if (file.extension() == ".mcap") return open_mcap(file);
    return std::make_unique<SqliteBag>(file);
}

std::unique_ptr<BagReader> open_ros2_bag(const fs::path& folder) {
    const fs::path metadata = folder / "metadata.yaml";
    std::error_code ec;
    if (!fs::is_regular_file(metadata, ec)) {
        // As `ros2 bag reindex` would: the storage files alone (.db3 and .mcap; one kind).
        const auto files = storage_files(folder);
        std::vector<std::unique_ptr<BagReader>> parts;
        for (const auto& f : files) {
            if (f.extension() != files.front().extension())
                throw InputError(quoted_path(folder) +
                                 " (no metadata.yaml) holds both .db3 and .mcap files: "
                                 "which are the bag's is not known");
            try {
                parts.push_back(open_ros2_storage(f));
            } catch (const InputError& e) {
                throw InputError(quoted_path(folder) +
                                 " is a folder without metadata.yaml, read from its storage "
                                 "files as `ros2 bag reindex` would: " +
                                 e.what());
            }
        }
        return std::make_unique<SplitBag>(folder, files.front().extension() == ".mcap" ? "mcap" : "sqlite3",
                                          std::move(parts));
    }
    std::string storage, compression, mode;
    std::vector<fs::path> files;
    std::map<std::string, std::string> formats;  // topic -> serialization_format
    try {
        const YAML::Node root = YAML::LoadFile(metadata.string())["rosbag2_bagfile_information"];
        if (!root || !root.IsMap()) throw InputError("it has no rosbag2_bagfile_information map");
        storage = root["storage_identifier"] ? root["storage_identifier"].as<std::string>() : "";
        if (storage != "sqlite3" && storage != "mcap")
            throw InputError("key 'storage_identifier': '" + storage + "' is not sqlite3 or mcap");
        const YAML::Node paths = root["relative_file_paths"];
        if (!paths || !paths.IsSequence() || paths.size() == 0)
            throw InputError("key 'relative_file_paths': no storage files are listed");
        for (const auto& p : paths) files.push_back(folder / p.as<std::string>());
        if (root["compression_format"]) compression = root["compression_format"].as<std::string>();
        if (root["compression_mode"]) mode = root["compression_mode"].as<std::string>();
        std::transform(mode.begin(), mode.end(), mode.begin(), [](unsigned char c) { return std::tolower(c); });
        if (mode == "none") mode.clear();
        if (!mode.empty() && compression != "zstd")
            throw InputError("key 'compression_format': '" + compression +
                             "' is a compression bvc3d cannot undo (it reads zstd, rosbag2's own)");
        if (!mode.empty() && mode != "file" && mode != "message")
            throw InputError("key 'compression_mode': '" + mode + "' is not file, message or none");
        if (const YAML::Node topics = root["topics_with_message_count"]; topics && topics.IsSequence())
            for (const auto& t : topics) {
                const YAML::Node m = t["topic_metadata"];
                if (m && m["name"] && m["serialization_format"])
                    formats[m["name"].as<std::string>()] = m["serialization_format"].as<std::string>();
            }
    } catch (const YAML::Exception& e) {
        throw InputError(quoted_path(metadata) + ": " + e.what());
    } catch (const InputError& e) {
        throw InputError(quoted_path(metadata) + ": " + e.what());
    }
    std::vector<std::unique_ptr<BagReader>> parts;
    std::vector<std::unique_ptr<DecompressedFile>> temporaries;
    for (const auto& f : files) {
        fs::path file = f;
        if (mode == "file") {
            temporaries.push_back(std::make_unique<DecompressedFile>(f));
            file = temporaries.back()->path();
        }
        parts.push_back(storage == "mcap" ? open_mcap(file) : std::make_unique<SqliteBag>(file));
    }
    return std::make_unique<SplitBag>(folder, storage + (mode == "file" ? ", files compressed with zstd" : ""),
                                      std::move(parts), formats, mode == "message", std::move(temporaries));
}

}  // namespace bvc3d::recording
