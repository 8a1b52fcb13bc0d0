#include "bvc3d/core/memory.hpp"

#include <cstdio>
#include <fstream>
#include <sstream>

#include "bvc3d/core/error.hpp"

namespace bvc3d {

std::optional<std::uint64_t> available_memory() {
    std::ifstream in("/proc/meminfo");
    for (std::string line; std::getline(in, line);) {
        std::istringstream is(line);
        std::string key;
        std::uint64_t kib = 0;
        if (is >> key >> kib && key == "MemAvailable:") return kib * 1024;
    }
    return std::nullopt;
}

std::string format_bytes(double bytes) {
    static const char* units[] = {"B", "kB", "MB", "GB", "TB", "PB", "EB"};
    int u = 0;
    while (bytes >= 1000 && u < 6) {
        bytes /= 1000;
        ++u;
    }
    char buf[64];
    std::snprintf(buf, sizeof buf, bytes < 10 && u > 0 ? "%.1f %s" : "%.0f %s", bytes, units[u]);
    return buf;
}

void check_memory(double needed, const std::string& what, const std::string& advice) {
    const auto available = available_memory();
    if (!available || needed <= static_cast<double>(*available)) return;
    throw InputError(what + " needs about " + format_bytes(needed) + " of memory, but the machine has " +
                     format_bytes(static_cast<double>(*available)) + " available (MemAvailable); " + advice);
}

}  // namespace bvc3d
