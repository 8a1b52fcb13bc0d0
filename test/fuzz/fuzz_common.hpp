#pragma once
// Shared by the fuzz targets (libFuzzer): bad input must end in an InputError (the message a user
// sees), never in a crash, a hang, a sanitizer report or another exception.
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <fstream>
#include <string>

#include "bvc3d/core/error.hpp"

namespace bvc3d::fuzz {

// Runs `read`; an InputError is the expected outcome of bad input, anything else is a finding.
template <class F>
int expect_input_errors(F&& read) {
    try {
        read();
    } catch (const InputError&) {
    } catch (const std::exception& e) {
        std::fprintf(stderr, "unexpected exception: %s\n", e.what());
        std::abort();
    }
    return 0;
}

// The input as a file with the given extension (the readers take paths), one per process.
inline std::string as_file(const std::uint8_t* data, std::size_t size, const std::string& extension) {
    static const std::string path = "/tmp/bvc3d-fuzz-" + std::to_string(::getpid()) + extension;
    std::ofstream(path, std::ios::binary | std::ios::trunc)
        .write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
    return path;
}

}  // namespace bvc3d::fuzz
