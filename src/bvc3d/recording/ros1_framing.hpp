#pragma once
// The framing of a ROS 1 bag (format 2.0), checked before Debian's rosbag storage library reads it.
// Takes: a file. Gives: nothing when every length and offset the library will follow is sound; else an
// InputError naming the file, the byte (and the chunk holding it) and the reason.
// Why: the library trusts the file. It sizes buffers from the lengths it reads and copies as far as they
// claim, so one corrupt length is a huge allocation or a read past a buffer. Checked here: the records of
// the file; the records inside each chunk, decompressed with the codecs the library uses (roslz4, bzip2);
// the fields of every record header and connection; and the index, whose offsets must point at records of
// the kind they name (a chunk, a message inside the chunk before the index).
#include <filesystem>

namespace bvc3d::recording::ros1 {

void check_framing(const std::filesystem::path& file);

}  // namespace bvc3d::recording::ros1
