#pragma once
// The machine's memory, for refusing runs that cannot fit before they start.
#include <cstdint>
#include <optional>
#include <string>

namespace bvc3d {

// MemAvailable of /proc/meminfo in bytes (what can be allocated without swapping), if known.
std::optional<std::uint64_t> available_memory();

// "1.5 GB", "320 MB": bytes for messages (decimal units).
std::string format_bytes(double bytes);

// Throws InputError when `needed` bytes exceed the available memory: "<what> needs about X of
// memory, but the machine has Y available; <advice>". Does nothing when the machine does not say.
void check_memory(double needed, const std::string& what, const std::string& advice);

}  // namespace bvc3d
