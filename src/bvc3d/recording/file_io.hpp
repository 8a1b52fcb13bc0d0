#pragma once
// Internal to the recording stage: whole-file reads and the one shape of error every reader
// throws. Takes: paths. Gives: file contents, and InputErrors worded "<file>: <where>: <reason>"
// (where = "line 12", "point 7", ... or nothing); a stable hash for fingerprints. Writers use
// core/atomic_file.hpp.
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>

#include "bvc3d/core/error.hpp"

namespace bvc3d::recording::detail {

// The error to throw for bad input in `file`; `where` may be empty.
InputError input_error(const std::filesystem::path& file, std::string_view where, std::string_view reason);
InputError input_error(const std::filesystem::path& file, std::string_view reason);

// "line 12", "point 7": the place part of an error message.
std::string line_ref(std::size_t line);
std::string point_ref(std::size_t point);

// The whole file in memory. Throws InputError for a missing file, a directory, an unreadable
// file or an empty one, naming the file and the reason.
std::string read_file(const std::filesystem::path& file);

// FNV-1a, 64 bits: a stable hash for recordings' fingerprints (their files' names, sizes and poses).
inline std::uint64_t fnv1a(std::string_view bytes, std::uint64_t h = 0xcbf29ce484222325ull) {
    for (unsigned char c : bytes) h = (h ^ c) * 0x100000001b3ull;
    return h;
}

}  // namespace bvc3d::recording::detail
