#pragma once
// Which files a request may name: only files inside the served folder.
// Takes: the served folder and a path from a request (already percent-decoded by the HTTP layer).
// Gives: the file's canonical path, or nullopt for an absolute path, a path with a ".." part or a
// backslash or NUL, or one whose real location (after symbolic links) lies outside the folder.
#include <filesystem>
#include <optional>
#include <string_view>

namespace bvc3d::view {

std::optional<std::filesystem::path> path_inside(const std::filesystem::path& root, std::string_view requested);

// The same path relative to `root`, with '/' separators (what the page names files by).
std::string relative_name(const std::filesystem::path& root, const std::filesystem::path& file);

}  // namespace bvc3d::view
