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
#include "bvc3d/recording/bag.hpp"

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

// Decodes every message of a bag as its topic's type says (clouds down to their points).
inline void read_every_message(const recording::BagReader& bag) {
    using namespace bvc3d::recording;
    for (std::size_t t = 0; t < bag.topics().size(); ++t)
        for (std::size_t k = 0; k < bag.topics()[t].count && k < 64; ++k) {
            try {
                switch (message_kind(bag.topics()[t].type)) {
                    case MessageKind::point_cloud2:
                        cloud_points(bag.cloud(t, k));
                        break;
                    case MessageKind::odometry:
                    case MessageKind::pose_stamped:
                        bag.pose(t, k);
                        break;
                    case MessageKind::tf:
                        bag.transforms(t, k);
                        break;
                    case MessageKind::other:
                        bag.serialized(t, k);
                        break;
                }
            } catch (const InputError&) {}
        }
}

}  // namespace bvc3d::fuzz
