#include "view/safe_path.hpp"

#include <algorithm>

namespace bvc3d::view {

namespace fs = std::filesystem;

std::optional<fs::path> path_inside(const fs::path& root, std::string_view requested) {
    if (requested.empty() || requested.front() == '/' || requested.find('\\') != std::string_view::npos ||
        requested.find('\0') != std::string_view::npos)
        return std::nullopt;
    const fs::path rel(requested);
    if (rel.is_absolute() || rel.has_root_name()) return std::nullopt;
    if (std::any_of(rel.begin(), rel.end(), [](const fs::path& part) { return part == ".."; })) return std::nullopt;
    std::error_code ec;
    const fs::path base = fs::weakly_canonical(root, ec);
    if (ec) return std::nullopt;
    const fs::path full = fs::weakly_canonical(base / rel, ec);
    if (ec) return std::nullopt;
    // Symbolic links inside the folder may not lead out of it.
    auto [b, f] = std::mismatch(base.begin(), base.end(), full.begin(), full.end());
    if (b != base.end()) return std::nullopt;
    return full;
}

std::string relative_name(const fs::path& root, const fs::path& file) {
    std::error_code ec;
    return fs::relative(fs::weakly_canonical(file, ec), fs::weakly_canonical(root, ec), ec).generic_string();
}

}  // namespace bvc3d::view
