#pragma once
// MCAP files (ROS 2's default bag storage). MCAP has no Debian package and is a small public format,
// so it is read and written here, from the MCAP format specification: magic, then records (an opcode
// byte, a uint64 length, the content; little-endian), Header first and Footer last; messages stand
// alone or inside Chunks, whose records may be compressed (zstd or lz4 frames, through Debian's
// libzstd and liblz4) and carry a CRC-32 of the uncompressed records (zlib's crc32). The summary
// section (schemas, channels, statistics, chunk indexes) and each chunk's message indexes, when the
// file has them, give the messages without decompressing any chunk; a file without them is read
// record by record, and a file without a footer (a recording that did not finish) up to its last
// complete record, with a warning.
// Takes: a file. Gives: a BagReader (open_mcap in bag.hpp), and a writer of ROS 2 bags as one .mcap.
#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "bvc3d/core/atomic_file.hpp"

namespace bvc3d::recording {

enum class McapCompression { none, zstd, lz4 };

// Writes an MCAP file all or nothing (commit() renames it into place): profile "ros2", schemas in
// ros2msg, messages in CDR, in chunks of about 4 MB compressed as asked, each with its CRC and
// followed by its message indexes; a DataEnd with the data section's CRC; a summary (schemas,
// channels, statistics, chunk indexes) with its summary offsets and CRC, as readers that read by
// index expect.
class McapWriter {
public:
    McapWriter(const std::filesystem::path& file, McapCompression compression);
    ~McapWriter();
    // A channel on `topic` of ROS 2 type `type` (e.g. "sensor_msgs/msg/PointCloud2") whose schema
    // text is `definition` (ros2msg, dependencies appended), with the channel's `metadata` (rosbag2
    // writes offered_qos_profiles there). Returns its id.
    std::uint16_t add_channel(const std::string& topic, const std::string& type, const std::string& definition,
                              const std::map<std::string, std::string>& metadata = {});
    // A CDR message (with its encapsulation header) logged at `log_time_ns`.
    void write(std::uint16_t channel, std::uint64_t log_time_ns, const std::vector<std::uint8_t>& cdr);
    void commit();

private:
    void flush_chunk();
    void emit(const std::string& bytes);  // to the file, counted and into the running CRC
    AtomicFile file_;
    McapCompression compression_;
    std::uint64_t written_ = 0;
    std::uint32_t crc_ = 0;  // of the data section, then of the summary
    std::string chunk_;      // records of the open chunk, uncompressed
    std::uint64_t chunk_start_ = 0, chunk_end_ = 0;
    std::vector<std::vector<std::pair<std::uint64_t, std::uint64_t>>> chunk_messages_;  // per channel: time, offset
    std::vector<std::string> schemas_, channels_, chunk_indexes_;  // records, repeated in the summary
    std::vector<std::uint64_t> counts_;                            // messages per channel
    std::uint64_t messages_ = 0, start_ = 0, end_ = 0;
};

// ROS 2 message definitions (ros2msg, with their dependencies) of the types bvc3d writes.
const std::string& ros2_definition(const std::string& type);

}  // namespace bvc3d::recording
