#pragma once
// Checkpoints of a running trial group (HDF5), written atomically.
#include <filesystem>
#include <optional>

#include "bvc3d/recorder/trial_record.hpp"

namespace bvc3d {

void write_checkpoint(const std::filesystem::path& path, const GroupCheckpoint& c);
// nullopt if the file is missing or not a readable checkpoint (a stale or broken one is ignored).
std::optional<GroupCheckpoint> read_checkpoint(const std::filesystem::path& path);

}  // namespace bvc3d
