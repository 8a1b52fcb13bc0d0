#pragma once
// Which scans make up a recording. Takes: a folder, a list file, or one scan file. Gives: the
// scan paths in recording order, each with its time when the list gives one.
//  - A folder: its files with a scan extension (.pcd, .ply, .bin) in natural name order
//    (digit runs compare as numbers: 2.pcd < 10.pcd); no times, unless the folder holds its own list,
//    scans.txt (as bvc3d writes recordings): then the list's times, which must name the same scans.
//  - A scan file: just that scan.
//  - Any other file: a list, one scan path per line (relative paths are relative to the list
//    file's folder), optionally followed by its time in seconds after whitespace or a comma.
//    Blank lines and lines starting with '#' are skipped. Either every line has a time or none.
// Errors (InputError) name the list file and line: missing scans, unknown extensions, bad times.
#include <filesystem>
#include <optional>
#include <string_view>
#include <vector>

namespace bvc3d::recording {

struct ScanEntry {
    std::filesystem::path path;
    std::optional<double> time;  // seconds, when the list gives one
};

std::vector<ScanEntry> list_scans(const std::filesystem::path& folder_or_list);

// The times of the entries, in order (what pair_scans_with_poses takes).
std::vector<std::optional<double>> scan_times(const std::vector<ScanEntry>& scans);

// Natural name order: "scan2" < "scan10"; equal numbers with fewer leading zeros first.
bool natural_less(std::string_view a, std::string_view b);

}  // namespace bvc3d::recording
