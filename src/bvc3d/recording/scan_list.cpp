#include "bvc3d/recording/scan_list.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "bvc3d/recording/file_io.hpp"
#include "bvc3d/recording/parsing.hpp"
#include "bvc3d/recording/scan_file.hpp"

namespace bvc3d::recording {

namespace fs = std::filesystem;
using namespace detail;

namespace {

bool is_digit(char c) { return c >= '0' && c <= '9'; }

std::vector<ScanEntry> scans_in_list(const fs::path& list);

// A folder's scans in name order; with its own scans.txt (as write_recording and the KITTI conversion write it)
// the list's entries, which carry the scans' times, once they are checked to be the same scans.
std::vector<ScanEntry> scans_in_folder(const fs::path& folder) {
    std::vector<ScanEntry> scans;
    std::error_code ec;
    for (fs::directory_iterator it(folder, ec), end; !ec && it != end; it.increment(ec)) {
        std::error_code not_a_file;  // a dangling link is skipped, not an error
        if (scan_format_of(it->path()) && it->is_regular_file(not_a_file)) scans.push_back({it->path(), std::nullopt});
    }
    if (ec) throw input_error(folder, "cannot list folder: " + ec.message());
    if (scans.empty()) throw input_error(folder, "no scan files (.pcd, .ply, .bin) in folder");
    std::sort(scans.begin(), scans.end(), [](const ScanEntry& a, const ScanEntry& b) {
        return natural_less(a.path.filename().string(), b.path.filename().string());
    });
    const fs::path list = folder / "scans.txt";
    if (!fs::is_regular_file(list, ec)) return scans;
    std::vector<ScanEntry> listed = scans_in_list(list);
    for (std::size_t i = 0; i < std::max(listed.size(), scans.size()); ++i) {
        std::error_code same_ec;
        if (i < listed.size() && i < scans.size() && fs::equivalent(listed[i].path, scans[i].path, same_ec)) continue;
        const std::string differs =
            i >= listed.size() ? "it lists " + std::to_string(listed.size()) + " scans, the folder holds " +
                                     std::to_string(scans.size())
            : i >= scans.size() ? "it lists " + std::to_string(listed.size()) + " scans, the folder holds only " +
                                      std::to_string(scans.size())
                                : "its scan " + std::to_string(i) + " is '" + listed[i].path.filename().string() +
                                      "', the folder's (in name order) '" + scans[i].path.filename().string() + "'";
        throw input_error(list, "lists other scans than its folder holds (" + differs +
                                    "): give the list itself to read the scans it names, or move it away to read "
                                    "every scan of the folder without times");
    }
    return listed;
}

// A list line: a path, optionally followed by a time after the last whitespace or comma.
ScanEntry parse_list_line(const fs::path& list, std::size_t line_number, std::string_view line) {
    const std::string where = line_ref(line_number);
    std::string_view path_text = trim(line);
    std::optional<double> time;
    const std::size_t separator = path_text.find_last_of(" \t,");
    if (separator != std::string_view::npos) {
        time = parse_double(trim(path_text.substr(separator + 1)));
        if (time) path_text = trim(path_text.substr(0, separator));
        while (!path_text.empty() && path_text.back() == ',')
            path_text = trim(path_text.substr(0, path_text.size() - 1));
    }
    if (time && !std::isfinite(*time)) throw input_error(list, where, "scan time is not finite");
    if (path_text.empty()) throw input_error(list, where, "no scan path");
    fs::path scan(path_text);
    if (scan.is_relative()) scan = list.parent_path() / scan;
    if (!scan_format_of(scan))
        throw input_error(list, where,
                          "scan " + quote_token(path_text) + " has an unknown extension: expected .pcd, .ply or .bin");
    std::error_code ec;
    if (!fs::is_regular_file(scan, ec)) throw input_error(list, where, "scan file '" + scan.string() + "' not found");
    return {scan, time};
}

std::vector<ScanEntry> scans_in_list(const fs::path& list) {
    const std::string text = read_file(list);
    std::vector<ScanEntry> scans;
    std::size_t first_line = 0;
    LineCursor lines(text);
    std::string_view line;
    while (lines.next(line)) {
        if (is_blank_or_comment(line)) continue;
        ScanEntry scan = parse_list_line(list, lines.line_number(), line);
        if (scans.empty()) first_line = lines.line_number();
        else if (scan.time.has_value() != scans.front().time.has_value())
            throw input_error(list, line_ref(lines.line_number()),
                              std::string(scan.time ? "has a time but " : "has no time but ") + line_ref(first_line) +
                                  (scan.time ? " has none" : " has one") + ": give every scan a time or none");
        scans.push_back(std::move(scan));
    }
    if (scans.empty()) throw input_error(list, "the list names no scans");
    return scans;
}

}  // namespace

std::vector<ScanEntry> list_scans(const fs::path& folder_or_list) {
    std::error_code ec;
    const auto status = fs::status(folder_or_list, ec);
    if (status.type() == fs::file_type::not_found) throw input_error(folder_or_list, "no such file or folder");
    if (fs::is_directory(status)) return scans_in_folder(folder_or_list);
    if (scan_format_of(folder_or_list)) {
        if (!fs::is_regular_file(status)) throw input_error(folder_or_list, "not a regular file");
        return {{folder_or_list, std::nullopt}};
    }
    return scans_in_list(folder_or_list);
}

std::vector<std::optional<double>> scan_times(const std::vector<ScanEntry>& scans) {
    std::vector<std::optional<double>> times;
    times.reserve(scans.size());
    for (const ScanEntry& scan : scans) times.push_back(scan.time);
    return times;
}

bool natural_less(std::string_view a, std::string_view b) {
    std::size_t i = 0, j = 0;
    while (i < a.size() && j < b.size()) {
        if (!is_digit(a[i]) || !is_digit(b[j])) {
            if (a[i] != b[j]) return static_cast<unsigned char>(a[i]) < static_cast<unsigned char>(b[j]);
            ++i, ++j;
            continue;
        }
        // Two digit runs: compare their values (length without leading zeros, then digits).
        const std::size_t a_run = i, b_run = j;
        while (i < a.size() && a[i] == '0') ++i;
        while (j < b.size() && b[j] == '0') ++j;
        const std::size_t a_digits = i, b_digits = j;
        while (i < a.size() && is_digit(a[i])) ++i;
        while (j < b.size() && is_digit(b[j])) ++j;
        if (i - a_digits != j - b_digits) return i - a_digits < j - b_digits;
        const int order = a.substr(a_digits, i - a_digits).compare(b.substr(b_digits, j - b_digits));
        if (order != 0) return order < 0;
        if (a_digits - a_run != b_digits - b_run) return a_digits - a_run < b_digits - b_run;
    }
    return i == a.size() && j < b.size();
}

}  // namespace bvc3d::recording
