// ROS 2 bags: a folder with metadata.yaml (yaml-cpp) and its storage files, SQLite `.db3` (Debian's
// libsqlite3: rosbag2's tables `topics` and `messages`) or `.mcap` (mcap.cpp). A bag split into
// several files reads as one, the files in the order metadata.yaml lists them.
#include <sqlite3.h>
#include <yaml-cpp/yaml.h>

#include <map>
#include <mutex>

#include "bvc3d/core/error.hpp"
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

// Several storage files read as one bag: a topic's messages are those of each file in turn.
class SplitBag : public BagReader {
public:
    SplitBag(const fs::path& folder, std::string storage, std::vector<std::unique_ptr<BagReader>> parts)
        : BagReader(folder), storage_(std::move(storage)), parts_(std::move(parts)) {
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
    }
    std::string format() const override { return "ROS 2 bag (" + storage_ + ")"; }

    std::vector<std::uint8_t> serialized(std::size_t t, std::size_t k) const override {
        const Place& w = where_[t][k];
        return parts_[w.part]->serialized(w.topic, w.index);
    }

private:
    struct Place {
        std::size_t part, topic, index;
    };
    std::string storage_;
    std::vector<std::unique_ptr<BagReader>> parts_;
    std::vector<std::vector<Place>> where_;
};

}  // namespace

std::unique_ptr<BagReader> open_ros2_bag(const fs::path& folder) {
    const fs::path metadata = folder / "metadata.yaml";
    std::error_code ec;
    if (!fs::is_regular_file(metadata, ec))
        throw InputError(quoted_path(folder) + " is a folder without metadata.yaml: not a ROS 2 bag");
    std::string storage;
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
    for (const auto& f : files) parts.push_back(storage == "mcap" ? open_mcap(f) : std::make_unique<SqliteBag>(f));
    auto bag = std::make_unique<SplitBag>(folder, storage, std::move(parts));
    // The metadata's serialization format is the one the topic's messages have (CDR for ROS 2).
    for (const auto& [name, format] : formats)
        if (format != "cdr")
            for (const auto& t : bag->topics())
                if (t.name == name && t.encoding != MessageEncoding::unknown)
                    throw InputError(quoted_path(metadata) + ": topic '" + name + "': unknown message encoding '" +
                                     format + "' (ROS 2 bags are read in cdr)");
    return bag;
}

}  // namespace bvc3d::recording
