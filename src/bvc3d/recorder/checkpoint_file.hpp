#pragma once
// Checkpoints of a running trial group (HDF5). The samples are stored in segments, each holding
// what was recorded since the previous checkpoint, so checkpointing costs time in proportion to
// the new samples, not to everything so far. Every file is written atomically and the state file
// (which lists the segments) last, so a crash leaves the previous checkpoint usable.
#include <filesystem>
#include <optional>
#include <string>

#include "bvc3d/recorder/trial_record.hpp"

namespace bvc3d {

// Writes c.partial's samples as segment number c.segments (unless there are none) and the state,
// then advances c.segments and c.saved. c.partial holds only the samples recorded since c.saved.
void write_checkpoint(const std::filesystem::path& path, GroupCheckpoint& c);
// The whole checkpoint with every segment's samples joined, or why there is none to use: nothing
// when the state file does not exist; otherwise `problem` says what is wrong (unreadable,
// truncated, a segment missing, inconsistent), naming the file.
struct CheckpointRead {
    std::optional<GroupCheckpoint> checkpoint;
    std::string problem;
};
CheckpointRead read_checkpoint(const std::filesystem::path& path);
// Removes the state file and its segments.
void remove_checkpoint(const std::filesystem::path& path);

}  // namespace bvc3d
